// depthbench fuzz: the GPU fuzz campaign, and the worst-case search.
#include <filesystem>
#include <iostream>

#include <fmt/format.h>

#include "bench/base/files.h"
#include "bench/base/progress.h"
#include "bench/base/resources.h"
#include "bench/base/text_table.h"
#include "bench/bound/bound.h"
#include "bench/cli/cli_common.h"
#include "bench/cli/commands.h"
#include "bench/fuzz/campaign.h"
#include "bench/fuzz/known_findings.h"
#include "bench/fuzz/worst_case.h"
#include "bench/pipeline/stats.h"
#include "bench/sweep/sweep.h"

namespace depthbench::cli {
namespace {

// Fuzz cases and the search's candidates are perspective frames (a field
// of view, the arithmetic bound's ray): an orthographic domain is measured
// by run, fit and choose, not fuzzed.
Status CheckFuzzable(const Domain& domain) {
  if (!domain.orthographic) return Status::Ok();
  return InvalidArgument(
      "fuzz: orthographic domains are not fuzzed yet (its cases and bounds are perspective "
      "frames); measure one with run, fit or choose");
}

struct FuzzFlags {
  double seconds = 30;
  std::string cases;
  std::uint64_t seed = 1;
  std::vector<std::string> corpus;  // default: the data folder's fuzz/corpus/formulas
  std::string out = "fuzz-findings";
  std::string known;  // default: the data folder's fuzz/known_findings.json; "none": no file
  bool search = false;
  int prove = 0;  // splits per cell of the proven bounds (0: none)
  std::string against_random;
  bool quiet = false;
  DomainFlags domain;
  CellFlags cells;
  BackendFlags backends;
};

std::string DescribeCase(const FuzzCase& c) {
  const Frame& f = c.frame;
  std::string depth = c.sample.pick == DepthPick::kEyeDepth     ? fmt::format("eye depth {:.6g}", c.sample.eye_depth)
                      : c.sample.pick == DepthPick::kStoredZero ? "stored 0"
                      : c.sample.pick == DepthPick::kStoredOne  ? "stored 1"
                      : c.sample.pick == DepthPick::kStoredAfterZero ? "first stored value above 0"
                                                                     : "last stored value below 1";
  return fmt::format(
      "fov {:.4g}, aspect {:.4g}, near {:.4g}, far/near {:.3g}, camera at {:.3g}, pixel ({}, {}) of "
      "{}x{}, {}",
      f.fov_y_degrees, f.aspect, f.near, f.ratio(), f.camera_distance(), c.sample.x, c.sample.y, f.width, f.height,
      depth);
}

// The bounds `depthbench bound` proves for `cells` over `domain`, with
// --prove's splits; the cells that have none are said.
Expected<std::vector<bound::CellBound>> Prove(const FuzzFlags& f, const Domain& domain, const std::vector<Cell>& cells,
                                              const TextOutput& out) {
  DB_ASSIGN_OR_RETURN(std::vector<bound::CellBound> bounds,
                      ProveCells(domain, cells, f.backends.shaders, f.prove, f.quiet, "prove"));
  const auto unbounded =
      std::count_if(bounds.begin(), bounds.end(), [](const bound::CellBound& b) { return !std::isfinite(b.total); });
  if (unbounded > 0) {
    out.text << fmt::format(
        "--prove: {} of {} cells have no proven bound over this domain (depthbench bound says "
        "why); they are held to the other checks only\n",
        unbounded, bounds.size());
  }
  return bounds;
}

// The campaign's proven bound of each (cell, backend), cells major: the
// shader part's under the Vulkan rules on a Vulkan backend, under exact
// rounding on the CPU's.
Expected<std::vector<double>> ProvenBounds(const FuzzFlags& f, const CampaignOptions& options,
                                           std::span<Backend* const> backends, const TextOutput& out) {
  DB_ASSIGN_OR_RETURN(const std::vector<bound::CellBound> bounds, Prove(f, options.domain, options.cells, out));
  std::vector<double> proven;
  for (const bound::CellBound& b : bounds) {
    for (const Backend* backend : backends)
      proven.push_back(backend->name() == "cpu" ? b.exact_shader : b.device_shader);
  }
  return proven;
}

// The same machines' bounds at single samples, for each batch's worst.
Expected<SampleBound> SampleBoundsOf(const FuzzFlags& f, const std::vector<Cell>& cells) {
  std::filesystem::path shader_dir = f.backends.shaders;
  if (shader_dir.empty()) DB_RETURN_IF_ERROR(StoreInto(DataPath("shaders"), shader_dir));
  DB_ASSIGN_OR_RETURN(const bound::SampleBounds bounds, bound::SampleBounds::Make(cells, shader_dir));
  return SampleBound([bounds](const Cell& cell, std::string_view backend, const Frame& frame, std::uint32_t x,
                              std::uint32_t y, float stored) {
    const Expected<double> b = bounds.At(cell, frame, x, y, Enclosure(stored),
                                         backend == "cpu" ? bound::kExactlyRounded : bound::kVulkanDevice);
    return b.ok() ? *b : INFINITY;
  });
}

Expected<std::vector<KnownFinding>> KnownFindings(const FuzzFlags& f) {
  if (f.known == "none") return std::vector<KnownFinding>{};
  std::filesystem::path path = f.known;
  if (path.empty()) DB_RETURN_IF_ERROR(StoreInto(DataPath("fuzz/known_findings.json"), path));
  Expected<std::vector<KnownFinding>> known = ReadKnownFindings(path);
  if (!known.ok()) return known.status().WithContext("--known");
  return known;
}

// Findings of one cell and kind, merged over the backends that agree.
struct FindingGroup {
  const CampaignFinding* first;
  std::vector<std::string> backends;
  std::uint64_t hits = 0;
  const KnownFinding* known;
};

void PrintFindings(const std::vector<FindingGroup>& groups, const TextOutput& out) {
  using Align = TextTable::Align;
  TextTable table({{"finding", Align::kLeft},
                   {"backends", Align::kLeft},
                   {"hits"},
                   {"shader bits lost"},
                   {"bound"},
                   {"shrunk case", Align::kLeft},
                   {"reproducer", Align::kLeft}});
  for (const FindingGroup& g : groups) {
    const CampaignFinding& finding = *g.first;
    const Judgement& j = finding.judgement;
    table.AddRow({fmt::format("{} {}", finding.cell.Name(), FindingKindName(finding.kind)),
                  fmt::format("{}", fmt::join(g.backends, ", ")), std::to_string(g.hits),
                  std::isfinite(j.arith) ? fmt::format("{:.1f}", BitsLost(j.arith)) : (j.nan ? "NaN" : "Inf"),
                  fmt::format("{:.1f}", BitsLost(j.bound)), DescribeCase(finding.shrunk),
                  finding.file.empty() ? "-" : "depthbench run --repro " + finding.file.string()});
  }
  table.Print(out);
}

Expected<int> Campaign(const FuzzFlags& f, const std::vector<Cell>& cells, std::span<Backend* const> backends,
                       const CommandContext& context) {
  const TextOutput& out = context.output;
  DB_ASSIGN_OR_RETURN(const std::vector<KnownFinding> known, KnownFindings(f));
  CampaignOptions options;
  options.seconds = f.seconds;
  if (!f.cases.empty()) {
    DB_ASSIGN_OR_RETURN(options.cases, ParseCount(f.cases, "--cases"));
    options.seconds = 0;
  }
  options.seed = f.seed;
  options.cells = cells;
  for (const std::string& c : f.corpus) options.corpus.emplace_back(c);
  if (f.corpus.empty()) {
    DB_ASSIGN_OR_RETURN(std::filesystem::path seeds, DataPath("fuzz/corpus/formulas"));
    options.corpus.push_back(std::move(seeds));
  }
  options.out = f.out;
  DB_ASSIGN_OR_RETURN(options.domain, f.domain.Apply(FuzzDomain(), context.catalogue));
  DB_RETURN_IF_ERROR(CheckFuzzable(options.domain));
  // The campaign's cases (and the reproducers it writes) carry no pipeline
  // model: they are produced as a GPU does, with exactly rounded constants.
  const Domain defaults;
  if (options.domain.production != defaults.production || options.domain.constants != defaults.constants) {
    return InvalidArgument(
        "--production and --constants apply to fuzz --search only: the campaign's cases and reproducers use float32 "
        "production and exact constants");
  }
  options.cells = CellsForDomain(cells, options.domain);
  if (f.prove > 0) {
    DB_RETURN_IF_ERROR(StoreInto(ProvenBounds(f, options, backends, out), options.proven));
    DB_RETURN_IF_ERROR(StoreInto(SampleBoundsOf(f, options.cells), options.sample_bound));
  }
  Progress progress("fuzz", StderrIsTerminal(), f.quiet);
  options.progress = [&](double fraction, const std::string& line) { progress.Update(fraction, line); };
  DB_ASSIGN_OR_RETURN(const CampaignResult result, RunCampaign(options, backends));
  if (!f.quiet) progress.Finish(fmt::format("{} inputs", result.cases));

  out.text << fmt::format(
      "fuzz: {} inputs ({} from the corpus, {} at the domain's extremes, {} random, {} mutated) through {} cells on "
      "{}: {} checks in {:.1f} s ({:.0f} inputs/s)\n",
      result.cases, result.from_corpus * kSamplesPerFrame, result.from_extremes * kSamplesPerFrame,
      result.from_random * kSamplesPerFrame, result.from_mutation * kSamplesPerFrame, options.cells.size(),
      backends.size() == 1 ? backends[0]->name() : "cpu and vulkan", result.checks, result.seconds,
      result.cases / std::max(result.seconds, 1e-9));
  out.text << fmt::format(
      "invariants: finite output where the reference is finite; arithmetic error within "
      "{}x2^-24 x (depth + ray + world condition numbers){}\n",
      kRoundings, options.proven.empty() ? "" : "; shader part of judged samples within the proven bound");
  if (options.sample_bound) {
    const CaseChecker::SampleBoundReach& reach = result.sample_bound_reach;
    out.text << fmt::format(
        "bounds at single samples: {} samples (each batch's worst of every cell and backend) held against the bound "
        "proven at their own inputs, {} of them under 24 bits; of those, {} within one bit of it, the closest at {:.3f} "
        "of it{}\n",
        reach.held, reach.below_24_bits, reach.within_one_bit, reach.closest,
        reach.closest_cell.empty() ? "" : " (" + reach.closest_cell + ")");
  }
  if (result.findings.empty()) {
    out.text << fmt::format("no findings; closest: {} at {:.2f} of its bound\n", result.closest_cell, result.closest);
    return kExitOk;
  }
  // Grouped by cell, kind and known reason (backends that agree merged),
  // new ones first, then the known ones under their reason.
  std::vector<FindingGroup> groups;
  for (const CampaignFinding& finding : result.findings) {
    const KnownFinding* reason = FindKnown(known, finding.cell, finding.kind, finding.backend);
    auto same = std::find_if(groups.begin(), groups.end(), [&](const FindingGroup& g) {
      return g.first->cell == finding.cell && g.first->kind == finding.kind && g.known == reason;
    });
    if (same == groups.end()) {
      groups.push_back({&finding, {}, 0, reason});
      same = groups.end() - 1;
    }
    same->backends.push_back(finding.backend);
    same->hits += finding.hits;
  }
  std::vector<FindingGroup> fresh, accepted;
  for (const FindingGroup& g : groups) (g.known == nullptr ? fresh : accepted).push_back(g);
  if (!fresh.empty()) {
    out.text << fmt::format(
        "{} new shader findings (a NaN, an Inf or an error beyond the bound where exact arithmetic on the shader's "
        "inputs is fine; each shrunk):\n",
        fresh.size());
    PrintFindings(fresh, out);
  } else {
    out.text << "no new findings\n";
  }
  if (!accepted.empty()) {
    out.text << fmt::format("\n{} known findings (the known-findings file says why each is accepted):\n",
                            accepted.size());
    std::vector<const KnownFinding*> reasons;
    for (const FindingGroup& g : accepted) {
      if (std::find(reasons.begin(), reasons.end(), g.known) == reasons.end()) reasons.push_back(g.known);
    }
    for (const KnownFinding* k : reasons) {
      std::vector<std::string> cells;
      for (const FindingGroup& g : accepted) {
        if (g.known == k) cells.push_back(g.first->cell.Name());
      }
      out.text << fmt::format("- {} {} in {} cells ({}): {}\n", Info(k->variant).name, FindingKindName(k->kind),
                              cells.size(), fmt::join(cells, ", "), k->reason);
    }
  }
  return fresh.empty() ? kExitOk : kExitFinding;
}

Expected<int> Search(const FuzzFlags& f, const std::vector<Cell>& cells, std::span<Backend* const> backends,
                     const CommandContext& context) {
  const TextOutput& out = context.output;
  DB_ASSIGN_OR_RETURN(const Domain domain, f.domain.Apply(Domain{}, context.catalogue));
  DB_RETURN_IF_ERROR(CheckFuzzable(domain));
  std::uint64_t random_samples = 0;
  if (!f.against_random.empty()) {
    DB_ASSIGN_OR_RETURN(random_samples, ParseCount(f.against_random, "--against-random"));
  }
  Backend& backend = *backends.front();
  std::vector<TextTable::Column> columns = {{"cell", TextTable::Align::kLeft},
                                            {"search: worst bits lost"},
                                            {"evaluations"},
                                            {"seconds"},
                                            {"random: worst bits lost"},
                                            {"samples"},
                                            {"seconds"},
                                            {"search >= random"}};
  if (f.prove > 0) columns.insert(columns.end(), {{"proven total bound"}, {"within"}});
  TextTable table(columns);
  std::vector<bound::CellBound> proven;
  if (f.prove > 0) DB_RETURN_IF_ERROR(StoreInto(Prove(f, domain, CellsForDomain(cells, domain), out), proven));
  bool all_found = true;
  for (const Cell& cell : CellsForDomain(cells, domain)) {
    SearchOptions options;
    options.cell = cell;
    options.domain = domain;
    options.seed = f.seed;
    options.seconds = f.seconds;
    Progress progress(cell.Name(), StderrIsTerminal(), f.quiet);
    options.progress = [&](double fraction, double worst) {
      progress.Update(fraction, fmt::format("worst {:.2f} bits lost", BitsLost(worst)));
    };
    DB_ASSIGN_OR_RETURN(const SearchResult found, SearchWorstCase(options, backend));
    if (!f.quiet) progress.Finish(fmt::format("{:.2f} bits lost", BitsLost(found.worst)));
    std::vector<std::string> row = {cell.Name(), fmt::format("{:.3f}", BitsLost(found.worst)),
                                    ShortCount(static_cast<double>(found.evaluations)),
                                    fmt::format("{:.1f}", found.seconds)};
    if (random_samples > 0) {
      SweepOptions sweep;
      sweep.samples = random_samples;
      sweep.seed = f.seed;
      sweep.domain = domain;
      sweep.cells = {cell};
      Backend* only[] = {&backend};
      DB_ASSIGN_OR_RETURN(const Results results, RunSweep(sweep, only));
      const double random_worst = results.cells.front().stats.All()[Metric::kTotal].max();
      const bool ok = found.worst >= random_worst;
      all_found = all_found && ok;
      row.insert(row.end(),
                 {fmt::format("{:.3f}", BitsLost(random_worst)), ShortCount(static_cast<double>(random_samples)),
                  fmt::format("{:.1f}", results.run.seconds), ok ? "yes" : "NO"});
    } else {
      row.insert(row.end(), {"-", "-", "-", "-"});
    }
    if (!proven.empty()) {
      // The search maximizes the whole error: its worst, and so every
      // input it judged, lies within the whole's bound (the Vulkan rules
      // allow more than the CPU's exact rounding).
      const double total =
          std::find_if(proven.begin(), proven.end(), [&](const auto& b) { return b.cell == cell; })->total;
      const bool within = found.worst <= total;
      all_found = all_found && within;
      row.insert(row.end(), {std::isfinite(total) ? fmt::format("{:.3f}", bound::BoundBits(total)) : "none",
                             within ? "yes" : "NO"});
    }
    table.AddRow(row);
    if (!f.quiet) std::cerr << "  worst input of " << cell.Name() << ": " << DescribeCase(found.worst_case) << "\n";
  }
  out.text << fmt::format("worst-case search on {} ({}), {:.1f} s per cell, domain {}\n", backend.name(),
                          backend.device().name, f.seconds, domain.Describe());
  table.Print(out);
  return all_found ? kExitOk : kExitFinding;
}

Expected<int> Fuzz(const FuzzFlags& f, const CommandContext& context) {
  if (!(f.seconds > 0)) return InvalidArgument(fmt::format("--seconds: must be positive (got {})", f.seconds));
  DB_ASSIGN_OR_RETURN(const std::vector<Cell> cells, f.cells.Select(context.catalogue));
  if (!f.search && !f.out.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(f.out, ec);
    DB_RETURN_IF_ERROR(CheckDirectory(f.out, "folder").WithContext("--out"));
    DB_RETURN_IF_ERROR(CheckWritable(f.out + "/.probe", "--out"));
  }
  BackendFlags backend_flags = f.backends;
  if (f.search && backend_flags.backends.size() > 1) backend_flags.backends = {"cpu"};
  DB_ASSIGN_OR_RETURN(const BackendSet made, backend_flags.Make(context.catalogue));
  return f.search ? Search(f, cells, made.view(), context) : Campaign(f, cells, made.view(), context);
}

}  // namespace

void AddFuzzCommand(CLI::App& app, CommandAction& action) {
  auto flags = std::make_shared<FuzzFlags>();
  CLI::App* cmd = app.add_subcommand(
      "fuzz",
      "Fuzz every cell on the GPU and the CPU together with adversarial inputs (the corpus, the extremes of every "
      "range, random and mutated points), or search each cell's worst case (--search)");
  cmd->footer(
      "Invariants: where the reference is finite the output must be finite, and the arithmetic error (from the "
      "value the texel holds) must stay within a first-order rounding bound (bench/fuzz/case_check.h). Findings "
      "are deduplicated by cell, backend and kind, written to --out as reproducer files as soon as they are found, "
      "then shrunk and rewritten at the end; exit 1 when there are any. SIGINT or SIGTERM stops the campaign after "
      "the batch or the file in hand (exit 130 or 143), keeping the reproducers written so far.\n\n"
      "The fuzz domain spans the extremes catalogue: near 1e-7 to 10, far/near 10 to 1e9 (and infinite far "
      "planes), fov 0.01 to 179.9 degrees, aspect 1e-3 to 1e3, cameras up to 1e7 from the origin; the domain "
      "flags narrow it.\n\n"
      "Examples:\n"
      "  depthbench fuzz --seconds 60 --out findings/\n"
      "  depthbench run --repro findings/divide_standard_d32_sfloat_cpu_beyond_bound.json\n"
      "  depthbench fuzz --search --seconds 2 --against-random 1e8 --variant divide --convention standard");
  cmd->add_option("--seconds", flags->seconds, "how long to fuzz (default 30); with --search, the time per cell");
  cmd->add_option("--cases", flags->cases, "stop after this many inputs instead of a time");
  cmd->add_option("--seed", flags->seed, "random seed of the mutations and of the search (default 1)");
  cmd->add_option(
      "--corpus", flags->corpus,
      "files or folders of inputs to run first (default: the seed corpus, fuzz/corpus/formulas of the data folder)");
  cmd->add_option("--out", flags->out, "folder for the reproducer files (default fuzz-findings)");
  cmd->add_option("--known", flags->known,
                  "the known-findings file: findings it lists, each with its reason, are reported apart and do not "
                  "fail the run (default: fuzz/known_findings.json of the data folder; none: every finding fails)")
      ->type_name("FILE|none");
  cmd->add_option("--prove", flags->prove,
                  "hold every judged sample against the bound depthbench bound proves for its cell over the domain, "
                  "proven with this many splits per cell (0, the default: not), and each batch's worst samples "
                  "against the bound proven at their own inputs; a sample beyond either is a finding of its own "
                  "kind, beyond_proven_bound: a wrong bound, or a device outside the Vulkan rounding rules");
  cmd->add_flag("--search", flags->search,
                "search each cell's worst case (largest total error) in the default domain, narrowed by the domain "
                "flags, on the CPU backend unless --backend says otherwise");
  cmd->add_option("--against-random", flags->against_random,
                  "with --search: also draw this many random samples per cell (e.g. 1e8) and compare the worst error "
                  "and the time");
  cmd->add_flag("--quiet", flags->quiet, "no progress line");
  flags->domain.Add(*cmd);
  flags->cells.Add(*cmd);
  flags->backends.Add(*cmd);
  cmd->callback(
      [flags, &action] { action = [flags](const CommandContext& context) { return Fuzz(*flags, context); }; });
}

}  // namespace depthbench::cli
