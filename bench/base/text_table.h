// TextTable: aligned plain-text tables for the human-readable output of
// every subcommand. Numbers right-aligned, text left-aligned.
#pragma once

#include <cstddef>
#include <memory>
#include <ostream>
#include <streambuf>
#include <string>
#include <string_view>
#include <vector>

namespace depthbench {

// How tables are printed (--table-format): aligned text for people, or
// every column, whole, as CSV (RFC 4180), a Markdown table or one line of
// JSON (an array of objects keyed by header) per table.
enum class TableFormat { kText, kCsv, kMarkdown, kJson };

// The columns of a terminal that text fits by default.
inline constexpr std::size_t kTerminalColumns = 120;

// How a command prints its tables, and how wide its lines for people are.
struct TableStyle {
  TableFormat format = TableFormat::kText;
  // The width text tables and wrapped lines fit; 0 for no limit (--wide).
  std::size_t max_width = kTerminalColumns;
};

// Where a printer writes: lines for people to `text`, tables to `tables`,
// in `style`. With the text format both are usually one stream; a machine
// format sends the tables alone to standard output and the lines to
// standard error. The streams belong to the caller and outlive the value.
struct TextOutput {
  // Lines and tables alike to `out`.
  explicit TextOutput(std::ostream& out, TableStyle table_style = {}) : text(out), tables(out), style(table_style) {}
  TextOutput(std::ostream& text_out, std::ostream& tables_out, TableStyle table_style)
      : text(text_out), tables(tables_out), style(table_style) {}

  std::ostream& text;
  std::ostream& tables;
  TableStyle style;
};

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
  // Prints the table to `out.tables` in `out.style`. The text format fits
  // the style's width: secondary columns left out, then the wrapping
  // column wrapped, as far as that takes; a line after the table names the
  // columns left out.
  void Print(const TextOutput& out) const;
  bool empty() const { return rows_.empty(); }

 private:
  void PrintText(std::size_t max_width, std::ostream& out) const;
  void PrintForMachines(TableFormat format, std::ostream& out) const;

  std::vector<Column> columns_;
  std::vector<std::vector<std::string>> rows_;  // an empty row is a separator
};

// While it lives, lines written to `out` that are wider than `max_width`
// (0: no limit) are wrapped at spaces, continuation lines indented
// two columns past the line's own indent (a word wider than the line stays
// whole, and so does a line that holds a depthbench command with flags, so
// that it can be copied). What the program prints for people goes through
// one of these; tables already fit and pass unchanged.
class WrappedOutput {
 public:
  WrappedOutput(std::ostream& out, std::size_t max_width);
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
