#include "bench/base/text_table.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace depthbench {

void TextTable::AddRow(std::vector<std::string> cells) {
  cells.resize(columns_.size());
  rows_.push_back(std::move(cells));
}

void TextTable::AddSeparator() { rows_.emplace_back(); }

namespace {

// Words of `text` in lines of at most `width` columns (a longer word has a
// line of its own).
std::vector<std::string> Wrap(const std::string& text, std::size_t width) {
  std::vector<std::string> lines(1);
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find(' ', start);
    if (end == std::string::npos) end = text.size();
    const std::string word = text.substr(start, end - start);
    std::string& line = lines.back();
    if (!line.empty() && DisplayWidth(line) + 1 + DisplayWidth(word) > width) {
      lines.push_back(word);
    } else {
      line += (line.empty() ? "" : " ") + word;
    }
    start = end + 1;
  }
  return lines;
}

}  // namespace

std::size_t DisplayWidth(std::string_view text) {
  return static_cast<std::size_t>(
      std::count_if(text.begin(), text.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
}

class WrappedOutput::Buffer : public std::streambuf {
 public:
  Buffer(std::streambuf* target, std::size_t max_width) : target_(target), max_width_(max_width) {}
  ~Buffer() override { Flush(); }
  void Flush() {
    if (!line_.empty()) Emit();
    target_->pubsync();
  }

 protected:
  int_type overflow(int_type c) override {
    if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
    line_.push_back(traits_type::to_char_type(c));
    if (c == '\n') Emit();
    return c;
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    for (std::streamsize k = 0; k < n; ++k) overflow(traits_type::to_int_type(s[k]));
    return n;
  }
  int sync() override {
    Flush();
    return 0;
  }

 private:
  void Emit() {
    const bool newline = !line_.empty() && line_.back() == '\n';
    if (newline) line_.pop_back();
    std::string text;
    const std::size_t limit = max_width_;
    // A line that holds a command to copy ("depthbench run --seed ...")
    // stays whole: a command broken across lines does not paste.
    const std::size_t command = line_.find("depthbench ");
    const bool copyable = command != std::string::npos && line_.find(" --", command) != std::string::npos;
    if (limit == 0 || copyable || DisplayWidth(line_) <= limit) {
      text = line_;
    } else {
      const std::size_t indent = std::min(line_.find_first_not_of(' '), limit / 2);
      const std::string continuation(std::min<std::size_t>(indent + 2, limit / 2), ' ');
      const std::vector<std::string> first = Wrap(line_.substr(indent), limit - indent);
      text = std::string(indent, ' ') + first.front();
      std::string rest;
      for (std::size_t k = 1; k < first.size(); ++k) rest += (k > 1 ? " " : "") + first[k];
      if (!rest.empty()) {
        for (const std::string& part : Wrap(rest, limit - continuation.size())) text += "\n" + continuation + part;
      }
    }
    if (newline) text += '\n';
    target_->sputn(text.data(), static_cast<std::streamsize>(text.size()));
    line_.clear();
  }

  std::streambuf* target_;
  std::size_t max_width_;
  std::string line_;
};

WrappedOutput::WrappedOutput(std::ostream& out, std::size_t max_width)
    : out_(out), original_(out.rdbuf()), buffer_(std::make_unique<Buffer>(original_, max_width)) {
  out_.rdbuf(buffer_.get());
}

WrappedOutput::~WrappedOutput() {
  out_.flush();
  buffer_->Flush();
  out_.rdbuf(original_);
}

namespace {

// A CSV field: quoted when it holds a comma, a quote or a line break.
std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

// A Markdown table cell: '|' escaped.
std::string MarkdownCell(const std::string& text) {
  std::string cell;
  for (char c : text) cell += c == '|' ? std::string("\\|") : std::string(1, c);
  return cell;
}
}  // namespace

void TextTable::Print(const TextOutput& out) const {
  if (out.style.format == TableFormat::kText) {
    PrintText(out.style.max_width, out.tables);
  } else {
    PrintForMachines(out.style.format, out.tables);
  }
}

void TextTable::PrintForMachines(TableFormat format, std::ostream& out) const {
  std::vector<std::string> headers;
  for (const Column& c : columns_) headers.push_back(c.header);
  auto joined = [](const std::vector<std::string>& cells, auto field, const char* between) {
    std::string line;
    for (std::size_t c = 0; c < cells.size(); ++c) line += (c ? between : "") + field(cells[c]);
    return line;
  };
  if (format == TableFormat::kJson) {
    nlohmann::ordered_json rows = nlohmann::ordered_json::array();
    for (const auto& row : rows_) {
      if (row.empty()) continue;
      nlohmann::ordered_json object = nlohmann::ordered_json::object();
      for (std::size_t c = 0; c < row.size(); ++c) object[headers[c]] = row[c];
      rows.push_back(std::move(object));
    }
    out << rows.dump() << "\n";
    return;
  }
  if (format == TableFormat::kCsv) {
    out << joined(headers, CsvField, ",") << "\n";
    for (const auto& row : rows_)
      if (!row.empty()) out << joined(row, CsvField, ",") << "\n";
  } else {
    out << "| " << joined(headers, MarkdownCell, " | ") << " |\n|";
    for (const Column& c : columns_) out << (c.align == Align::kRight ? " ---: |" : " --- |");
    out << "\n";
    for (const auto& row : rows_)
      if (!row.empty()) out << "| " << joined(row, MarkdownCell, " | ") << " |\n";
  }
  out << "\n";  // a blank line between tables
}

void TextTable::PrintText(std::size_t max_width, std::ostream& out) const {
  const std::size_t n = columns_.size();
  std::vector<std::size_t> width(n);
  for (std::size_t c = 0; c < n; ++c) {
    width[c] = DisplayWidth(columns_[c].header);
    for (const auto& row : rows_)
      if (!row.empty()) width[c] = std::max(width[c], DisplayWidth(row[c]));
  }
  std::vector<bool> shown(n, true);
  const auto total = [&] {
    std::size_t sum = 0, count = 0;
    for (std::size_t c = 0; c < n; ++c) {
      if (!shown[c]) continue;
      sum += width[c];
      ++count;
    }
    return sum + 2 * (count > 0 ? count - 1 : 0);
  };
  std::vector<std::string> left_out;
  const std::size_t limit = max_width;
  if (limit > 0) {
    for (std::size_t c = n; c-- > 0 && total() > limit;) {
      if (!columns_[c].secondary) continue;
      shown[c] = false;
      left_out.insert(left_out.begin(), columns_[c].header);
    }
    std::size_t wrapped = n;
    for (std::size_t c = 0; c < n; ++c)
      if (columns_[c].wrap && shown[c]) wrapped = c;
    if (wrapped < n && total() > limit) {
      const std::size_t others = total() - width[wrapped];
      constexpr std::size_t kNarrowest = 16;
      width[wrapped] = std::max(kNarrowest, limit > others ? limit - others : 0);
    }
  }
  auto print_line = [&](const std::vector<std::string>& cells) {
    std::string line;
    bool first = true;
    for (std::size_t c = 0; c < n; ++c) {
      if (!shown[c]) continue;
      const std::string& text = cells[c];
      const std::size_t used = DisplayWidth(text);
      std::string pad(width[c] > used ? width[c] - used : 0, ' ');
      if (!first) line += "  ";
      first = false;
      line += columns_[c].align == Align::kLeft ? text + pad : pad + text;
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out << line << '\n';
  };
  // A row whose wrapping cell is too wide takes continuation lines, the
  // other cells blank there.
  auto print_row = [&](const std::vector<std::string>& cells) {
    std::vector<std::vector<std::string>> lines{cells};
    for (std::size_t c = 0; c < n; ++c) {
      if (!columns_[c].wrap || !shown[c] || DisplayWidth(cells[c]) <= width[c]) continue;
      const std::vector<std::string> parts = Wrap(cells[c], width[c]);
      for (std::size_t k = 0; k < parts.size(); ++k) {
        if (k >= lines.size()) lines.emplace_back(n);
        lines[k][c] = parts[k];
      }
    }
    for (const auto& line : lines) print_line(line);
  };
  std::vector<std::string> headers;
  for (const auto& c : columns_) headers.push_back(c.header);
  print_line(headers);
  const std::string rule(total(), '-');
  out << rule << '\n';
  for (const auto& row : rows_) {
    if (row.empty()) {
      out << rule << '\n';
    } else {
      print_row(row);
    }
  }
  if (!left_out.empty()) {
    std::string names;
    for (const std::string& name : left_out) names += (names.empty() ? "'" : ", '") + name + "'";
    out << fmt::format("(left out to fit {} columns: {}; --wide shows them)\n", limit, names);
  }
}

std::string ShortCount(double x) {
  if (x >= 1e9) return fmt::format("{:.2f}G", x / 1e9);
  if (x >= 1e6) return fmt::format("{:.2f}M", x / 1e6);
  if (x >= 1e4) return fmt::format("{:.0f}k", x / 1e3);
  return fmt::format("{:.0f}", x);
}

std::string Readable(double x, int digits) {
  if (!std::isfinite(x)) return fmt::format("{}", x);
  const double magnitude = std::fabs(x);
  if (magnitude == 0.0) return "0";
  if (magnitude >= 1e6 || magnitude < 1e-3) {
    // "1.06e+07" as "1.06e7": the exponent's sign and zeros add nothing.
    std::string text = fmt::format("{:.{}g}", x, digits);
    const std::size_t e = text.find('e');
    if (e == std::string::npos) return text;
    std::string exponent = text.substr(e + 1);
    const bool negative = exponent[0] == '-';
    exponent.erase(0, exponent.find_first_not_of("+-0"));
    return text.substr(0, e) + "e" + (negative ? "-" : "") + exponent;
  }
  const int exponent = static_cast<int>(std::floor(std::log10(magnitude)));
  return fmt::format("{:.{}f}", x, std::max(0, digits - 1 - exponent));
}

}  // namespace depthbench
