// The subcommands of depthbench. Each Add*Command registers its flags and,
// when chosen, sets `action` to the function that runs it.
#pragma once

#include <functional>

#include <CLI/CLI.hpp>

#include "bench/base/status.h"
#include "bench/base/text_table.h"
#include "bench/pipeline/cells.h"

namespace depthbench::cli {

// What a chosen subcommand runs with, made for that one run from its command
// line: the variants it may run (the built-in ones and those of its
// --variant-file), and where and how it prints (the text for people, and
// its tables in the style --table-format and --wide ask for).
struct CommandContext {
  const Catalogue& catalogue;
  const TextOutput& output;
};

// Runs a chosen subcommand: the exit code of a command that ran (kExitOk, or
// kExitFinding for a finding), or the Status that says why it could not run,
// which RunDepthbench reports (exit kExitCannotRun).
using CommandAction = std::function<Expected<int>(const CommandContext&)>;

void AddListCommand(CLI::App& app, CommandAction& action);
void AddRunCommand(CLI::App& app, CommandAction& action);
void AddMergeCommand(CLI::App& app, CommandAction& action);
void AddSpeedCommand(CLI::App& app, CommandAction& action);
void AddGateCommand(CLI::App& app, CommandAction& action);
void AddFitCommand(CLI::App& app, CommandAction& action);
void AddChooseCommand(CLI::App& app, CommandAction& action);
void AddFuzzCommand(CLI::App& app, CommandAction& action);
void AddReportCommand(CLI::App& app, CommandAction& action);
void AddBoundCommand(CLI::App& app, CommandAction& action);

}  // namespace depthbench::cli
