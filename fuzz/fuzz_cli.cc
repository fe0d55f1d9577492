// Fuzz target: command-line parsing with the real depthbench app. The bytes,
// split at NUL, are the words after the program name; the parse chooses a
// subcommand but nothing runs. Invariants: no crash, hang or sanitizer
// report; a refused command line explains itself on stderr (exit 2); help
// prints something (exit 0); a parse that succeeds has chosen what to run
// (otherwise depthbench would exit 2 without a word); and nothing one
// command line sets is left for the next: after the input and a command
// line that sets every program-wide option (--wide, --table-format,
// --variant-file), a plain `depthbench list` decides what it decides alone
// (the default table style, no variant file), and the input parsed again
// decides what it did the first time (the outcome, the messages, the
// variant files, and a table printed in the chosen style).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "bench/base/text_table.h"
#include "bench/cli/app.h"

namespace {

using depthbench::TextOutput;
using depthbench::TextTable;

// A command line that sets every option of the whole program, and one that
// sets none.
const std::vector<std::string> kEverySetting = {"depthbench", "--wide",         "--table-format", "csv",
                                                "list",       "--variant-file", "x.glsl"};
const std::vector<std::string> kPlain = {"depthbench", "list"};

// A table wider than a terminal, with a column that a narrow table leaves
// out, printed in `style`: it reads differently in every style.
std::string SampleTable(const depthbench::TableStyle& style) {
  TextTable table({{"cell", TextTable::Align::kLeft}, {"secondary", TextTable::Align::kRight, true}});
  table.AddRow({std::string(depthbench::kTerminalColumns, 'x'), "y"});
  std::ostringstream printed;
  table.Print(TextOutput(printed, style));
  return printed.str();
}

// What parsing `words` (the program's name first) decides, as text; checks
// the invariants of one parse.
std::string Decided(const std::vector<std::string>& words) {
  std::vector<const char*> argv;
  for (const std::string& w : words) argv.push_back(w.c_str());
  argv.push_back(nullptr);  // as the C runtime passes it

  depthbench::cli::CommandLine line;
  const std::unique_ptr<CLI::App> app = depthbench::cli::MakeDepthbenchApp(line);
  std::ostringstream out, err;  // keeps the fuzzer's own output readable
  const depthbench::cli::ParseOutcome parsed =
      depthbench::cli::ParseCommandLine(*app, static_cast<int>(words.size()), argv.data(), out, err);
  if (parsed.run) {
    if (!line.action) std::abort();
  } else if (parsed.exit_code == 0) {
    if (out.str().empty()) std::abort();  // help with nothing in it
  } else {
    if (parsed.exit_code != 2 || err.str().empty()) std::abort();
  }
  std::string decided = std::to_string(parsed.exit_code) + (parsed.run ? " run\n" : "\n") + out.str() + err.str();
  for (const std::string& file : line.variant_files) decided += "--variant-file " + file + "\n";
  return decided + SampleTable(line.table_style());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> words{"depthbench"};
  std::string word;
  for (std::size_t i = 0; i < size; ++i) {
    if (data[i] == 0) {
      words.push_back(word);
      word.clear();
    } else {
      word.push_back(static_cast<char>(data[i]));
    }
  }
  if (!word.empty()) words.push_back(word);

  const std::string first = Decided(words);
  Decided(kEverySetting);
  // What a plain command line decides alone: it runs, says nothing, and
  // prints in the default style.
  if (Decided(kPlain) != "0 run\n" + SampleTable(depthbench::TableStyle{})) std::abort();
  if (Decided(words) != first) std::abort();
  return 0;
}
