// The depthbench command line as one object: every subcommand with its
// flags, the parse (which only chooses what to run), and the run. main()
// calls RunDepthbench; the command-line fuzz target parses without running.
#pragma once

#include <functional>
#include <iosfwd>
#include <memory>

#include <CLI/CLI.hpp>

#include "bench/cli/commands.h"

namespace depthbench::cli {

// The program's CLI11 app. When a parse chooses a subcommand, `action` is set
// to the function that runs it; `action` must outlive the app.
std::unique_ptr<CLI::App> MakeDepthbenchApp(CommandAction& action);

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
