#include "bench/cli/app.h"

#include <iostream>
#include <string>

#include <fmt/format.h>

#include "bench/base/build_info.h"
#include "bench/base/resources.h"
#include "bench/cli/cli_common.h"
#include "bench/cli/commands.h"

namespace depthbench::cli {
namespace {

// The one place where a command that could not run becomes a message
// ("depthbench: error: ...") and exit code 2.
int ExitCode(const Expected<int>& ran) { return ran.ok() ? *ran : ReportError(ran.status()); }

}  // namespace

std::unique_ptr<CLI::App> MakeDepthbenchApp(CommandAction& action) {
  auto app = std::make_unique<CLI::App>(
      "depthbench: measures how precisely shader code reconstructs view- and world-space position "
      "from a depth buffer, for every variant, depth convention and storage format, on the GPU "
      "(Vulkan) and the CPU",
      "depthbench");
  app->require_subcommand(1);
  app->set_version_flag("--version", [] {
    const Expected<DataFolder> data = FindDataFolder();
    return fmt::format(
        "depthbench {} (commit {})\ndata folder: {}", BuildVersion(), BuildCommit(),
        data.ok() ? fmt::format("{} ({})", data->root.string(), data->found_by) : data.status().message());
  });
  app->footer(
      "Run 'depthbench SUBCOMMAND --help' for a subcommand's flags.\n"
      "Exit codes: 0 success, 1 a finding (a gate that fails, a fuzz finding), 2 could not run.");
  AddListCommand(*app, action);
  AddRunCommand(*app, action);
  AddMergeCommand(*app, action);
  AddSpeedCommand(*app, action);
  AddGateCommand(*app, action);
  AddFitCommand(*app, action);
  AddChooseCommand(*app, action);
  AddReportCommand(*app, action);
  AddFuzzCommand(*app, action);
  return app;
}

ParseOutcome ParseCommandLine(CLI::App& app, int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  // A first word that is neither a flag nor a subcommand gets a message
  // that names it (CLI11 would only say a subcommand is required).
  if (argc > 1 && argv[1][0] != '-' &&
      app.get_subcommands([&](const CLI::App* sub) { return sub->get_name() == argv[1]; }).empty()) {
    std::string names;
    for (const CLI::App* sub : app.get_subcommands({})) names += (names.empty() ? "" : ", ") + sub->get_name();
    err << "depthbench: error: unknown subcommand '" << argv[1] << "'; available: " << names
        << " (see depthbench --help)\n";
    return {false, kExitCannotRun};
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e, out, err);
    return {false, code == 0 ? kExitOk : kExitCannotRun};
  }
  return {true, kExitOk};
}

int RunDepthbench(int argc, const char* const* argv) {
  CommandAction action;
  std::unique_ptr<CLI::App> app = MakeDepthbenchApp(action);
  const ParseOutcome parsed = ParseCommandLine(*app, argc, argv, std::cout, std::cerr);
  if (!parsed.run) return parsed.exit_code;
  return action ? ExitCode(action()) : kExitCannotRun;
}

}  // namespace depthbench::cli
