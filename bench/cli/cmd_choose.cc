// depthbench choose: the cheapest reconstruction that meets a scene's
// requirement.
#include <iostream>

#include <fmt/format.h>

#include "bench/backends/factory.h"

#include "bench/base/files.h"
#include "bench/base/progress.h"
#include "bench/choose/choose.h"
#include "bench/cli/cli_common.h"
#include "bench/cli/commands.h"

namespace depthbench::cli {
namespace {

struct ChooseFlags {
  std::string scene;
  std::string samples = "1e5";
  std::uint64_t seed = 11;
  std::string speed;
  std::string json;
  std::string backend = "vulkan";
  std::string device, shaders;
};

int RunChoose(const ChooseFlags& f) {
  auto scene = LoadScene(f.scene);
  if (!scene.ok()) return ReportError(scene.status());
  ChooseOptions options;
  auto samples = ParseCount(f.samples, "--samples");
  if (!samples.ok()) return ReportError(samples.status());
  options.samples = *samples;
  options.seed = f.seed;
  if (!f.json.empty()) {
    Status writable = CheckWritable(f.json, "--json");
    if (!writable.ok()) return ReportError(writable);
  }
  auto costs = StaticCostLookup(f.shaders);
  if (!costs.ok()) return ReportError(costs.status());
  CostLookup lookup = *costs;
  if (!f.speed.empty()) {
    auto measured = SpeedCostLookup(f.speed, lookup);
    if (!measured.ok()) return ReportError(measured.status());
    lookup = *measured;
  }
  auto backend = MakeBackend(f.backend, {f.device, f.shaders, false});
  if (!backend.ok()) return ReportError(backend.status());
  Progress progress("choose", StderrIsTerminal());
  auto choice = Choose(*scene, **backend, lookup, options);
  if (!choice.ok()) return ReportError(choice.status());
  progress.Finish(fmt::format("{} candidates", choice->ranked.size()));
  PrintChoice(*choice, std::cout);
  if (!f.json.empty()) {
    Status written = WriteFileAtomically(f.json, ChoiceToJson(*choice).dump(1) + "\n");
    if (!written.ok()) return ReportError(written);
  }
  return kExitOk;
}

}  // namespace

void AddChooseCommand(CLI::App& app, std::function<int()>& action) {
  auto flags = std::make_shared<ChooseFlags>();
  CLI::App* cmd = app.add_subcommand(
      "choose", "Rank the reconstructions a scene can use: the cheapest that meets its requirement first");
  cmd->footer(
      "Measures every (variant, convention, format) the scene's engine allows, inside the scene's ranges (and at "
      "the requirement's depth), models its error over eye depth to predict the scene's far end, costs it (GPU "
      "time from a `depthbench speed --json` file when given, otherwise the arithmetic instructions of its "
      "compiled shader), and ranks: the cheapest candidate that meets the requirement first. When nothing does, "
      "it says so, shows the closest, and what would have to change. Example scenes: bench/scenes/*.toml.\n\n"
      "Examples:\n"
      "  depthbench choose --scene bench/scenes/open_world.toml\n"
      "  depthbench choose --scene my_scene.toml --backend cpu --json choice.json");
  cmd->add_option("--scene", flags->scene, "scene file (TOML; see bench/scenes/)")->required();
  cmd->add_option("--samples", flags->samples, "samples in the scene (default 1e5)");
  cmd->add_option("--seed", flags->seed, "random seed (default 11)");
  cmd->add_option("--speed", flags->speed, "costs from a `depthbench speed --json` file");
  cmd->add_option("--json", flags->json, "write the ranking (schema depthbench.choose v1) to FILE");
  cmd->add_option("--backend", flags->backend, "the backend the scene's engine runs: vulkan (default) or cpu");
  cmd->add_option("--device", flags->device, "Vulkan device (part of its name); default lavapipe");
  cmd->add_option("--shaders", flags->shaders, "shader directory (default: the source tree's shaders/)");
  cmd->callback([flags, &action] { action = [flags] { return RunChoose(*flags); }; });
}

}  // namespace depthbench::cli
