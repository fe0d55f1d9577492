// depthbench gate: a fixed-seed sweep of every cell against committed
// baselines; exit 1 when something got worse, for CI.
#include <filesystem>
#include <iostream>

#include <fmt/format.h>

#include "bench/base/files.h"
#include "bench/base/progress.h"
#include "bench/cli/cli_common.h"
#include "bench/cli/commands.h"
#include "bench/gate/gate_report.h"
#include "bench/sweep/sweep.h"

namespace depthbench::cli {
namespace {

struct GateFlags {
  std::vector<std::string> baselines;
  std::vector<std::string> new_backends;  // for --update of baselines that do not exist yet
  std::string device, shaders, junit, json;
  bool update = false, validate = false;
  unsigned threads = 0;
};

struct BaselineSlot {
  std::string path;
  bool exists = false;
  Baseline baseline;
};

int Gate(const GateFlags& f) {
  for (const auto& [path, what] : {std::pair{f.junit, "--junit"}, std::pair{f.json, "--json"}}) {
    if (path.empty()) continue;
    Status writable = CheckWritable(path, what);
    if (!writable.ok()) return ReportError(writable);
  }
  // The baselines, and the backends they name.
  std::vector<BaselineSlot> slots;
  std::size_t next_new = 0;
  for (const std::string& path : f.baselines) {
    BaselineSlot slot;
    slot.path = path;
    if (f.update) {  // refused now, not after the sweep
      Status writable = CheckWritable(path, "--baseline");
      if (!writable.ok()) return ReportError(writable.WithContext("--update"));
    }
    slot.exists = std::filesystem::exists(path);
    if (slot.exists) {
      auto baseline = ReadBaseline(path);
      if (!baseline.ok()) return ReportError(baseline.status().WithContext("the baseline does not parse"));
      slot.baseline = std::move(*baseline);
    } else if (!f.update) {
      return ReportError(NotFound(fmt::format(
          "baseline '{}' does not exist; make one with: depthbench gate --update --baseline {} --backend cpu|vulkan",
          path, path)));
    } else if (next_new < f.new_backends.size()) {
      slot.baseline.backend = f.new_backends[next_new++];
    } else {
      return ReportError(InvalidArgument(fmt::format(
          "baseline '{}' does not exist yet: say which backend it is for with --backend (one per new baseline)",
          path)));
    }
    if (slot.baseline.backend != "cpu" && slot.baseline.backend != "vulkan") {
      return ReportError(InvalidArgument(
          fmt::format("baseline '{}' is for backend '{}'; allowed: cpu, vulkan", path, slot.baseline.backend)));
    }
    slots.push_back(std::move(slot));
  }
  BackendFlags backend_flags;
  backend_flags.backends.clear();
  for (const BaselineSlot& s : slots) {
    if (std::find(backend_flags.backends.begin(), backend_flags.backends.end(), s.baseline.backend) ==
        backend_flags.backends.end()) {
      backend_flags.backends.push_back(s.baseline.backend);
    }
  }
  backend_flags.device = f.device;
  backend_flags.shaders = f.shaders;
  backend_flags.validate = f.validate;
  auto made = backend_flags.Make();
  if (!made.ok()) return ReportError(made.status());
  std::vector<Backend*> backends;
  for (auto& b : *made) backends.push_back(b.get());

  // The gate's own sweep.
  const SamplePlan plan = GatePlan();
  SweepOptions options;
  options.seed = plan.seed;
  options.samples = plan.samples;
  options.domain = plan.domain;
  options.threads = f.threads;
  Progress progress("gate", StderrIsTerminal());
  options.progress = [&](const SweepProgress& p) { progress.Update(p.fraction(), p.Describe()); };
  auto results = RunSweep(options, backends);
  if (!results.ok()) return ReportError(results.status());
  progress.Finish(fmt::format("{} cells on {} backend(s)", results->cells.size(), backends.size()));

  const GateTolerance tolerance;
  std::vector<GateRun> runs;
  for (const BaselineSlot& s : slots) {
    GateRun run;
    run.current = BaselineFromResults(*results, s.baseline.backend);
    run.shader_dir = f.shaders;
    if (s.exists) {
      auto comparison = CompareWithBaseline(s.baseline, run.current, tolerance);
      if (!comparison.ok()) {
        return ReportError(comparison.status().WithContext(fmt::format("cannot judge against '{}'", s.path)));
      }
      run.comparison = std::move(*comparison);
      run.baseline = s.baseline;
    } else {
      run.comparison.backend = s.baseline.backend;
    }
    runs.push_back(std::move(run));
  }

  PrintGateVerdict(runs, tolerance, std::cout);
  if (!f.junit.empty()) {
    Status written = WriteFileAtomically(f.junit, GateJUnit(runs));
    if (!written.ok()) return ReportError(written);
  }
  if (!f.json.empty()) {
    Status written = WriteFileAtomically(f.json, GateJson(runs, tolerance).dump(1) + "\n");
    if (!written.ok()) return ReportError(written);
  }
  if (f.update) {
    for (std::size_t k = 0; k < slots.size(); ++k) {
      Status written = WriteBaseline(slots[k].path, runs[k].current);
      if (!written.ok()) return ReportError(written);
      std::cout << fmt::format("baseline written: {} ({} cells on {})\n", slots[k].path, runs[k].current.cells.size(),
                               runs[k].current.device.name);
    }
    return kExitOk;
  }
  int failures = 0;
  for (const GateRun& r : runs) failures += r.comparison.failures();
  return failures == 0 ? kExitOk : kExitFinding;
}

}  // namespace

void AddGateCommand(CLI::App& app, std::function<int()>& action) {
  auto flags = std::make_shared<GateFlags>();
  CLI::App* cmd = app.add_subcommand(
      "gate", "Fail when a shader edit loses precision: a fixed-seed sweep of every cell against baselines");
  const SamplePlan plan = GatePlan();
  cmd->footer(fmt::format(
      "Runs every cell on the baselines' backends with seed {} and {} samples (camera at the world origin), "
      "compares each cell and band with the baseline, and exits 0 when nothing got worse, 1 when something did, "
      "2 when it cannot judge (no device, a shader that does not compile, a baseline that does not parse or was "
      "made on another device or with another sample plan). Worse: the p99.9 or maximum bits lost of the total "
      "or arithmetic error grew by more than 0.25 or 0.5 bit (the same seed and device give identical results; "
      "the tolerance absorbs driver and compiler updates), NaN or Inf appeared, or a cell disappeared.\n\n"
      "Examples:\n"
      "  depthbench gate --baseline reports/baselines/cpu.json --baseline reports/baselines/lavapipe.json\n"
      "  depthbench gate --baseline reports/baselines/lavapipe.json --shaders my_edited_copy/shaders --junit gate.xml\n"
      "  depthbench gate --update --baseline reports/baselines/cpu.json",
      plan.seed, plan.samples));
  cmd->add_option("--baseline", flags->baselines, "baseline file, one per backend (repeat for several)")->required();
  cmd->add_option("--backend", flags->new_backends,
                  "with --update, the backend of each baseline file that does not exist yet, in order");
  cmd->add_option("--shaders", flags->shaders, "shader directory to test (an edited copy of shaders/)");
  cmd->add_option("--device", flags->device, "Vulkan device (part of its name); default lavapipe");
  cmd->add_flag("--update", flags->update, "show what changes, then rewrite the baselines with this run");
  cmd->add_option("--junit", flags->junit, "write JUnit XML, one test case per cell");
  cmd->add_option("--json", flags->json, "write the full comparison as JSON");
  cmd->add_flag("--validate", flags->validate, "enable the Vulkan validation layer");
  cmd->add_option("--threads", flags->threads, "worker threads (default: one per core)");
  cmd->callback([flags, &action] { action = [flags] { return Gate(*flags); }; });
}

}  // namespace depthbench::cli
