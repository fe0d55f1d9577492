// The depthbench command line as one object: every subcommand with its
// flags, the parse (which only chooses what to run), and the run. main()
// calls RunDepthbench; the command-line fuzz target parses without running.
#pragma once

#include <functional>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "bench/base/text_table.h"
#include "bench/cli/commands.h"

namespace depthbench::cli {

// What a parse of the command line decides: the subcommand to run and the
// options of the whole program it runs with. The app writes into it while
// it parses, and every parse has its own, so nothing one command line sets
// is left behind for the next.
struct CommandLine {
  // The function that runs the chosen subcommand; empty until one is chosen.
  CommandAction action;
  // --variant-file, in the order given.
  std::vector<std::string> variant_files;
  // --table-format and --wide.
  std::string table_format = "text";
  bool wide = false;

  // How the command prints its tables, as --table-format and --wide say.
  TableStyle table_style() const;
};

// The program's CLI11 app, which parses into `line`; `line` must outlive
// the app.
std::unique_ptr<CLI::App> MakeDepthbenchApp(CommandLine& line);

// What a parse decided.
struct ParseOutcome {
  // True when the chosen subcommand should now run; false when the parse
  // itself ended the program (help, or a command line that is refused).
  bool run = false;
  // The exit code when `run` is false: 0 after --help, 2 for a refusal.
  int exit_code = 0;
};

// Parses argv into `app`. Help goes to `out`; a refusal is explained on `err`
// (naming the flag or word at fault) and gives exit code 2.
ParseOutcome ParseCommandLine(CLI::App& app, int argc, const char* const* argv, std::ostream& out, std::ostream& err);

// Parses argv and runs the chosen subcommand; returns the exit code.
int RunDepthbench(int argc, const char* const* argv);

}  // namespace depthbench::cli
