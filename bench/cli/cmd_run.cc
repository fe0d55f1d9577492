// depthbench run: every selected cell on every selected backend against the
// high-precision reference.

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "bench/base/files.h"
#include "bench/base/parse_number.h"
#include "bench/base/progress.h"
#include "bench/base/text_table.h"
#include "bench/cli/cli_common.h"
#include "bench/cli/commands.h"
#include "bench/fuzz/case_check.h"
#include "bench/fuzz/fuzz_case.h"
#include "bench/pipeline/stats.h"
#include "bench/results/results_table.h"
#include "bench/sweep/repro.h"
#include "bench/sweep/sweep.h"

namespace depthbench::cli {
namespace {

struct RunFlags {
  std::string samples = "1e6";
  std::uint64_t seed = 1;
  std::string shard;
  std::string json;
  std::string index;
  std::string repro;
  std::vector<std::string> split;
  unsigned threads = 0;
  std::uint32_t batch = 0;  // by the judge (SweepOptions::batch_size)
  std::string judge = "auto";
  std::string judge_fusion = "auto";
  std::string draw = "auto";
  bool quiet = false;
  DomainFlags domain;
  CellFlags cells;
  BackendFlags backends;
};

// Replays a reproducer file of depthbench fuzz: the same output, and
// whether the finding still holds (exit 1) or is gone (exit 0).
Expected<int> ReplayReproFile(const RunFlags& f, std::span<Backend* const> backends, std::ostream& out) {
  DB_ASSIGN_OR_RETURN(const ReproFile file, ReadReproFile(f.repro));
  const CaseSource source(file.fuzz_case);
  DB_ASSIGN_OR_RETURN(Repro repro, ReproduceFrom(source, 0, file.cells, backends));
  repro.origin = fmt::format("the case of {}", f.repro);
  PrintRepro(repro, out);
  DB_ASSIGN_OR_RETURN(CaseChecker checker,
                      CaseChecker::Make(file.cells, std::vector<Backend*>(backends.begin(), backends.end()), 1));
  DB_RETURN_IF_ERROR(checker.Evaluate(source, 0, 1));
  int failures = 0;
  out << "\n";
  for (std::size_t c = 0; c < file.cells.size(); ++c) {
    for (std::size_t b = 0; b < backends.size(); ++b) {
      const Judgement& j = checker.At(c, b, 0);
      std::string verdict =
          !j.checked          ? "not checked (the reference is degenerate)"
          : j.nan             ? "FINDING: NaN where the reference is finite"
          : j.inf             ? "FINDING: Inf where the reference is finite"
          : j.arith > j.bound ? fmt::format(
                                    "FINDING: arithmetic error {:.3g} ({:.1f} bits lost) beyond the bound "
                                    "{:.3g} ({:.1f} bits)",
                                    j.arith, BitsLost(j.arith), j.bound, BitsLost(j.bound))
                              : fmt::format("holds: arithmetic error {:.3g} within the bound {:.3g}", j.arith, j.bound);
      failures += j.violates();
      out << fmt::format("{} on {}: {}\n", file.cells[c].Name(), backends[b]->name(), verdict);
    }
  }
  if (!f.json.empty()) DB_RETURN_IF_ERROR(WriteFileAtomically(f.json, ReproToJson(repro).dump(1) + "\n"));
  return failures > 0 ? kExitFinding : kExitOk;
}

Expected<int> Run(const RunFlags& f, const CommandContext& context) {
  const TextOutput& out = context.output;
  SweepOptions options;
  DB_ASSIGN_OR_RETURN(options.samples, ParseCount(f.samples, "--samples"));
  options.seed = f.seed;
  options.threads = f.threads;
  options.batch_size = f.batch;
  options.judge = f.judge == "host" ? JudgeSite::kHost : f.judge == "device" ? JudgeSite::kDevice : JudgeSite::kAuto;
  options.device_draws = f.draw == "auto";
  options.device_tuning.fusion = f.judge_fusion == "separate" ? JudgeFusion::kSeparate
                                 : f.judge_fusion == "fused"  ? JudgeFusion::kFused
                                                              : JudgeFusion::kAuto;
  if (!f.shard.empty()) {
    DB_ASSIGN_OR_RETURN(options.shard, ParseShard(f.shard));
  }
  DB_ASSIGN_OR_RETURN(options.domain, f.domain.Apply(Domain{}, context.catalogue));
  DB_ASSIGN_OR_RETURN(options.cells, f.cells.Select(context.catalogue));
  DB_ASSIGN_OR_RETURN(const std::vector<std::string> projection, f.domain.DescribeProjection());
  if (!projection.empty()) {
    out.text << "projection matrix: " << fmt::format("{}", fmt::join(projection, "\n  ")) << "\n";
  }
  std::vector<BandFamily> splits;
  for (const std::string& s : f.split) {
    if (s == "ratio")
      splits.push_back(BandFamily::kRatio);
    else if (s == "depth")
      splits.push_back(BandFamily::kDepth);
    else if (s == "distance")
      splits.push_back(BandFamily::kDistance);
    else
      return InvalidArgument(fmt::format("--split: '{}' is not one of ratio, depth, distance", s));
  }
  if (!f.json.empty()) DB_RETURN_IF_ERROR(CheckWritable(f.json, "--json"));
  DB_RETURN_IF_ERROR(FileRoles().Input(f.repro, "--repro").Output(f.json, "--json").Check());
  DB_ASSIGN_OR_RETURN(const BackendSet made, f.backends.Make(context.catalogue));
  const std::span<Backend* const> backends = made.view();

  if (!f.repro.empty()) return ReplayReproFile(f, backends, out.text);
  if (!f.index.empty()) {  // one sample, in full
    const std::optional<std::uint64_t> index = ParseDigits<std::uint64_t>(f.index);
    if (!index) {
      return InvalidArgument(fmt::format("--index: '{}' is not a sample index (0, 1, 2, ... below 2^64)", f.index));
    }
    DB_ASSIGN_OR_RETURN(const Repro repro, Reproduce(options.seed, *index, options.domain,
                                                     CellsForDomain(options.cells, options.domain), backends));
    PrintRepro(repro, out.text);
    if (!f.json.empty()) DB_RETURN_IF_ERROR(WriteFileAtomically(f.json, ReproToJson(repro).dump(1) + "\n"));
    return kExitOk;
  }

  Progress progress("run", StderrIsTerminal(), f.quiet);
  options.progress = [&](const SweepProgress& p) { progress.Update(p.fraction(), p.Describe()); };
  DB_ASSIGN_OR_RETURN(const Results results, RunSweep(options, backends));
  if (!f.quiet) {
    progress.Finish(fmt::format("{} reconstructions in {} cells",
                                ShortCount(static_cast<double>(results.run.reconstructions)), results.cells.size()));
  }

  PrintRunHeader(results, out.text);
  PrintResultsTable(results, out);
  PrintRasterAgreement(results, out.text);
  for (BandFamily family : splits) PrintBandTable(results, family, out);
  if (!f.json.empty()) DB_RETURN_IF_ERROR(WriteResults(f.json, results));
  return kExitOk;
}

}  // namespace

void AddRunCommand(CLI::App& app, CommandAction& action) {
  auto flags = std::make_shared<RunFlags>();
  CLI::App* cmd = app.add_subcommand(
      "run",
      "Run every reconstruction variant under every depth convention and storage format, on the GPU (Vulkan) "
      "and the CPU, against a high-precision reference; print the error per cell");
  cmd->footer(
      "Each sample (a projection, camera pose, pixel and depth drawn from --seed) goes through every selected "
      "cell. Errors are measured in world space relative to the distance from the camera, as bits lost "
      "(log2(error / 2^-24), floored at 0), and in world units; 'storage' is the part due to the format's "
      "rounding, 'arith' the part due to the shader's arithmetic.\n\n"
      "Examples:\n"
      "  depthbench run --samples 1e6\n"
      "  depthbench run --backend cpu --variant divide,pq --convention standard,reversed --format d24 --split ratio\n"
      "  depthbench run --camera-distance 0 --ratio 1e4 --json out.json\n"
      "  depthbench run --shard 2/4 --samples 1e9 --json part2.json   (then: depthbench merge part*.json)");
  cmd->add_option("--samples", flags->samples, "samples to draw, each run through every cell (default 1e6)");
  cmd->add_option("--seed", flags->seed, "random seed; the same seed gives the same samples anywhere (default 1)");
  cmd->add_option("--shard", flags->shard, "run shard K of N (1-based) of the sweep; shards merge exactly");
  cmd->add_option(
      "--json", flags->json,
      fmt::format("write the results (schema {} v{}) to FILE; after an interrupt (exit 130) what was judged, "
                  "marked partial",
                  kResultsSchema.name, kResultsSchema.version));
  cmd->add_option("--index", flags->index,
                  "replay sample N alone and show everything about it (inputs, stored values, reference, each "
                  "backend's output and errors): what the gate and the fuzzer print to reproduce a finding");
  cmd->add_option("--repro", flags->repro,
                  "replay a reproducer file written by depthbench fuzz (its cells, on the selected backends) and say "
                  "whether the finding still holds (exit 1) or not (exit 0)");
  cmd->add_option("--split", flags->split, "also print p99.9 per band: ratio, depth, distance")->delimiter(',');
  cmd->add_option("--threads", flags->threads, kThreadsHelp);
  cmd->add_option("--batch", flags->batch,
                  fmt::format("samples per batch (memory is proportional to it; cut to what the Vulkan device can "
                              "bind at once); default {}, or {} when a GPU judges (the fastest measured)",
                              kHostBatch, kDeviceJudgeBatch))
      ->check(CLI::Range(kMinBatch, kMaxBatch));
  cmd->add_option("--judge", flags->judge,
                  "where the Vulkan backend's outputs are judged: 'host' (read back, binned on the host's cores), "
                  "'device' (binned on the GPU where they are, histograms read back; needs float64 and 64-bit "
                  "atomics), or 'auto' (default): the device for a GPU, the host for lavapipe. Same results either way. "
                  "The raster form is judged on its device only where it is the one backend")
      ->check(CLI::IsMember({"auto", "host", "device"}))
      ->type_name("WHERE")
      ->group("Backends");
  cmd->add_option("--judge-fusion", flags->judge_fusion,
                  "how the device judges: 'fused': each variant's reconstruction inside the judge's program, so "
                  "that no position goes through device memory (GLSL variants only); 'separate': the backend's "
                  "pass writes the positions and the judge reads them; 'auto' (default): fused on a GPU where "
                  "every variant is GLSL and the form is compute, separate on lavapipe and for --pipeline raster. Same "
                  "results either way")
      ->check(CLI::IsMember({"auto", "fused", "separate"}))
      ->type_name("HOW")
      ->group("Backends");
  cmd->add_option("--draw", flags->draw,
                  "where the samples are drawn when every backend judges on its device: 'auto' (default): on the "
                  "device too, where depths are produced in float32, so that the host makes only the frames; "
                  "'host'. The same samples either way")
      ->check(CLI::IsMember({"auto", "host"}))
      ->type_name("WHERE")
      ->group("Backends");
  cmd->add_flag("--quiet", flags->quiet, "no progress line");
  flags->domain.Add(*cmd);
  flags->cells.Add(*cmd);
  flags->backends.Add(*cmd);
  cmd->callback([flags, &action] { action = [flags](const CommandContext& context) { return Run(*flags, context); }; });
}

}  // namespace depthbench::cli
