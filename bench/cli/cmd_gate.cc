// depthbench gate: a fixed-seed sweep of every cell against committed
// baselines; exit 1 when something got worse, for CI.
#include <algorithm>
#include <filesystem>
#include <span>

#include <fmt/format.h>

#include "bench/base/environment.h"
#include "bench/base/files.h"
#include "bench/base/interrupt.h"
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
  std::string device, shaders, junit, json, summary;
  bool update = false, validate = false, allow_uncovered = false;
  unsigned threads = 0;
};

struct BaselineSlot {
  std::string path;
  bool exists = false;
  Baseline baseline;
};

// The baselines beside `path` (in its folder), for a message about a name
// that is not there: "cpu.json, lavapipe.json", or "none".
std::string BaselinesBeside(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path folder = fs::path(path).parent_path().empty() ? fs::path(".") : fs::path(path).parent_path();
  std::vector<std::string> found;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    if (entry.path().extension() == ".json") found.push_back((folder / entry.path().filename()).string());
  }
  std::sort(found.begin(), found.end());
  std::string list;
  for (const std::string& name : found) list += (list.empty() ? "" : ", ") + name;
  return list.empty() ? fmt::format("none in '{}'", folder.string()) : list;
}

// The baselines named, read where they exist; a new one (--update) takes
// its backend from the next --backend. In CI none is made: a misspelt
// name would make a new baseline that every later run passes.
Expected<std::vector<BaselineSlot>> ReadBaselines(const GateFlags& f, const Catalogue& catalogue) {
  std::vector<BaselineSlot> slots;
  std::size_t next_new = 0;
  for (const std::string& path : f.baselines) {
    BaselineSlot slot;
    slot.path = path;
    if (f.update) {  // refused now, not after the sweep
      DB_RETURN_IF_ERROR(CheckWritable(path, "--baseline").WithContext("--update"));
    }
    // A link counts as there (a loop of links is then refused as one).
    std::error_code ec;
    slot.exists = std::filesystem::exists(std::filesystem::symlink_status(path, ec));
    if (slot.exists) {
      DB_RETURN_IF_ERROR(
          StoreInto(ReadBaseline(path, catalogue), slot.baseline).WithContext("the baseline does not parse"));
    } else if (!f.update) {
      return NotFound(
          fmt::format("baseline '{}' does not exist (baselines found: {}); make one with: depthbench gate --update "
                      "--baseline {} --backend cpu|vulkan",
                      path, BaselinesBeside(path), path));
    } else if (InCi()) {
      return NotFound(fmt::format(
          "baseline '{}' does not exist (baselines found: {}), and CI is set: a gate in CI makes no new baseline, "
          "which a misspelt name would make and every later run pass; make it outside CI",
          path, BaselinesBeside(path)));
    } else if (next_new < f.new_backends.size()) {
      slot.baseline.backend = f.new_backends[next_new++];
    } else {
      return InvalidArgument(fmt::format(
          "baseline '{}' does not exist yet: say which backend it is for with --backend (one per new baseline)", path));
    }
    // A gate compares what a plain backend does; a probed one measures another rule.
    if (slot.baseline.backend != BackendKindName(BackendKind::kCpu) &&
        slot.baseline.backend != BackendKindName(BackendKind::kVulkan)) {
      return InvalidArgument(
          fmt::format("baseline '{}' is for backend '{}'; allowed: cpu, vulkan", path, slot.baseline.backend));
    }
    slots.push_back(std::move(slot));
  }
  return slots;
}

// The backends the baselines are for, each once, as the flags make them.
Expected<BackendSet> MakeGateBackends(const GateFlags& f, std::span<const BaselineSlot> slots,
                                      const Catalogue& catalogue) {
  BackendFlags backend_flags;
  backend_flags.backends.clear();
  for (const BaselineSlot& s : slots) {
    if (std::find(backend_flags.backends.begin(), backend_flags.backends.end(), s.baseline.backend) ==
        backend_flags.backends.end()) {
      backend_flags.backends.push_back(s.baseline.backend);
    }
  }
  if (!f.shaders.empty() && std::find(backend_flags.backends.begin(), backend_flags.backends.end(), "vulkan") ==
                                backend_flags.backends.end()) {
    return InvalidArgument(
        "--shaders: none of the baselines is for the vulkan backend, the only one that compiles shaders: this gate "
        "would compare nothing the edited shaders change (give a vulkan baseline, e.g. "
        "reports/baselines/lavapipe.json)");
  }
  backend_flags.device = f.device;
  backend_flags.shaders = f.shaders;
  backend_flags.validate = f.validate;
  return backend_flags.Make(catalogue);
}

