// TextTable: aligned plain-text tables for the human-readable output of
// every subcommand. Numbers right-aligned, text left-aligned.
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace depthbench {

class TextTable {
 public:
  enum class Align { kLeft, kRight };
  struct Column {
    std::string header;
    Align align = Align::kRight;
  };

  explicit TextTable(std::vector<Column> columns) : columns_(std::move(columns)) {}
  void AddRow(std::vector<std::string> cells);
  void AddSeparator();
  void Print(std::ostream& out) const;
  bool empty() const { return rows_.empty(); }

 private:
  std::vector<Column> columns_;
  std::vector<std::vector<std::string>> rows_;  // an empty row is a separator
};

// A count in few characters: 950, 12k, 4.20M, 1.50G.
std::string ShortCount(double x);

}  // namespace depthbench
