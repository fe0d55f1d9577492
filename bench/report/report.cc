#include "bench/report/report.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "bench/base/environment.h"
#include "bench/choose/choose.h"
#include "bench/gate/gate.h"
#include "bench/pipeline/bands.h"
#include "bench/speed/trade.h"
#include "bench/sweep/repro.h"

namespace depthbench {
namespace {

using json = nlohmann::json;

// The far/near ratios whose error-versus-depth curves the page draws (the
// infinite sweep too): the decades the depth-precision literature plots.
const double kDepthCurveRatios[] = {1e2, 1e4, 1e6, 1e8, INFINITY};
// The levels of the precision-loss chart.
const Level kChartLevels[] = {Level::kP999, Level::kMax};
// The far/near ratios of the speed/accuracy front: a small, a typical and a
// large scene.
const double kFrontRatios[] = {1e2, 1e4, 1e6};
// Backend differences smaller than this are the statistics' resolution
// (quarter-octave bins: a p99.9 is known to a quarter of a bit).
constexpr double kNotableDifferenceBits = kBitsResolution;
constexpr std::size_t kMostWorstSamples = 40;
constexpr std::size_t kMostDifferences = 40;

// A number for the page: four significant digits (the statistics hold no
// more), null when not finite (JSON has no infinity; the schema says what
// null means where it may appear).
json Num(double x) {
  if (!std::isfinite(x)) return nullptr;
  return std::stod(fmt::format("{:.4g}", x));
}

// "1e4", "1e3.5", "inf".
std::string RatioLabel(double ratio) {
  if (std::isinf(ratio)) return "inf";
  return fmt::format("1e{:g}", std::round(std::log10(ratio) * 100.0) / 100.0);
}

json Log10Ratio(double ratio) { return std::isinf(ratio) ? json(nullptr) : Num(std::log10(ratio)); }

// The columns every row about a cell starts with.
json CellRow(const Cell& cell, const std::string& backend) {
  return {{"variant", Info(cell.variant).name},
          {"convention", Info(cell.convention).name},
          {"format", Info(cell.format).name},
          {"backend", backend}};
}

double P999Bits(const BandStats& band, Metric metric) { return BitsLost(band[metric].AtLevel(Level::kP999, metric)); }

// What a model says at (x, y), with its 95% interval.
Estimate ModelAt(const FittedModel& model, double x, double y) {
  return EstimateOf(model, [x, y](const FittedModel& m) { return m.Predict(x, y); });
}

// A fit's measured bands beside what its model says at each: every band of
// the ratios in `ratios` (empty: all), or only the deepest eye-depth decade
// of each ratio (the one the far plane lies in). A band whose quantile is
// not finite (NaN/Inf outputs past the level) or below the statistics'
// resolution has no measured value, and says which.
json ModelAlongPoints(const PrecisionFit& fit, const FitSweeps& sweeps, const FitPlan& plan, bool deepest_only,
                      std::span<const double> ratios, bool relative) {
  const std::vector<BandPoint> bands = CollectBandPoints(sweeps, fit.cell, fit.backend, fit.metric, fit.level);
  std::map<double, int> deepest;  // ratio -> deepest depth band
  for (const BandPoint& p : bands) {
    auto [it, added] = deepest.try_emplace(p.ratio, p.depth_band);
    if (!added) it->second = std::max(it->second, p.depth_band);
  }
  // Bits, or the relative error they stand for.
  auto value = [relative](double b) { return Num(relative ? std::ldexp(std::exp2(b), -24) : b); };
  json rows = json::array();
  for (const BandPoint& band : bands) {
    if (deepest_only && band.depth_band != deepest[band.ratio]) continue;
    if (!ratios.empty() && std::none_of(ratios.begin(), ratios.end(), [&](double r) {
          return std::isinf(r) ? std::isinf(band.ratio) : std::fabs(std::log10(r) - std::log10(band.ratio)) < 1e-6;
        })) {
      continue;
    }
    const FitPoint& p = band.point;
    const Estimate model = ModelAt(fit.model, p.x, p.y);
    const bool held_out = std::any_of(plan.held_out.begin(), plan.held_out.end(),
                                      [&](double r) { return std::fabs(std::log2(r) - p.x) < 1e-9; });
    json row = CellRow(fit.cell, fit.backend);
    row["level"] = LevelName(fit.level);
    row["ratio"] = RatioLabel(band.ratio);
    row["log10_ratio"] = Log10Ratio(band.ratio);
    row["depth"] = Num(std::exp2(p.y));
    row["measured"] = band.modelled ? value(p.b) : json(nullptr);
    row["state"] = band.modelled ? "measured" : std::isinf(p.b) ? "not finite" : "below resolution";
    row["model"] = value(model.value);
    row["low"] = value(model.low);
    row["high"] = value(model.high);
    row["held_out"] = !fit.infinite_far && held_out;
    rows.push_back(std::move(row));
  }
  return rows;
}

json BudgetJson(const PrecisionFit& fit, const char* budget) {
  auto it = fit.budget_ratio.find(budget);
  if (it == fit.budget_ratio.end()) return nullptr;  // infinite far: no ratio to speak of
  if (!it->second) return "always";
  if (*it->second == 0.0) return "never";
  return Num(*it->second);
}

// The sweep a result came from, in words, and its repro command.
std::string SweepName(const Results& r) {
  if (!r.run.domain.finite_far) return "f/n inf";
  if (r.run.domain.ratio.min == r.run.domain.ratio.max && !r.run.domain.infinite_far) {
    return "f/n " + RatioLabel(r.run.domain.ratio.min);
  }
  return "default domain";
}

json HeadlineRows(const ReportMeasurements& m) {
  json rows = json::array();
  for (const PrecisionFit& f : m.fits) {
    if (f.metric != Metric::kTotal || f.level != Level::kP999) continue;
    json row = CellRow(f.cell, f.backend);
    row["cell"] = f.cell.Name();
    row["infinite_far"] = f.infinite_far;
    row["model"] = Info(f.model.kind).name;
    row["points"] = f.points;
    if (f.infinite_far) {
      row["slope"] = row["slope_low"] = row["slope_high"] = nullptr;
    } else {
      row["slope"] = Num(f.slope);
      row["slope_low"] = Num(f.slope_low);
      row["slope_high"] = Num(f.slope_high);
    }
    json predicted = json::object();
    for (const auto& [name, bits] : f.predicted) predicted[name] = Num(bits);
    row["predicted_bits"] = predicted;
    row["ratio_for_1e-3"] = BudgetJson(f, "1e-3");
    row["ratio_for_1e-6"] = BudgetJson(f, "1e-6");
    row["holdout_max_miss"] = f.holdout_points > 0 ? Num(f.holdout_max_miss) : json(nullptr);
    if (const CellResult* r = m.main.Find(f.cell, f.backend)) {
      const BandStats all = r->stats.All();
      row["p999_bits"] = Num(P999Bits(all, Metric::kTotal));
      row["max_bits"] = Num(BitsLost(all[Metric::kTotal].max()));
      row["nan"] = all.nan;
      row["inf"] = all.inf;
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

json SplitRows(const FitSweeps& sweeps) {
  json rows = json::array();
  for (std::size_t k = 0; k < sweeps.results.size(); ++k) {
    for (const CellResult& c : sweeps.results[k].cells) {
      const BandStats all = c.stats.All();
      if (all.finite < MinimumSamples(Level::kP999)) continue;
      json row = CellRow(c.cell, c.backend);
      row["ratio"] = RatioLabel(sweeps.ratios[k]);
      row["log10_ratio"] = Log10Ratio(sweeps.ratios[k]);
      row["total"] = Num(P999Bits(all, Metric::kTotal));
      row["storage"] = Num(P999Bits(all, Metric::kStorage));
      row["arith"] = Num(P999Bits(all, Metric::kArith));
      rows.push_back(std::move(row));
    }
  }
  return rows;
}

// Where the GPU and the CPU disagree by more than the statistics resolve.
json BackendDifferences(const FitSweeps& sweeps, std::span<const std::string> backends) {
  struct Difference {
    double size;
    json row;
  };
  std::vector<Difference> found;
  double largest = 0.0;
  std::size_t compared = 0;
  if (backends.size() >= 2) {
    for (std::size_t k = 0; k < sweeps.results.size(); ++k) {
      for (const CellResult& a : sweeps.results[k].cells) {
        if (a.backend != backends[0]) continue;
        const CellResult* b = sweeps.results[k].Find(a.cell, backends[1]);
        if (b == nullptr) continue;
        const BandStats sa = a.stats.All(), sb = b->stats.All();
        if (sa.finite < MinimumSamples(Level::kP999)) continue;
        ++compared;
        for (Metric metric : {Metric::kTotal, Metric::kArith}) {
          const double x = P999Bits(sa, metric), y = P999Bits(sb, metric);
          const double d = y - x;
          largest = std::max(largest, std::fabs(d));
          if (std::fabs(d) <= kNotableDifferenceBits) continue;
          json row = CellRow(a.cell, "");
          row.erase("backend");
          row["ratio"] = RatioLabel(sweeps.ratios[k]);
          row["metric"] = MetricName(metric);
          row[backends[0]] = Num(x);
          row[backends[1]] = Num(y);
          row["difference"] = Num(d);
          found.push_back({std::fabs(d), std::move(row)});
        }
      }
    }
  }
  std::stable_sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.size > b.size; });
  json rows = json::array();
  for (std::size_t i = 0; i < found.size() && i < kMostDifferences; ++i) rows.push_back(found[i].row);
  return {{"backends", backends.size() >= 2 ? json{backends[0], backends[1]} : json::array()},
          {"compared", compared},
          {"notable", found.size()},
          {"largest_bits", Num(largest)},
          {"threshold_bits", kNotableDifferenceBits},
          {"rows", rows}};
}

// NaN/Inf findings of every sweep, and the worst samples of the default one.
json Findings(const ReportMeasurements& m) {
  json nonfinite = json::array();
  auto scan = [&](const Results& r) {
    for (const CellResult& c : r.cells) {
      const BandStats all = c.stats.All();
      if (all.nan + all.inf == 0) continue;
      json row = CellRow(c.cell, c.backend);
      row["sweep"] = SweepName(r);
      row["nan"] = all.nan;
      row["inf"] = all.inf;
      row["judged"] = all.judged();
      row["first_index"] = all.first_nonfinite_index;
      row["command"] = ReproCommand(r.run.seed, all.first_nonfinite_index, r.run.domain, c.cell, c.backend);
      nonfinite.push_back(std::move(row));
    }
  };
  scan(m.main);
  for (const Results& r : m.sweeps.results) scan(r);

  std::vector<std::pair<double, json>> worst;
  for (const CellResult& c : m.main.cells) {
    const BandStats all = c.stats.All();
    const MetricStats& total = all[Metric::kTotal];
    if (total.Count() == 0) continue;
    json row = CellRow(c.cell, c.backend);
    row["bits"] = Num(BitsLost(total.max()));
    row["relative"] = Num(total.max());
    row["index"] = total.worst_index;
    row["command"] = ReproCommand(m.main.run.seed, total.worst_index, m.main.run.domain, c.cell, c.backend);
    worst.emplace_back(std::isfinite(total.max()) ? total.max() : INFINITY, std::move(row));
  }
  std::stable_sort(worst.begin(), worst.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  json worst_rows = json::array();
  for (std::size_t i = 0; i < worst.size() && i < kMostWorstSamples; ++i) worst_rows.push_back(worst[i].second);
  return {{"nonfinite", nonfinite}, {"worst", worst_rows}};
}

// One candidate of a speed/accuracy front.
struct FrontEntry {
  Cell cell;
  FrontCandidate candidate;
  std::uint64_t nonfinite = 0;
};

// Marks the front of each (convention, format) among `entries` and adds
// them as rows of `source` at far/near `ratio`.
void AddFronts(const std::string& source, double ratio, const std::vector<FrontEntry>& entries, json& rows) {
  std::map<std::pair<Convention, Format>, std::vector<std::size_t>> groups;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    groups[{entries[i].cell.convention, entries[i].cell.format}].push_back(i);
  }
  for (const auto& [encoding, members] : groups) {
    std::vector<FrontCandidate> candidates;
    for (std::size_t i : members) candidates.push_back(entries[i].candidate);
    const std::vector<bool> on_front = ParetoFront(candidates);
    for (std::size_t k = 0; k < members.size(); ++k) {
      const FrontEntry& e = entries[members[k]];
      json row = CellRow(e.cell, "");
      row.erase("backend");
      row["source"] = source;
      row["ratio"] = RatioLabel(ratio);
      row["cost"] = Num(e.candidate.cost);
      row["spread"] = Num(e.candidate.spread);
      row["bits"] = Num(e.candidate.bits_lost);
      row["nonfinite"] = e.nonfinite;
      row["on_front"] = static_cast<bool>(on_front[k]);
      rows.push_back(std::move(row));
    }
  }
}

// On the front, bits lost stop at every bit: a relative error of 1 or more
// leaves nothing of the position right. (AccuracyOf already counts a cell
// whose NaN/Inf outputs pass p99.9 as losing every bit.)
double FrontBits(double p999_bits) { return std::min(p999_bits, kAllBitsLost); }

// The speed/accuracy front at the far/near ratios a scene typically has:
// the cost from each speed file (GPU time per reconstruction) and from the
// instruction mix (which always exists), the accuracy from this report's
// sweep at that ratio on the GPU backend.
Expected<json> SpeedSection(const ReportPlan& plan, const ReportMeasurements& m) {
  json rows = json::array(), sources = json::array();
  const Expected<std::string> trade_backend = TradeBackend(m.main);
  const std::string backend = trade_backend.ok() ? *trade_backend : "cpu";
  std::string device;
  for (const BackendRecord& b : m.main.run.backends) {
    if (b.name == backend) device = b.device.name;
  }
  const std::string accuracy = fmt::format(
      "this report's sweep at the chosen far/near (camera at the origin) on the {} backend ({})", backend, device);
  DB_ASSIGN_OR_RETURN(CostLookup lanes, StaticCostLookup(plan.shader_dir.string()));

  for (std::size_t k = 0; k < m.sweeps.ratios.size(); ++k) {
    const double ratio = m.sweeps.ratios[k];
    if (std::none_of(std::begin(kFrontRatios), std::end(kFrontRatios),
                     [&](double r) { return std::fabs(std::log10(r) - std::log10(ratio)) < 1e-6; })) {
      continue;
    }
    const Results& at = m.sweeps.results[k];
    for (const auto& [path, speed] : m.speed) {
      if (speed.gpu.empty()) continue;
      std::vector<std::string> left_out;
      std::vector<FrontEntry> entries;
      for (const TradeFront& front : BuildTrade(speed, at, backend, speed.run.trade_resolution, left_out)) {
        for (const TradePoint& p : front.points) {
          entries.push_back({Cell{p.variant, front.convention, front.format},
                             {p.gpu_ns_per_reconstruction, p.gpu_spread_ns, FrontBits(p.p999_bits_lost)},
                             p.nonfinite});
        }
      }
      AddFronts(fmt::format("{} ({})", speed.run.device.name, path.filename().string()), ratio, entries, rows);
    }
    std::vector<FrontEntry> entries;
    for (const CellResult& c : at.cells) {
      const std::optional<CandidateCost> cost = c.backend == backend ? lanes(c.cell) : std::nullopt;
      if (!cost) continue;
      const CellAccuracy cell = AccuracyOf(c.stats);
      entries.push_back({c.cell, {cost->value, 0.0, FrontBits(cell.p999_bits_lost)}, cell.nonfinite});
    }
    AddFronts("instruction count", ratio, entries, rows);
  }
  for (const auto& [path, speed] : m.speed) {
    if (speed.gpu.empty()) continue;
    sources.push_back({{"source", fmt::format("{} ({})", speed.run.device.name, path.filename().string())},
                       {"cost_unit", fmt::format("GPU ns per reconstruction, ALU-bound, {} (measured {})",
                                                 ResolutionName(speed.run.trade_resolution), speed.run.started_at)},
                       {"accuracy", accuracy}});
  }
  sources.push_back({{"source", "instruction count"},
                     {"cost_unit", "SPIR-V arithmetic lanes of the compiled shader"},
                     {"accuracy", accuracy}});
  return json{{"sources", sources}, {"rows", rows}};
}

json EnvironmentJson(const ReportPlan& plan, const ReportMeasurements& m) {
  json backends = json::array();
  for (const BackendRecord& b : m.main.run.backends) {
    backends.push_back({{"name", b.name}, {"device", DeviceToJson(b.device)}});
  }
  json stages = json::array();
  double seconds = 0.0;
  for (const auto& [stage, s] : m.stage_seconds) {
    stages.push_back({{"stage", stage}, {"seconds", Num(s)}});
    seconds += s;
  }
  json ratios = json::array();
  for (double r : m.sweeps.ratios) ratios.push_back(RatioLabel(r));
  json speed_files = json::array();
  for (const auto& [path, speed] : m.speed) speed_files.push_back(path.string());
  return {{"version", m.main.run.version},
          {"commit", m.main.run.commit},
          {"host", m.main.run.host},
          {"started_at", m.main.run.started_at},
          {"seconds", Num(seconds)},
          {"stages", stages},
          {"backends", backends},
          {"quick", plan.quick},
          {"fit_sweeps",
           {{"seed", plan.fit.seed},
            {"samples_per_ratio", plan.fit.samples_per_ratio},
            {"ratios", ratios},
            {"held_out", json(plan.fit.held_out)},
            {"domain", plan.fit.domain.Describe()}}},
          {"default_sweep",
           {{"seed", m.main.run.seed},
            {"samples", m.main.run.samples},
            {"reconstructions", m.main.run.reconstructions},
            {"domain", m.main.run.domain.Describe()}}},
          {"speed_files", speed_files}};
}

}  // namespace

ReportPlan ReportPlan::Nightly() {
  ReportPlan plan;
  plan.fit.samples_per_ratio = 300000;
  plan.main_samples = 1000000;
  return plan;
}

ReportPlan ReportPlan::Quick() {
  ReportPlan plan;
  plan.quick = true;
  // Enough for a p99.9 in most depth decades (MinimumSamples: 4000 a band).
  plan.fit.samples_per_ratio = 40000;
  plan.main_samples = 100000;
  return plan;
}

Expected<ReportMeasurements> MeasureReport(const ReportPlan& plan, std::span<Backend* const> backends,
                                           const ReportProgress& progress) {
  ReportMeasurements m;
  auto stage = std::chrono::steady_clock::now();
  auto begin = [&](const std::string& name) {
    stage = std::chrono::steady_clock::now();
    if (progress.begin) progress.begin(name);
  };
  auto end = [&](const std::string& name, const std::string& summary) {
    m.stage_seconds.emplace_back(name, std::chrono::duration<double>(std::chrono::steady_clock::now() - stage).count());
    if (progress.end) progress.end(summary);
  };

  FitPlan fit_plan = plan.fit;
  fit_plan.cells = plan.cells;
  begin("sweeps at fixed far/near");
  DB_ASSIGN_OR_RETURN(m.sweeps, RunFitSweeps(fit_plan, backends, progress.sweep));
  end("sweeps at fixed far/near", fmt::format("{} far/near ratios", m.sweeps.ratios.size()));

  begin("default-domain sweep");
  SweepOptions main;
  main.seed = plan.main_seed;
  main.samples = plan.main_samples;
  main.domain = plan.main_domain;
  main.cells = CellsForDomain(plan.cells.empty() ? AllCells() : plan.cells, main.domain);
  main.progress = progress.sweep;
  DB_ASSIGN_OR_RETURN(m.main, RunSweep(main, backends));
  end("default-domain sweep", fmt::format("{} cells", m.main.cells.size()));

  begin("error models");
  const Metric metrics[] = {Metric::kTotal};
  m.fits = FitPrecision(m.sweeps, fit_plan, metrics, kAllLevels, progress.fits);
  end("error models", fmt::format("{} fits", m.fits.size()));

  begin("speed files");
  for (const std::filesystem::path& path : plan.speed_files) {
    DB_ASSIGN_OR_RETURN(SpeedResults speed, ReadSpeedResults(path));
    m.speed.emplace_back(path, std::move(speed));
  }
  end("speed files", fmt::format("{} read", m.speed.size()));
  return m;
}

nlohmann::json ReportJson(const ReportPlan& plan, const ReportMeasurements& m) {
  json precision = json::array(), depth = json::array();
  for (const PrecisionFit& f : m.fits) {
    if (f.metric != Metric::kTotal) continue;
    if (std::find(std::begin(kChartLevels), std::end(kChartLevels), f.level) != std::end(kChartLevels)) {
      for (json& row : ModelAlongPoints(f, m.sweeps, plan.fit, true, {}, false)) precision.push_back(std::move(row));
    }
    if (f.level == Level::kP999) {
      for (json& row : ModelAlongPoints(f, m.sweeps, plan.fit, false, kDepthCurveRatios, true)) {
        depth.push_back(std::move(row));
      }
    }
  }
  std::vector<std::string> backends;
  for (const BackendRecord& b : m.main.run.backends) backends.push_back(b.name);

  json report = {{"schema", kReportSchema},
                 {"schema_version", kReportSchemaVersion},
                 {"environment", EnvironmentJson(plan, m)},
                 {"headline", HeadlineRows(m)},
                 {"precision_points", precision},
                 {"depth_points", depth},
                 {"split", SplitRows(m.sweeps)},
                 {"backend_differences", BackendDifferences(m.sweeps, backends)},
                 {"findings", Findings(m)}};
  Expected<json> speed = SpeedSection(plan, m);
  report["speed"] =
      speed.ok() ? *speed
                 : json{{"sources", json::array()}, {"rows", json::array()}, {"error", speed.status().message()}};
  report["history"] = nullptr;
  return report;
}

std::vector<Baseline> HistoryFigures(const ReportMeasurements& m) {
  std::vector<Baseline> figures;
  for (const BackendRecord& b : m.main.run.backends) figures.push_back(BaselineFromResults(m.main, b.name));
  return figures;
}

Status AddHistory(nlohmann::json& report, History& history, const HistoryRun& run, std::span<const Baseline> figures,
                  int trend_runs) {
  DB_ASSIGN_OR_RETURN(std::int64_t id, history.Record(run, figures));
  DB_ASSIGN_OR_RETURN(std::int64_t runs, history.RunCount());
  json trend = json::array(), changes = json::array(), previous = json::array(), notes = json::array();
  const GateTolerance tolerance;
  for (const Baseline& now : figures) {
    DB_ASSIGN_OR_RETURN(std::vector<TrendPoint> points, history.Trend(id, now, trend_runs));
    for (const TrendPoint& p : points) {
      trend.push_back({{"run", p.run},
                       {"made_at", p.made_at},
                       {"commit", p.commit},
                       {"backend", p.backend},
                       {"cell", p.cell},
                       {"p999_bits", Num(p.total_p999)},
                       {"max_bits", Num(p.total_max)},
                       {"nonfinite", p.nonfinite}});
    }
    DB_ASSIGN_OR_RETURN(auto before, history.Previous(id, now));
    if (!before) continue;
    const auto& [before_run, before_figures] = *before;
    previous.push_back({{"backend", now.backend},
                        {"run", before_run.id},
                        {"made_at", before_run.made_at},
                        {"commit", before_run.commit}});
    DB_ASSIGN_OR_RETURN(GateComparison comparison, CompareWithBaseline(before_figures, now, tolerance));
    for (const std::string& note : comparison.notes) notes.push_back(now.backend + ": " + note);
    for (const CellVerdict& v : comparison.cells) {
      auto add = [&](const char* direction, const std::string& band, const std::vector<std::string>& reasons,
                     double before_bits, double after_bits) {
        changes.push_back({{"direction", direction},
                           {"backend", now.backend},
                           {"cell", v.cell},
                           {"band", band},
                           {"reasons", reasons},
                           {"before_p999_bits", Num(before_bits)},
                           {"after_p999_bits", Num(after_bits)}});
      };
      if (v.disappeared) add("worse", "all", {"the cell is missing from this run"}, NAN, NAN);
      for (const BandChange& c : v.worse) add("worse", c.band, c.reasons, c.before.total_p999, c.after.total_p999);
      for (const BandChange& c : v.better) add("better", c.band, c.reasons, c.before.total_p999, c.after.total_p999);
    }
  }
  report["history"] = {{"database", history.path().string()},
                       {"run", id},
                       {"runs_recorded", runs},
                       {"previous", previous},
                       {"tolerance", {{"p999_bits", tolerance.p999_bits}, {"max_bits", tolerance.max_bits}}},
                       {"notes", notes},
                       {"changes", changes},
                       {"trend", trend}};
  return Status::Ok();
}

}  // namespace depthbench