// The gate's own sweep (GatePlan) of every cell of the catalogue; a sweep
// cut short gives no results.
Expected<Results> RunGateSweep(const GateFlags& f, std::span<Backend* const> backends, const Catalogue& catalogue) {
  const SamplePlan plan = GatePlan();
  SweepOptions options;
  options.seed = plan.seed;
  options.samples = plan.samples;
  options.domain = plan.domain;
  options.threads = f.threads;
  options.cells = catalogue.Cells();
  Progress progress("gate", StderrIsTerminal());
  options.progress = [&](const SweepProgress& p) { progress.Update(p.fraction(), p.Describe()); };
  DB_ASSIGN_OR_RETURN(Results results, RunSweep(options, backends));
  if (results.run.partial) {
    // Figures of part of the plan compare with nothing: no verdict, report or baseline.
    return InterruptedError(
        fmt::format("the gate's sweep stopped after {} of its {} samples: no verdict was given and nothing was written",
                    results.run.samples_judged, results.run.samples));
  }
  progress.Finish(fmt::format("{} cells on {} backend(s)", results.cells.size(), backends.size()));
  return results;
}

// Each baseline against this run's figures of its backend. Under --update
// a baseline of another plan or device is not comparable, and is replaced.
Expected<std::vector<GateRun>> CompareRuns(const GateFlags& f, std::span<const BaselineSlot> slots,
                                           const Results& results, const GateTolerance& tolerance,
                                           const CommandContext& context) {
  std::vector<GateRun> runs;
  for (const BaselineSlot& s : slots) {
    GateRun run;
    run.catalogue = &context.catalogue;
    run.current = BaselineFromResults(results, s.baseline.backend);
    run.shader_dir = f.shaders;
    run.baseline_path = s.path;
    run.comparison.backend = s.baseline.backend;
    if (s.exists) {
      Expected<GateComparison> comparison = CompareWithBaseline(s.baseline, run.current, tolerance, context.catalogue);
      if (comparison.ok()) {
        run.comparison = std::move(comparison).value();
        run.baseline = s.baseline;
      } else if (f.update) {
        context.output.text << fmt::format("note: '{}' is not comparable ({}); --update replaces it\n", s.path,
                                           comparison.status().message());
      } else {
        return comparison.status().WithContext(fmt::format("cannot judge against '{}'", s.path));
      }
    }
    runs.push_back(std::move(run));
  }
  return runs;
}

// Everything the run measured is compared, or the gate says what it did
// not compare (--allow-uncovered accepts a baseline that covers part).
Status CheckCoverage(std::span<const GateRun> runs, bool allow_uncovered) {
  for (const GateRun& r : runs) {
    const std::string uncovered = r.comparison.Uncovered();
    if (r.comparison.compared() == 0) {
      return InvalidArgument(fmt::format(
          "baseline '{}' covers none of the {} cells this gate ran ({}): nothing would be compared; make it again "
          "with: depthbench gate --update --baseline {}",
          r.baseline_path, r.current.cells.size(), uncovered, r.baseline_path));
    }
    if (!uncovered.empty() && !allow_uncovered) {
      return InvalidArgument(fmt::format(
          "baseline '{}' does not cover this run: {}; make it again with --update, or pass --allow-uncovered to "
          "compare only what it covers",
          r.baseline_path, uncovered));
    }
  }
  return Status::Ok();
}

