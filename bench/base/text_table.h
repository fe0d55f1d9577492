// TextTable: aligned plain-text tables for the human-readable output of
// every subcommand. Numbers right-aligned, text left-aligned.
#pragma once

#include <memory>
#include <ostream>
#include <streambuf>
#include <string>
#include <string_view>
#include <vector>

namespace depthbench {

class TextTable {
 public:
  enum class Align { kLeft, kRight };
  struct Column {
    std::string header;
    Align align = Align::kRight;
    // Left out, rightmost first, when the table would not fit the width.
    bool secondary = false;
    // Wrapped at spaces onto continuation lines when the table would not
    // fit the width (one such column per table: the last that asks).
    bool wrap = false;
  };

  explicit TextTable(std::vector<Column> columns) : columns_(std::move(columns)) {}
  void AddRow(std::vector<std::string> cells);
  void AddSeparator();
  // Prints the table within `MaxWidth()` columns: secondary columns left
  // out, then the wrapping column wrapped, as far as that takes; a line
  // after the table names the columns left out.
  void Print(std::ostream& out) const;
  bool empty() const { return rows_.empty(); }

  // The width every table fits: 120 by default (a terminal of 120
  // columns), 0 for no limit (the --wide flag).
  static std::size_t MaxWidth();
  static void SetMaxWidth(std::size_t columns);

  // How every table is printed (--table-format): aligned text for people,
  // or every column, whole, as CSV (RFC 4180), a Markdown table or one
  // line of JSON (an array of objects keyed by header) per table. The
  // machine formats go to `sink` (standard output), whatever stream Print
  // is given, so that the lines for people can go elsewhere.
  enum class Format { kText, kCsv, kMarkdown, kJson };
  static void SetFormat(Format format, std::ostream* sink);

 private:
  void PrintForMachines(Format format, std::ostream& out) const;

  std::vector<Column> columns_;
  std::vector<std::vector<std::string>> rows_;  // an empty row is a separator
};

// While it lives, lines written to `out` that are wider than
// TextTable::MaxWidth() are wrapped at spaces, continuation lines indented
// two columns past the line's own indent (a word wider than the line stays
// whole, and so does a line that holds a depthbench command with flags, so
// that it can be copied). What the program prints for people goes through
// one of these; tables already fit and pass unchanged.
class WrappedOutput {
 public:
  explicit WrappedOutput(std::ostream& out);
  ~WrappedOutput();
  WrappedOutput(const WrappedOutput&) = delete;
  WrappedOutput& operator=(const WrappedOutput&) = delete;

 private:
  class Buffer;
  std::ostream& out_;
  std::streambuf* original_;
  std::unique_ptr<Buffer> buffer_;
};

// Columns a terminal gives a UTF-8 string (code points; every character
// depthbench prints is one column wide).
std::size_t DisplayWidth(std::string_view text);

// A count in few characters: 950, 12k, 4.20M, 1.50G.
std::string ShortCount(double x);

// A figure for people: `digits` significant digits written out in full
// from 1e-3 to 1e6 (12630, 0.0106, 2.41), a short exponent outside that
// range (1.06e7, 5e-5); "-0" never shows. For tables, the report's page and
// its Markdown summary alike.
std::string Readable(double x, int digits = 3);

}  // namespace depthbench
