// depthbench choose: the cheapest reconstruction that meets a scene's
// requirement.

#include <fmt/format.h>

#include "bench/backends/factory.h"

#include "bench/base/files.h"
#include "bench/base/progress.h"
#include "bench/choose/choose.h"
#include "bench/choose/frame_cost.h"
#include "bench/cli/cli_common.h"
#include "bench/cli/commands.h"
#include "bench/speed/trade.h"

namespace depthbench::cli {
namespace {

struct ChooseFlags {
  std::string scene;
  std::string samples = "1e5";
  std::uint64_t seed = 11;
  std::string speed;
  std::string resolution;
  std::string json, summary;
  std::string backend = "vulkan";
  std::string device, shaders;
  int splits = ChooseOptions{}.bound_splits;
};

// The frame costs of the speed file for the device the scene runs on
// (SpeedFileFor), at the frame the scene renders; a note saying how to make
// one where there is none.
Status AddFrameCosts(const ChooseFlags& f, const Scene& scene, const Backend& backend, const Catalogue& catalogue,
                     CostSources& costs) {
  FrameCostModel model;
  model.stencil = scene.stencil;
  model.frame = scene.resolution.value_or(kCostFrame);
  if (!f.resolution.empty()) {
    DB_ASSIGN_OR_RETURN(model.frame, ParseResolution(f.resolution, "--resolution"));
  }
  DB_ASSIGN_OR_RETURN(model.speed, SpeedFileFor(backend.device(), f.speed, catalogue, model.source));
  if (model.speed == nullptr && backend.name() == "cpu") {
    costs.no_measured_note =
        "the CPU backend renders no frame, so candidates are costed by the static model (the shader's arithmetic; "
        "formats and extra targets cost nothing there); --speed FILE costs the frames of the device that made it";
    return Status::Ok();
  }
  if (model.speed == nullptr) {
    costs.no_measured_note = fmt::format(
        "no speed file of {} is committed or named (--speed), so formats and extra targets are not costed: the "
        "static model counts the shader's arithmetic only; make one in about a minute with\n  depthbench speed "
        "--quick --device '{}' --json reports/speed/NAME.json",
        backend.device().name, backend.device().name);
    return Status::Ok();
  }
  costs.measured_from = model.source;
  costs.measured = FrameCostLookup(std::move(model));
  return Status::Ok();
}

Expected<int> RunChoose(const ChooseFlags& f, const CommandContext& context) {
  const TextOutput& out = context.output;
  DB_ASSIGN_OR_RETURN(const Scene scene, LoadScene(f.scene, context.catalogue));
  ChooseOptions options;
  DB_ASSIGN_OR_RETURN(options.samples, ParseCount(f.samples, "--samples"));
  options.seed = f.seed;
  if (!f.json.empty()) DB_RETURN_IF_ERROR(CheckWritable(f.json, "--json"));
  if (!f.summary.empty()) DB_RETURN_IF_ERROR(CheckWritable(f.summary, "--summary"));
  DB_RETURN_IF_ERROR(FileRoles()
                         .Input(f.scene, "--scene")
                         .Input(f.speed, "--speed")
                         .Output(f.json, "--json")
                         .Output(f.summary, "--summary")
                         .Check());
  DB_ASSIGN_OR_RETURN(const std::unique_ptr<Backend> backend, MakeBackend(f.backend, {f.device, f.shaders, false}));
  CostSources costs;
  DB_ASSIGN_OR_RETURN(costs.static_model, StaticCostLookup(f.shaders, context.catalogue));
  DB_RETURN_IF_ERROR(AddFrameCosts(f, scene, *backend, context.catalogue, costs));
  options.shader_dir = f.shaders;
  if (f.splits < 0) return InvalidArgument(fmt::format("--splits: {} is negative", f.splits));
  options.bound_splits = f.splits;
  Progress proving("bound", StderrIsTerminal());
  options.bound_progress = CellsBoundProgress(proving);
  Progress progress("choose", StderrIsTerminal());
  DB_ASSIGN_OR_RETURN(const ChooseResult choice, Choose(scene, *backend, costs, options));
  progress.Finish(fmt::format("{} candidates", choice.ranked.size()));
  PrintChoice(choice, out);
  if (!f.json.empty()) DB_RETURN_IF_ERROR(WriteFileAtomically(f.json, ChoiceToJson(choice).dump(1) + "\n"));
  DB_RETURN_IF_ERROR(WriteSummary(f.summary, ChoiceSummaryMarkdown(choice)));
  return choice.Met() ? kExitOk : kExitFinding;
}

}  // namespace

void AddChooseCommand(CLI::App& app, CommandAction& action) {
  auto flags = std::make_shared<ChooseFlags>();
  CLI::App* cmd = app.add_subcommand(
      "choose", "Rank the reconstructions a scene can use: the cheapest that meets its requirement first");
  std::string cost_table;
  for (const OperationCost& c : kOperationCosts)
    cost_table += fmt::format("  {:<4g} {}: {}\n", c.weight, c.operation, c.why);
  cmd->footer(
      "Measures every (variant, convention, format) the scene's engine allows, inside the scene's ranges (and at "
      "the requirement's depth), models its error over eye depth to predict the scene's far end, costs it, and "
      "ranks: the cheapest candidate that meets the requirement first. A candidate meets it when the upper end of "
      "the 95% interval of its measured level is within the limit, it has enough samples for that level, and it "
      "has no NaN or Inf findings inside the scene's ranges. With requirement.level = \"bound\" the proven bound "
      "decides instead (depthbench bound: the most the candidate can lose on any conformant Vulkan device, over "
      "the requirement's population), so a scene is decided for devices nobody has tested; the measured maximum "
      "is shown beside it, and no what-ifs are measured. When nothing does, it says so, shows the closest, and "
      "what would have to change. Example scenes: bench/scenes/*.toml.\n\n"
      "Costs come in one unit per ranking. With a speed file of the device the command runs on (committed under "
      "reports/speed/, or named with --speed, whatever device it was measured on) a candidate costs what it makes "
      "a frame at the scene's resolution do: the depth attachment's bytes per pixel (D16 2, D24 4, D32F 4; with "
      "[engine] stencil = true, D16 4 and D32F 8), written and read again; for a linear or view-z depth, the D24 "
      "attachment written plus the extra target written and read; all at the bandwidth the file's probe measured; "
      "plus one reconstruction per pixel at the file's ALU-bound time. Costs within the spread tie ('='). "
      "Without a speed file, every candidate is costed by the static model, which counts the shader's arithmetic "
      "only (formats cost nothing there): the compiled shader's floating-point instructions, each lane weighed in "
      "FMA-equivalent issue slots:\n" +
      cost_table +
      "\nExit status: 0 when a candidate meets the requirement, 1 when none does (so a CI job can gate a scene "
      "on it), 2 when it cannot run.\n\n"
      "Examples:\n"
      "  depthbench choose --scene bench/scenes/open_world.toml\n"
      "  depthbench choose --scene my_scene.toml --speed reports/speed/nvidia-h200.json --json choice.json");
  cmd->add_option("--scene", flags->scene, "scene file (TOML; see bench/scenes/)")->required();
  cmd->add_option("--samples", flags->samples, "samples in the scene (default 1e5)");
  cmd->add_option("--seed", flags->seed, "random seed (default 11)");
  cmd->add_option("--speed", flags->speed,
                  "cost with this `depthbench speed --json` file (default: the committed one of the device the "
                  "command runs on)");
  cmd->add_option("--resolution", flags->resolution,
                  "the frame a cost is for, WIDTHxHEIGHT (default: the scene's projection.resolution, else 1920x1080)");
  cmd->add_option("--summary", flags->summary, kSummaryHelp);
  cmd->add_option("--json", flags->json, "write the whole decision (schema depthbench.choose v2) to FILE");
  cmd->add_option("--backend", flags->backend, "the backend the scene's engine runs: vulkan (default) or cpu");
  cmd->add_option("--device", flags->device, "Vulkan device (part of its name); default lavapipe");
  cmd->add_option("--shaders", flags->shaders, "shader directory (default: the source tree's shaders/)");
  cmd->add_option("--splits", flags->splits,
                  "with requirement.level = \"bound\": how many times the worst box of a candidate's domain is "
                  "split (depthbench bound --splits; default 200)");
  cmd->callback(
      [flags, &action] { action = [flags](const CommandContext& context) { return RunChoose(*flags, context); }; });
}

}  // namespace depthbench::cli