Expected<int> Gate(const GateFlags& f, const CommandContext& context) {
  const TextOutput& out = context.output;
  for (const auto& [path, what] :
       {std::pair{f.junit, "--junit"}, std::pair{f.json, "--json"}, std::pair{f.summary, "--summary"}}) {
    if (path.empty()) continue;
    DB_RETURN_IF_ERROR(CheckWritable(path, what));
  }
  // With --update the baselines are written too; otherwise they are read.
  FileRoles roles;
  for (const std::string& path : f.baselines) {
    if (f.update) {
      roles.Output(path, "--baseline");
    } else {
      roles.Input(path, "--baseline");
    }
  }
  DB_RETURN_IF_ERROR(roles.Output(f.junit, "--junit").Output(f.json, "--json").Output(f.summary, "--summary").Check());
  DB_ASSIGN_OR_RETURN(const std::vector<BaselineSlot> slots, ReadBaselines(f, context.catalogue));
  DB_ASSIGN_OR_RETURN(const BackendSet made, MakeGateBackends(f, slots, context.catalogue));
  DB_ASSIGN_OR_RETURN(const Results results, RunGateSweep(f, made.view(), context.catalogue));
  const GateTolerance tolerance;
  DB_ASSIGN_OR_RETURN(const std::vector<GateRun> runs, CompareRuns(f, slots, results, tolerance, context));
  if (!f.update) DB_RETURN_IF_ERROR(CheckCoverage(runs, f.allow_uncovered));

  PrintGateVerdict(runs, tolerance, out.text);
  // A machine format asks for the table alone on standard output.
  if (out.style.format != TableFormat::kText) GateCellsTable(runs, SIZE_MAX).Print(out);
  if (!f.junit.empty()) DB_RETURN_IF_ERROR(WriteFileAtomically(f.junit, GateJUnit(runs)));
  if (!f.json.empty()) DB_RETURN_IF_ERROR(WriteFileAtomically(f.json, GateJson(runs, tolerance).dump(1) + "\n"));
  DB_RETURN_IF_ERROR(WriteSummary(f.summary, GateSummaryMarkdown(runs, tolerance)));
  if (f.update) {
    for (std::size_t k = 0; k < slots.size(); ++k) {
      DB_RETURN_IF_ERROR(WriteBaseline(slots[k].path, runs[k].current));
      out.text << fmt::format("baseline written: {} ({} cells on {})\n", slots[k].path, runs[k].current.cells.size(),
                              runs[k].current.device.name);
    }
    return kExitOk;
  }
  int failures = 0;
  for (const GateRun& r : runs) failures += r.comparison.failures();
  return failures == 0 ? kExitOk : kExitFinding;
}

}  // namespace

void AddGateCommand(CLI::App& app, CommandAction& action) {
  auto flags = std::make_shared<GateFlags>();
  CLI::App* cmd = app.add_subcommand(
      "gate", "Fail when a shader edit loses precision: a fixed-seed sweep of every cell against baselines");
  const SamplePlan plan = GatePlan();
  cmd->footer(fmt::format(
      "Runs every cell on the baselines' backends with seed {} and {} samples (camera at the world origin), "
      "compares each cell and band with the baseline, and exits 0 when nothing got worse, 1 when something did, "
      "2 when it cannot judge (no device, a shader that does not compile, a baseline that does not parse or was "
      "made on another device or with another sample plan, or one that lacks cells or bands of the run: every cell "
      "and band the run measures is compared unless --allow-uncovered, and then what was not compared is listed, and "
      "skipped in JUnit), 130 when interrupted (nothing is written). A band with no finite output has no bits "
      "figure: it counts as worse when it had one before. Worse: the p99.9 or maximum bits lost of the total "
      "or arithmetic error grew by more than {} or {} bit (the same seed and device give identical results; "
      "the tolerance absorbs driver and compiler updates), NaN or Inf appeared, or a cell disappeared.\n\n"
      "Examples:\n"
      "  depthbench gate --baseline reports/baselines/cpu.json --baseline reports/baselines/lavapipe.json\n"
      "  depthbench gate --baseline reports/baselines/lavapipe.json --shaders my_edited_copy/shaders --junit gate.xml\n"
      "  depthbench gate --update --baseline reports/baselines/cpu.json",
      plan.seed, plan.samples, GateTolerance{}.p999_bits, GateTolerance{}.max_bits));
  cmd->add_option("--baseline", flags->baselines, "baseline file, one per backend (repeat for several)")->required();
  cmd->add_option("--backend", flags->new_backends,
                  "with --update, the backend of each baseline file that does not exist yet, in order");
  cmd->add_option("--shaders", flags->shaders, "shader directory to test (an edited copy of shaders/)");
  cmd->add_option("--device", flags->device, "Vulkan device (part of its name); default lavapipe");
  cmd->add_flag("--update", flags->update, "show what changes, then rewrite the baselines with this run");
  cmd->add_flag("--allow-uncovered", flags->allow_uncovered,
                "judge even when a baseline lacks cells or bands this run measures; they are listed as not compared");
  cmd->add_option("--junit", flags->junit, "write JUnit XML, one test case per cell");
  cmd->add_option("--json", flags->json, "write the full comparison as JSON");
  cmd->add_option("--summary", flags->summary, kSummaryHelp);
  cmd->add_flag("--validate", flags->validate, "enable the Vulkan validation layer");
  cmd->add_option("--threads", flags->threads, kThreadsHelp);
  cmd->callback(
      [flags, &action] { action = [flags](const CommandContext& context) { return Gate(*flags, context); }; });
}

}  // namespace depthbench::cli
