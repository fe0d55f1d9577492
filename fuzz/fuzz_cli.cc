// Fuzz target: command-line parsing with the real depthbench app. The bytes,
// split at NUL, are the words after the program name; the parse chooses a
// subcommand but nothing runs. Invariants: no crash, hang or sanitizer
// report; a refused command line explains itself on stderr (exit 2); help
// prints something (exit 0); a parse that succeeds has chosen what to run
// (otherwise depthbench would exit 2 without a word).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "bench/cli/app.h"

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
  return 0;
}
