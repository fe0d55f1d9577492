// depthbench: a test bench and fuzzer for the shader code that
// reconstructs view- and world-space position from a depth buffer.
#include <iostream>

#include <CLI/CLI.hpp>

#include "bench/cli/cli_common.h"
#include "bench/cli/commands.h"

int main(int argc, char** argv) {
  using namespace depthbench::cli;
  CLI::App app("depthbench: measures how precisely shader code reconstructs view- and world-space position "
               "from a depth buffer, for every variant, depth convention and storage format, on the GPU "
               "(Vulkan) and the CPU",
               "depthbench");
  app.require_subcommand(1);
  app.footer("Run 'depthbench SUBCOMMAND --help' for a subcommand's flags.\n"
             "Exit codes: 0 success, 1 a finding (a gate that fails, a fuzz finding), 2 could not run.");
  std::function<int()> action;
  AddListCommand(app, action);
  AddRunCommand(app, action);
  AddMergeCommand(app, action);
  AddSpeedCommand(app, action);
  AddGateCommand(app, action);
  AddFitCommand(app, action);
  AddChooseCommand(app, action);
  AddReportCommand(app, action);
  // A first word that is neither a flag nor a subcommand gets a message
  // that names it (CLI11 would only say a subcommand is required).
  if (argc > 1 && argv[1][0] != '-' && app.get_subcommands([&](const CLI::App* sub) {
                                              return sub->get_name() == argv[1];
                                            }).empty()) {
    std::string names;
    for (const CLI::App* sub : app.get_subcommands({})) names += (names.empty() ? "" : ", ") + sub->get_name();
    std::cerr << "depthbench: error: unknown subcommand '" << argv[1] << "'; available: " << names
              << " (see depthbench --help)\n";
    return kExitCannotRun;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int code = app.exit(e);
    return code == 0 ? kExitOk : kExitCannotRun;
  }
  return action ? action() : kExitCannotRun;
}
