// The subcommands of depthbench. Each Add*Command registers its flags and,
// when chosen, sets `action` to the function that runs it and returns the
// exit code.
#pragma once

#include <functional>

#include <CLI/CLI.hpp>

namespace depthbench::cli {

void AddListCommand(CLI::App& app, std::function<int()>& action);
void AddRunCommand(CLI::App& app, std::function<int()>& action);
void AddMergeCommand(CLI::App& app, std::function<int()>& action);
void AddSpeedCommand(CLI::App& app, std::function<int()>& action);
void AddGateCommand(CLI::App& app, std::function<int()>& action);
void AddFitCommand(CLI::App& app, std::function<int()>& action);
void AddChooseCommand(CLI::App& app, std::function<int()>& action);
void AddFuzzCommand(CLI::App& app, std::function<int()>& action);
void AddReportCommand(CLI::App& app, std::function<int()>& action);

}  // namespace depthbench::cli
