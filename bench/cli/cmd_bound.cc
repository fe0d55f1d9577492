// depthbench bound: per cell, the most bits it can lose anywhere in the
// domain, proven from its compiled program, beside the worst a sweep
// measures.
#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "bench/base/files.h"
#include "bench/base/progress.h"
#include "bench/base/resources.h"
#include "bench/base/text_table.h"
#include "bench/bound/bound.h"
#include "bench/cli/cli_common.h"
#include "bench/cli/commands.h"
#include "bench/pipeline/stats.h"
#include "bench/sweep/sweep.h"

namespace depthbench::cli {
namespace {

struct BoundFlags {
  int splits = bound::BoundOptions{}.splits;
  std::string samples = "1e5";
  std::uint64_t seed = 1;
  std::string json;
  bool quiet = false;
  DomainFlags domain;
  CellFlags cells;
  BackendFlags backends;
};

// A bound in bits lost; "24+" where it allows an error as large as the
// distance (nothing is guaranteed, as "none" where no bound holds).
std::string Bits(double relative) {
  if (!std::isfinite(relative)) return "none";
  const double bits = bound::BoundBits(relative);
  return bits >= kAllBitsLost ? "24+" : fmt::format("{:.1f}", bits);
}

// The measured worst of one metric of a cell over every judged sample.
double Measured(const CellResult* result, Metric metric) {
  return result == nullptr ? NAN : result->stats.Everything()[metric].max();
}

Expected<int> Bound(const BoundFlags& f, const CommandContext& context) {
  const TextOutput& out = context.output;
  DB_ASSIGN_OR_RETURN(const Domain domain, f.domain.Apply(Domain{}, context.catalogue));
  DB_ASSIGN_OR_RETURN(const std::vector<Cell> selected, f.cells.Select(context.catalogue));
  const std::vector<Cell> cells = CellsForDomain(selected, domain);
  if (!f.json.empty()) DB_RETURN_IF_ERROR(CheckWritable(f.json, "--json"));
  if (f.splits < 0) return InvalidArgument(fmt::format("--splits: {} is negative", f.splits));
  DB_ASSIGN_OR_RETURN(const std::uint64_t samples, ParseCount(f.samples, "--samples"));
  DB_ASSIGN_OR_RETURN(const BackendSet made, f.backends.Make(context.catalogue));
  const std::span<Backend* const> backends = made.view();

  DB_ASSIGN_OR_RETURN(const std::vector<bound::CellBound> bounds,
                      ProveCells(domain, cells, f.backends.shaders, f.splits, f.quiet, "bound"));

  SweepOptions sweep;
  sweep.samples = samples;
  sweep.seed = f.seed;
  sweep.domain = domain;
  sweep.cells = cells;
  Progress measuring("measure", StderrIsTerminal(), f.quiet);
  sweep.progress = [&](const SweepProgress& p) { measuring.Update(p.fraction(), p.Describe()); };
  DB_ASSIGN_OR_RETURN(const Results results, RunSweep(sweep, backends));
  measuring.Finish(fmt::format("{} samples measured", samples));

  using Align = TextTable::Align;
  std::vector<TextTable::Column> columns = {
      {"cell", Align::kLeft}, {"shader, Vulkan rules", Align::kRight}, {"shader, exact rounding", Align::kRight}};
  for (const Backend* backend : backends)
    columns.push_back({fmt::format("measured {}", backend->name()), Align::kRight});
  columns.push_back({"depth part", Align::kRight});
  columns.push_back({"total, Vulkan rules", Align::kRight});
  TextTable table(columns);
  nlohmann::json rows = nlohmann::json::array();
  std::vector<std::string> beyond;  // "cell on backend"
  for (const bound::CellBound& b : bounds) {
    std::vector<std::string> row = {b.cell.Name(), Bits(b.device_shader), Bits(b.exact_shader)};
    nlohmann::json measured = nlohmann::json::object();
    for (const Backend* backend : backends) {
      const CellResult* result = results.Find(b.cell, backend->name());
      const double shader = Measured(result, Metric::kArith), total = Measured(result, Metric::kTotal);
      // The CPU rounds exactly; a Vulkan backend, probed or not, is held to
      // the specification's rules. A sample beyond its bound is a wrong
      // bound or a device outside the rules.
      const double shader_bound = backend->name() == "cpu" ? b.exact_shader : b.device_shader;
      const bool past = shader > shader_bound || total > b.total;
      if (past) beyond.push_back(fmt::format("{} on {}", b.cell.Name(), backend->name()));
      row.push_back(fmt::format("{:.1f}{}", BitsLost(shader), past ? " beyond" : ""));
      measured[backend->name()] = {
          {"shader_bits", BitsLost(shader)}, {"total_bits", BitsLost(total)}, {"beyond_bound", past}};
    }
    row.push_back(Bits(b.depth));
    row.push_back(Bits(b.total));
    table.AddRow(row);
    nlohmann::json json = {{"cell", b.cell.Name()},
                           {"device_shader_bits", bound::BoundBits(b.device_shader)},
                           {"exact_shader_bits", bound::BoundBits(b.exact_shader)},
                           {"depth_bits", bound::BoundBits(b.depth)},
                           {"total_bits", bound::BoundBits(b.total)},
                           {"boxes", b.boxes},
                           {"measured", measured}};
    if (!std::isfinite(b.device_shader) || !std::isfinite(b.total)) json["unbounded"] = b.unbounded;
    rows.push_back(std::move(json));
  }
  out.text << fmt::format(
      "Proven bounds over {} (bits lost; 24+: an error as large as the distance is not excluded; measured: the "
      "worst of {} samples)\n",
      domain.Describe(), samples);
  table.Print(out);
  for (const bound::CellBound& b : bounds) {
    if (!b.unbounded.empty()) out.text << fmt::format("{}: no bound: {}\n", b.cell.Name(), b.unbounded);
  }
  if (!f.json.empty()) {
    const nlohmann::json doc = {{"domain", domain.Describe()}, {"samples", samples}, {"cells", rows}};
    DB_RETURN_IF_ERROR(WriteFileAtomically(f.json, doc.dump(1) + "\n"));
  }
  if (!beyond.empty()) {
    out.text << fmt::format(
        "{} measured beyond the proven bound (shader part or whole error): {}. Either the bound is wrong or the "
        "device does not follow the Vulkan rounding rules; `depthbench fuzz --prove` shrinks such a sample to a "
        "reproducer\n",
        beyond.size(), fmt::join(beyond, ", "));
    return kExitFinding;
  }
  return kExitOk;
}

}  // namespace

void AddBoundCommand(CLI::App& app, CommandAction& action) {
  auto flags = std::make_shared<BoundFlags>();
  CLI::App* cmd = app.add_subcommand(
      "bound",
      "Prove, per cell, the most bits it can lose anywhere in the domain: the shader part on any conformant Vulkan "
      "device (the specification's rounding rules: adds and multiplies correctly rounded, maybe fused; division within "
      "2.5 ULP) and on an exactly rounded machine, read from the compiled program; the depth part from the format; "
      "beside the worst a sweep measures");
  cmd->add_option(
      "--splits", flags->splits,
      "how many times the worst box of the domain is split, per cell and machine (more: tighter and slower)");
  cmd->add_option("--samples", flags->samples, "samples of the sweep whose worst is shown beside each bound");
  cmd->add_option("--seed", flags->seed, "the sweep's seed");
  cmd->add_option("--json", flags->json, "write the bounds and the measured worst here as JSON");
  cmd->add_flag("--quiet", flags->quiet, "no progress lines");
  flags->domain.Add(*cmd);
  flags->cells.Add(*cmd);
  flags->backends.Add(*cmd);
  cmd->footer(
      "A bound holds for every sample of the domain, on any device that follows the Vulkan specification's precision "
      "rules, where a measurement holds for the samples drawn on the devices at hand. It covers the compute form "
      "(the texels hold the host's encode) and perspective domains (a scene's absolute far plane and depth range "
      "are taken over every near plane they may meet).\n\n"
      "A measured worst beyond its bound (the shader part against exact rounding on the CPU, against the Vulkan "
      "rules on a Vulkan backend; the whole error against its bound) is marked 'beyond': a wrong bound, or a "
      "device outside the rules. vulkan:worst-division is a device that uses the whole division tolerance.\n\n"
      "Exit status: 0 when every measured worst is within its bound, 1 when one is beyond, 2 when it cannot run.\n\n"
      "Examples:\n"
      "  depthbench bound --backend cpu --variant divide,inverse_vp --convention standard,reversed --format d32f\n"
      "  depthbench bound --domain wide --json bounds.json\n"
      "  depthbench bound --backend vulkan:worst-division --variant divide,reciprocal\n"
      "  depthbench bound --variant-file bench/examples/divide_subtract_first.glsl --backend vulkan");
  cmd->callback([flags, &action] { action = [flags](const CommandContext& c) { return Bound(*flags, c); }; });
}

}  // namespace depthbench::cli
