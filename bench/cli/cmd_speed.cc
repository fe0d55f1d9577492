// depthbench speed: the speed side of the trade on one Vulkan device. GPU
// time per pixel of full-screen passes reading a real depth image, in a
// memory-bound and an ALU-bound regime; the static instruction mix of each
// variant; the CPU backend's cost; and the speed/accuracy front.
#include <iostream>

#include <fmt/format.h>

#include "bench/backends/vulkan/vulkan_backend.h"
#include "bench/base/progress.h"
#include "bench/base/resources.h"
#include "bench/cli/cli_common.h"
#include "bench/cli/commands.h"
#include "bench/results/results.h"
#include "bench/speed/speed_run.h"
#include "bench/speed/speed_table.h"
#include "bench/sweep/sweep.h"

namespace depthbench::cli {
namespace {

struct SpeedFlags {
  std::string device;
  std::string shaders;
  bool validate = false;
  CellFlags cells;
  std::vector<std::string> resolutions{"1920x1080", "3840x2160"};
  std::uint32_t taps = 16;
  std::uint32_t repetitions = 10;
  std::uint32_t warmup = 2;
  std::string results;
  std::string accuracy_samples = "1e5";
  std::string domain;  // of the accuracy run (default typical)
  std::string json;
  std::string compare;
  bool quick = false;
  bool quiet = false;
  double budget = 0.0;  // seconds of GPU timings; 0: no limit
  // Which flags were given (quick must not override them).
  bool repetitions_given = false, warmup_given = false, accuracy_samples_given = false, resolutions_given = false;
};

// Accuracy results for the trade: the file given, or a run of the selected
// cells on the same device's Vulkan backend.
Expected<Results> AccuracyFor(const SpeedFlags& f, const Catalogue& catalogue, const std::vector<Cell>& cells,
                              std::shared_ptr<VulkanContext> context, std::uint64_t samples, std::string& source) {
  if (!f.results.empty()) {
    source = f.results;
    return ReadResults(f.results, catalogue);
  }
  BackendOptions backend_options{f.device, f.shaders, f.validate};
  DB_ASSIGN_OR_RETURN(std::unique_ptr<Backend> backend, MakeVulkanBackend(std::move(context), backend_options));
  SweepOptions sweep;
  sweep.samples = samples;
  if (!f.domain.empty()) DB_RETURN_IF_ERROR(StoreInto(DomainByName(f.domain, catalogue), sweep.domain));
  sweep.cells = CellsForDomain(cells, sweep.domain);
  Backend* backends[] = {backend.get()};
  source = fmt::format("internal run of {} samples, seed {}, {}", samples, sweep.seed, sweep.domain.Describe());
  return RunSweep(sweep, backends);
}

Expected<int> Speed(const SpeedFlags& f, const CommandContext& context) {
  const TextOutput& out = context.output;
  SpeedOptions options;
  DB_ASSIGN_OR_RETURN(options.cells, f.cells.Select(context.catalogue));
  options.catalogue = &context.catalogue;
  options.resolutions.clear();
  const std::vector<std::string> resolutions =
      f.quick && !f.resolutions_given ? std::vector<std::string>{"1280x720"} : f.resolutions;
  for (const std::string& text : resolutions) {
    DB_ASSIGN_OR_RETURN(const Resolution resolution, ParseResolution(text, "--resolution"));
    options.resolutions.push_back(resolution);
  }
  options.alu_taps = f.taps;
  options.warmup = f.quick && !f.warmup_given ? 1 : f.warmup;
  options.repetitions = f.quick && !f.repetitions_given ? 5 : f.repetitions;
  if (f.quick) options.cpu.repetitions = 5;
  // Formats named on purpose must be measured; by default the device's
  // unsupported formats are left out and listed.
  options.refuse_unsupported = !f.cells.formats.empty();
  Status valid = ValidateSpeedOptions(options);
  if (!valid.ok()) {
    // Name the flags, not the struct.
    if (options.alu_taps < 2 || options.alu_taps > GpuPassTimer::kMaxTaps) {
      return InvalidArgument(
          fmt::format("--taps: {} is out of range; allowed 2 to {} (the ALU-bound "
                      "regime; 1 tap is the memory-bound one, always measured)",
                      options.alu_taps, GpuPassTimer::kMaxTaps));
    }
    if (options.repetitions < 3) {
      return InvalidArgument(
          fmt::format("--repetitions: {} is too few; at least 3 (a spread needs three values)", options.repetitions));
    }
    if (options.warmup < 1) return InvalidArgument("--warmup: at least 1 warm-up pass is needed");
    return valid;
  }
  const std::string accuracy_samples_text = f.quick && !f.accuracy_samples_given ? "1e4" : f.accuracy_samples;
  DB_ASSIGN_OR_RETURN(const std::uint64_t accuracy_samples, ParseCount(accuracy_samples_text, "--accuracy-samples"));
  if (!f.json.empty()) DB_RETURN_IF_ERROR(CheckWritable(f.json, "--json"));
  // Files given are read before the long work starts.
  std::optional<SpeedResults> previous;
  if (!f.compare.empty()) {
    DB_RETURN_IF_ERROR(StoreInto(ReadSpeedResults(f.compare, context.catalogue), previous).WithContext("--compare"));
  }
  std::optional<Results> given_accuracy;
  if (!f.results.empty()) {
    DB_RETURN_IF_ERROR(StoreInto(ReadResults(f.results, context.catalogue), given_accuracy).WithContext("--results"));
  }

  VulkanContextOptions context_options;
  context_options.device = f.device;
  context_options.validation = f.validate;
  DB_ASSIGN_OR_RETURN(const std::shared_ptr<VulkanContext> shared_context, VulkanContext::Create(context_options));
  std::filesystem::path shader_dir = f.shaders;
  if (shader_dir.empty()) DB_RETURN_IF_ERROR(StoreInto(DataPath("shaders"), shader_dir));
  DB_ASSIGN_OR_RETURN(const std::unique_ptr<GpuPassTimer> timer, GpuPassTimer::Create(shared_context, shader_dir));

  Progress progress("speed", StderrIsTerminal(), f.quiet);
  options.progress = [&](std::size_t done, std::size_t total, const std::string& what) {
    progress.Update(static_cast<double>(done) / static_cast<double>(total), what);
  };
  options.budget_seconds = f.budget;
  options.estimate = [&](double seconds) {
    // Said before a run that takes more than about a minute, so that the
    // user can stop it and ask for less.
    if (seconds > 60.0 && !f.quiet) {
      std::cerr << fmt::format(
          "speed: the GPU timings will take about {:.0f} min at this rate ({} cells, {} resolutions); --budget "
          "SECONDS, --quick, fewer --resolution or cell filters take less\n",
          seconds / 60.0, options.cells.size(), options.resolutions.size());
    }
  };
  DB_ASSIGN_OR_RETURN(SpeedResults results, RunSpeed(*timer, shader_dir, options));
  if (!f.quiet) progress.Finish(fmt::format("{} GPU timings in {:.1f} s", results.gpu.size(), results.run.seconds));

  std::string source;
  Expected<Results> accuracy =
      given_accuracy ? Expected<Results>(*given_accuracy)
                     : AccuracyFor(f, context.catalogue, options.cells, shared_context, accuracy_samples, source);
  if (given_accuracy) source = f.results;
  if (!accuracy.ok()) return accuracy.status().WithContext("accuracy results for the trade");
  DB_RETURN_IF_ERROR(AddTrade(results, *accuracy, source).WithContext("accuracy results for the trade"));

  PrintSpeedHeader(results, out.text);
  PrintGpuTable(results, out);
  PrintStaticTable(results, out);
  PrintCpuTable(results, out);
  PrintTradeTable(results, out);
  PrintSkipped(results, out.text);
  if (!f.json.empty()) DB_RETURN_IF_ERROR(WriteSpeedResults(f.json, results));
  if (previous) {
    RankingComparison comparison;
    DB_RETURN_IF_ERROR(StoreInto(CompareRankings(*previous, results), comparison).WithContext("--compare"));
    PrintRankingComparison(comparison, out.text);
    if (!comparison.contradictions.empty()) return kExitFinding;
  }
  return kExitOk;
}

}  // namespace

void AddSpeedCommand(CLI::App& app, CommandAction& action) {
  auto flags = std::make_shared<SpeedFlags>();
  CLI::App* cmd = app.add_subcommand(
      "speed",
      "Measure the speed side of the trade on a Vulkan device: GPU time per pixel of full-screen passes reading a "
      "real depth image (memory-bound and ALU-bound), the device's bandwidth, how fast its vertex and fragment "
      "stages compute against compute (and, on NVIDIA, on how many processors), the SPIR-V instruction mix, the CPU "
      "backend's cost, and each variant's cost against its p99.9 bits lost (the Pareto front)");
  cmd->footer(
      "Timing on lavapipe (the default device) is timing of JIT-compiled CPU code, not of a GPU; results are kept "
      "per device (reports/speed/<device>.json).\n\n"
      "Examples:\n"
      "  depthbench speed --json reports/speed/llvmpipe.json\n"
      "  depthbench speed --device nvidia --results results.json --json reports/speed/nvidia-h200.json\n"
      "  depthbench speed --variant divide,pq --convention reversed --format d32f --resolution 1920x1080 --quick\n"
      "  depthbench speed --compare reports/speed/llvmpipe.json   (exit 1 if a ranking flips)");
  cmd->add_option("--device", flags->device,
                  "Vulkan device: a case-insensitive part of its name (default: Mesa lavapipe, 'llvmpipe')");
  cmd->add_option("--shaders", flags->shaders,
                  "directory of the shaders (holding speed/), compiled at run time (default: the source tree's "
                  "shaders/)");
  cmd->add_flag("--validate", flags->validate, "enable the Vulkan validation layer and fail on its messages");
  flags->cells.Add(*cmd);
  cmd->add_option("--resolution", flags->resolutions,
                  "full-screen pass sizes WIDTHxHEIGHT (several, or comma-separated; default 1920x1080,3840x2160, "
                  "with --quick 1280x720)")
      ->delimiter(',')
      ->each([flags](const std::string&) { flags->resolutions_given = true; });
  cmd->add_option("--taps", flags->taps, "reconstructions per pixel in the ALU-bound regime, 2 to 64 (default 16)");
  cmd->add_option("--repetitions", flags->repetitions, "timed repetitions per measurement, at least 3 (default 10)")
      ->each([flags](const std::string&) { flags->repetitions_given = true; });
  cmd->add_option("--warmup", flags->warmup,
                  "warm-up rounds (one pass of each variant timed together), at least 1; more follow up to 20 ms "
                  "of device time (default 2)")
      ->each([flags](const std::string&) { flags->warmup_given = true; });
  cmd->add_option("--results", flags->results,
                  "accuracy results (depthbench run --json) for the trade; default: an internal run on the same "
                  "device");
  cmd->add_option("--domain", flags->domain, std::string("the internal accuracy run's domain: ") + kDomainHelp)
      ->type_name("NAME|FILE");
  cmd->add_option("--accuracy-samples", flags->accuracy_samples,
                  "samples of the internal accuracy run when no --results is given (default 1e5)")
      ->each([flags](const std::string&) { flags->accuracy_samples_given = true; });
  cmd->add_option("--json", flags->json, "write the results (schema depthbench.speed v1) to FILE");
  cmd->add_option("--compare", flags->compare,
                  "an earlier speed JSON of the same device: report whether the variants rank the same way "
                  "wherever their medians differ by more than the spread (exit 1 where they do not)");
  cmd->add_flag("--quick", flags->quick,
                "a usable speed file in about a minute on lavapipe, seconds on a GPU: one resolution (1280x720), 1 "
                "warm-up, 5 repetitions, a 1e4-sample accuracy run; choose and report cost frames from it");
  cmd->add_flag("--quiet", flags->quiet, "no progress line");
  cmd->add_option("--budget", flags->budget,
                  "seconds the GPU timings may take: depth images whose timings would end past it are left out "
                  "(listed as not measured); a run that will take over a minute says how long first")
      ->type_name("SECONDS")
      ->check(CLI::NonNegativeNumber);
  cmd->callback(
      [flags, &action] { action = [flags](const CommandContext& context) { return Speed(*flags, context); }; });
}

}  // namespace depthbench::cli
