#include "bench/report/report.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "bench/base/environment.h"
#include "bench/base/interrupt.h"
#include "bench/base/resources.h"
#include "bench/capture/depth_capture.h"
#include "bench/choose/choose.h"
#include "bench/choose/frame_cost.h"
#include "bench/gate/gate.h"
#include "bench/pipeline/bands.h"
#include "bench/speed/trade.h"
#include "bench/sweep/repro.h"

namespace depthbench {
namespace {

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
constexpr double kNotableDifferenceBits = kResolvedBits;
constexpr std::size_t kMostWorstSamples = 40;
constexpr std::size_t kMostDifferences = 40;

// "1e4", "1e3.5", "inf".
std::string RatioLabel(double ratio) {
  if (std::isinf(ratio)) return "inf";
  return fmt::format("1e{:g}", std::round(std::log10(ratio) * 100.0) / 100.0);
}

Figure Log10Ratio(double ratio) { return std::isinf(ratio) ? Figure() : Shown(std::log10(ratio)); }

CellColumns Columns(const Cell& cell, const std::string& backend = "") {
  return {std::string(cell.variant_info().name), std::string(Info(cell.convention).name),
          std::string(Info(cell.format).name), backend};
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
std::vector<ModelPointRow> ModelAlongPoints(const PrecisionFit& fit, const FitSweeps& sweeps, const FitPlan& plan,
                                            bool deepest_only, std::span<const double> ratios, bool relative) {
  const std::vector<BandPoint> bands = CollectBandPoints(sweeps, fit.cell, fit.backend, fit.metric, fit.level);
  std::map<double, int> deepest;  // ratio -> deepest depth band
  for (const BandPoint& p : bands) {
    auto [it, added] = deepest.try_emplace(p.ratio, p.depth_band);
    if (!added) it->second = std::max(it->second, p.depth_band);
  }
  // Bits (0 to 24: a model and its interval say nothing past "nothing
  // left"), or the relative error they stand for.
  auto value = [relative](double b) {
    return Shown(relative ? std::ldexp(std::exp2(b), -24) : std::clamp(b, 0.0, kAllBitsLost));
  };
  std::vector<ModelPointRow> rows;
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
    ModelPointRow row;
    row.cell = Columns(fit.cell, fit.backend);
    row.level = LevelName(fit.level);
    row.ratio = RatioLabel(band.ratio);
    row.log10_ratio = Log10Ratio(band.ratio);
    row.depth = Shown(std::exp2(p.y));
    row.measured = band.modelled ? value(p.b) : Figure();
    row.state = band.modelled     ? ModelPointRow::State::kMeasured
                : std::isinf(p.b) ? ModelPointRow::State::kNotFinite
                                  : ModelPointRow::State::kBelowResolution;
    row.model = value(model.value);
    row.low = value(model.low);
    row.high = value(model.high);
    row.held_out = !fit.infinite_far && held_out;
    rows.push_back(std::move(row));
  }
  return rows;
}

BudgetRatio Budget(const PrecisionFit& fit, const char* budget) {
  auto it = fit.budget_ratio.find(budget);
  if (it == fit.budget_ratio.end()) return {};  // infinite far: no ratio to speak of
  if (!it->second) return {BudgetRatio::Kind::kAlways, {}};
  if (*it->second == 0.0) return {BudgetRatio::Kind::kNever, {}};
  return {BudgetRatio::Kind::kRatio, Shown(*it->second)};
}

// The sweep a result came from, in words, and its repro command.
std::string SweepName(const Results& r) {
  if (!r.run.domain.finite_far) return "f/n inf";
  if (r.run.domain.ratio.min == r.run.domain.ratio.max && !r.run.domain.infinite_far) {
    return "f/n " + RatioLabel(r.run.domain.ratio.min);
  }
  return "default domain";
}

std::vector<HeadlineRow> HeadlineRows(const ReportMeasurements& m) {
  std::vector<HeadlineRow> rows;
  for (const PrecisionFit& f : m.fits) {
    if (f.metric != Metric::kTotal || f.level != Level::kP999) continue;
    HeadlineRow row;
    row.cell = Columns(f.cell, f.backend);
    row.infinite_far = f.infinite_far;
    row.model = Info(f.model.kind).name;
    row.points = f.points;
    if (!f.infinite_far) {
      row.slope = Shown(f.slope);
      row.slope_low = Shown(f.slope_low);
      row.slope_high = Shown(f.slope_high);
    }
    for (const auto& [name, bits] : f.predicted) row.predicted_bits[name] = Shown(bits);
    for (const auto& [name, interval] : f.predicted_interval) {
      row.predicted_interval[name] = {Shown(interval.first), Shown(interval.second)};
    }
    row.ratio_for_1e3 = Budget(f, "1e-3");
    row.ratio_for_1e6 = Budget(f, "1e-6");
    if (f.holdout_points > 0) row.holdout_max_miss = Shown(f.holdout_max_miss);
    if (const CellResult* r = m.main.Find(f.cell, f.backend)) {
      const BandStats all = r->stats.All();
      row.measured = HeadlineRow::Measured{Shown(P999Bits(all, Metric::kTotal)),
                                           Shown(BitsLost(all[Metric::kTotal].max())), all.nan, all.inf};
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

std::vector<SplitRow> SplitRows(const FitSweeps& sweeps) {
  std::vector<SplitRow> rows;
  for (std::size_t k = 0; k < sweeps.results.size(); ++k) {
    for (const CellResult& c : sweeps.results[k].cells) {
      const BandStats all = c.stats.All();
      if (all.finite < MinimumSamples(Level::kP999)) continue;
      rows.push_back({Columns(c.cell, c.backend), RatioLabel(sweeps.ratios[k]), Log10Ratio(sweeps.ratios[k]),
                      Shown(P999Bits(all, Metric::kTotal)), Shown(P999Bits(all, Metric::kProduction)),
                      Shown(P999Bits(all, Metric::kStorage)), Shown(P999Bits(all, Metric::kArith))});
    }
  }
  return rows;
}

// Where the GPU and the CPU disagree by more than the statistics resolve.
BackendDifferences Differences(const FitSweeps& sweeps, std::span<const std::string> backends) {
  struct Difference {
    double size;
    BackendDifferenceRow row;
  };
  std::vector<Difference> found;
  double largest = 0.0;
  BackendDifferences out;
  if (backends.size() >= 2) {
    out.backends = {backends[0], backends[1]};
    for (std::size_t k = 0; k < sweeps.results.size(); ++k) {
      for (const CellResult& a : sweeps.results[k].cells) {
        if (a.backend != backends[0]) continue;
        const CellResult* b = sweeps.results[k].Find(a.cell, backends[1]);
        if (b == nullptr) continue;
        const BandStats sa = a.stats.All(), sb = b->stats.All();
        if (sa.finite < MinimumSamples(Level::kP999)) continue;
        ++out.compared;
        for (Metric metric : {Metric::kTotal, Metric::kArith}) {
          const double x = P999Bits(sa, metric), y = P999Bits(sb, metric);
          const double d = y - x;
          largest = std::max(largest, std::fabs(d));
          if (std::fabs(d) <= kNotableDifferenceBits) continue;
          found.push_back(
              {std::fabs(d),
               {Columns(a.cell), RatioLabel(sweeps.ratios[k]), MetricName(metric), Shown(x), Shown(y), Shown(d)}});
        }
      }
    }
  }
  std::stable_sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.size > b.size; });
  for (std::size_t i = 0; i < found.size() && i < kMostDifferences; ++i) out.rows.push_back(found[i].row);
  out.notable = found.size();
  out.largest_bits = Shown(largest);
  out.threshold_bits = kNotableDifferenceBits;
  return out;
}

// Appends `value` to `list` unless it is there already.
void AddOnce(std::vector<std::string>& list, const std::string& value) {
  if (std::find(list.begin(), list.end(), value) == list.end()) list.push_back(value);
}

// The non-finite rows by cause (variant and kind), the most rows first.
std::vector<FindingGroup> GroupFindings(const std::vector<NonFiniteRow>& rows) {
  std::vector<FindingGroup> groups;
  for (const NonFiniteRow& row : rows) {
    auto it = std::find_if(groups.begin(), groups.end(),
                           [&](const FindingGroup& g) { return g.variant == row.cell.variant && g.kind == row.kind; });
    if (it == groups.end()) {
      groups.push_back({row.cell.variant, row.kind, 0, 0, {}, {}, {}, row.command});
      it = std::prev(groups.end());
    }
    ++it->rows;
    it->outputs += row.nan + row.inf;
    AddOnce(it->encodings, row.cell.convention + "/" + row.cell.format);
    AddOnce(it->sweeps, row.sweep);
    AddOnce(it->backends, row.cell.backend);
  }
  std::stable_sort(groups.begin(), groups.end(),
                   [](const FindingGroup& a, const FindingGroup& b) { return a.rows > b.rows; });
  return groups;
}

// NaN/Inf findings of every sweep, and the worst samples of the default one.
void Findings(const ReportMeasurements& m, Report& report) {
  auto scan = [&](const Results& r) {
    for (const CellResult& c : r.cells) {
      const BandStats all = c.stats.All();
      if (all.nan + all.inf == 0) continue;
      const NonFiniteKind kind = all.inf == 0   ? NonFiniteKind::kNaN
                                 : all.nan == 0 ? NonFiniteKind::kInf
                                                : NonFiniteKind::kNaNAndInf;
      report.nonfinite.push_back(
          {Columns(c.cell, c.backend), SweepName(r), kind, all.nan, all.inf, all.judged(), all.first_nonfinite_index,
           ReproCommand(r.run.seed, all.first_nonfinite_index, r.run.domain, c.cell, c.backend)});
    }
  };
  scan(m.main);
  for (const Results& r : m.sweeps.results) scan(r);
  report.finding_groups = GroupFindings(report.nonfinite);

  std::vector<std::pair<double, WorstSampleRow>> worst;
  for (const CellResult& c : m.main.cells) {
    const BandStats all = c.stats.All();
    const MetricStats& total = all[Metric::kTotal];
    if (total.Count() == 0) continue;
    worst.emplace_back(
        std::isfinite(total.max()) ? total.max() : INFINITY,
        WorstSampleRow{Columns(c.cell, c.backend), Shown(BitsLost(total.max())), Shown(total.max()), total.worst_index,
                       ReproCommand(m.main.run.seed, total.worst_index, m.main.run.domain, c.cell, c.backend)});
  }
  std::stable_sort(worst.begin(), worst.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  for (std::size_t i = 0; i < worst.size() && i < kMostWorstSamples; ++i) report.worst.push_back(worst[i].second);
}

// One candidate of a speed/accuracy front.
struct FrontEntry {
  Cell cell;
  FrontCandidate candidate;
  CellAccuracy accuracy;
};

// On the front, bits lost stop at every bit: a relative error of 1 or more
// leaves nothing of the position right. (AccuracyOf already counts a cell
// whose NaN/Inf outputs pass p99.9 as losing every bit.)
double FrontBits(double p999_bits) { return std::min(p999_bits, kAllBitsLost); }

// Marks the front of each (convention, format) among `entries` and adds
// them as rows of `source` at far/near `ratio`.
void AddFronts(const std::string& source, double ratio, const std::vector<FrontEntry>& entries,
               std::vector<FrontRow>& rows) {
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
      rows.push_back({Columns(e.cell), source, RatioLabel(ratio), Shown(e.candidate.cost), Shown(e.candidate.spread),
                      Shown(e.candidate.bits_lost), Shown(FrontBits(e.accuracy.p999_bits_low)),
                      Shown(FrontBits(e.accuracy.p999_bits_high)), e.accuracy.nonfinite,
                      static_cast<bool>(on_front[k])});
    }
  }
}

// The backend the first screen and the speed section speak for: the
// Vulkan backend where the report ran it (TradeBackend), else the CPU.
std::string FirstScreenBackend(const ReportMeasurements& m) {
  const Expected<std::string> backend = TradeBackend(m.main);
  return backend.ok() ? *backend : "cpu";
}

// The speed/accuracy front at the far/near ratios a scene typically has:
// the cost from each speed file (GPU time per kCostFrame frame, from the
// ALU-bound time per reconstruction) and from the instruction mix (which
// always exists), the accuracy from this report's sweep at that ratio on
// the GPU backend, with its interval. Sources best first (CostKind).
SpeedSection Speed(const ReportMeasurements& m) {
  SpeedSection section;
  if (!m.static_costs_status.ok()) {
    section.error = m.static_costs_status.message();
    return section;
  }
  std::vector<FrontRow>& rows = section.rows;
  const std::string backend = FirstScreenBackend(m);
  std::string device;
  for (const BackendRecord& b : m.main.run.backends) {
    if (b.name == backend) device = b.device.name;
  }
  const std::string accuracy = fmt::format(
      "this report's sweep at the chosen far/near (camera at the origin) on the {} backend ({})", backend, device);
  const auto source_name = [](const std::filesystem::path& path, const SpeedResults& speed) {
    return fmt::format("{} ({})", speed.run.device.name, path.filename().string());
  };
  for (const auto& [path, speed] : m.speed) {
    if (speed.gpu.empty()) continue;
    FrontSource source;
    source.source = source_name(path, speed);
    source.kind = speed.run.device.kind == DeviceKind::kGpu ? CostKind::kMeasuredGpu : CostKind::kMeasuredSoftware;
    source.device = speed.run.device.name;
    source.cost_unit = fmt::format(
        "the reconstruction's ALU time in µs per {} frame (one per pixel; no depth traffic: the first screen's cost "
        "adds it), from the ALU-bound time per reconstruction at {} (measured {})",
        ResolutionName(kCostFrame), ResolutionName(speed.run.trade_resolution), speed.run.started_at);
    source.cost_title =
        fmt::format("ALU time per {} frame (µs) on {}", ResolutionName(kCostFrame), speed.run.device.name);
    source.accuracy = accuracy;
    section.sources.push_back(std::move(source));
  }
  section.sources.push_back({"static cost model", CostKind::kStaticModel, "",
                             std::string(kStaticCostUnit) + " of the compiled shader (docs/choosing.md)",
                             fmt::format("static cost ({} of the compiled shader)", kStaticCostUnit), accuracy});
  std::stable_sort(section.sources.begin(), section.sources.end(),
                   [](const FrontSource& a, const FrontSource& b) { return a.kind < b.kind; });

  for (std::size_t k = 0; k < m.sweeps.ratios.size(); ++k) {
    const double ratio = m.sweeps.ratios[k];
    if (std::none_of(std::begin(kFrontRatios), std::end(kFrontRatios),
                     [&](double r) { return std::fabs(std::log10(r) - std::log10(ratio)) < 1e-6; })) {
      continue;
    }
    const Results& at = m.sweeps.results[k];
    const auto accuracy_of = [&](const Cell& cell) -> std::optional<CellAccuracy> {
      const CellResult* r = at.Find(cell, backend);
      if (r == nullptr) return std::nullopt;
      return AccuracyOf(r->stats);
    };
    for (const auto& [path, speed] : m.speed) {
      if (speed.gpu.empty()) continue;
      std::vector<std::string> left_out;
      std::vector<FrontEntry> entries;
      for (const TradeFront& front : BuildTrade(speed, at, backend, speed.run.trade_resolution, left_out)) {
        for (const TradePoint& p : front.points) {
          const Cell cell{p.variant, front.convention, front.format, speed.catalogue};
          const std::optional<CellAccuracy> cell_accuracy = accuracy_of(cell);
          if (!cell_accuracy) continue;
          const double us_per_frame = static_cast<double>(kCostFrame.width) * kCostFrame.height * 1e-3;
          entries.push_back({cell,
                             {p.gpu_ns_per_reconstruction * us_per_frame, p.gpu_spread_ns * us_per_frame,
                              FrontBits(p.p999_bits_lost)},
                             *cell_accuracy});
        }
      }
      AddFronts(source_name(path, speed), ratio, entries, rows);
    }
    std::vector<FrontEntry> entries;
    for (const CellResult& c : at.cells) {
      const std::optional<CandidateCost> cost = c.backend == backend ? m.static_costs(c.cell) : std::nullopt;
      if (!cost) continue;
      const CellAccuracy cell = AccuracyOf(c.stats);
      entries.push_back({c.cell, {cost->value, 0.0, FrontBits(cell.p999_bits_lost)}, cell});
    }
    AddFronts("static cost model", ratio, entries, rows);
  }
  return section;
}

// The costs the first screen ranks by: the best speed file's (a GPU's
// time over a software rasteriser's) where it covers every candidate,
// else the static model for all (ChooseCosts), with its unit and kind.
struct ScreenCosts {
  CostLookup lookup;
  CostKind kind = CostKind::kStaticModel;
  std::string unit = kStaticCostUnit;
};
ScreenCosts CostsForScreen(const ReportMeasurements& m, std::span<const Cell> candidates, Resolution frame = kCostFrame,
                           bool stencil = false) {
  const SpeedResults* best = nullptr;
  std::string best_name;
  for (const auto& [path, speed] : m.speed) {
    if (speed.gpu.empty() || !CheckFrameCostable(speed, path.string()).ok()) continue;
    if (best == nullptr || (speed.run.device.kind == DeviceKind::kGpu && best->run.device.kind != DeviceKind::kGpu)) {
      best = &speed;
      best_name = path.filename().string();
    }
  }
  CostSources sources{{}, best_name, m.static_costs, ""};
  FrameCostModel model;
  if (best != nullptr) {
    // The measurements outlive the screen built from them: the model
    // refers to them without owning them.
    model = {std::shared_ptr<const SpeedResults>(std::shared_ptr<void>(), best), best_name, frame, stencil};
    sources.measured = FrameCostLookup(model);
  }
  const CostChoice choice = ChooseCosts(sources, candidates);
  ScreenCosts costs;
  costs.lookup = choice.lookup;
  if (choice.measured) {
    costs.kind = best->run.device.kind == DeviceKind::kGpu ? CostKind::kMeasuredGpu : CostKind::kMeasuredSoftware;
    costs.unit = model.Unit();
  }
  return costs;
}

// The first screen: per convention and format, on the GPU backend where
// the report ran one, at far/near 1e4 for finite conventions. The fits'
// predictions at the far plane (unrounded) within the statistics'
// resolution of the most precise meet the bar, and the ranking that
// `choose` uses (choose/ranking.h) puts them in order, cheapest first.
std::vector<RecommendationRow> Recommendations(const ReportMeasurements& m) {
  const std::string backend = FirstScreenBackend(m);
  std::vector<const PrecisionFit*> screen;
  std::vector<Cell> candidates;
  for (const PrecisionFit& f : m.fits) {
    if (f.metric != Metric::kTotal || f.level != Level::kP999 || f.backend != backend) continue;
    screen.push_back(&f);
    candidates.push_back(f.cell);
  }
  const ScreenCosts costs = CostsForScreen(m, candidates);
  std::map<std::pair<Convention, Format>, std::vector<const PrecisionFit*>> groups;
  std::vector<std::pair<Convention, Format>> order;
  for (const PrecisionFit* f : screen) {
    const auto key = std::make_pair(f->cell.convention, f->cell.format);
    if (groups[key].empty()) order.push_back(key);
    groups[key].push_back(f);
  }
  std::vector<RecommendationRow> rows;
  for (const auto& key : order) {
    const std::vector<const PrecisionFit*>& group = groups[key];
    RecommendationRow row;
    row.convention = Info(key.first).name;
    row.format = Info(key.second).name;
    row.backend = backend;
    row.ratio = group.front()->infinite_far ? "inf" : "1e4";
    const auto bits_of = [&](const PrecisionFit* f) {
      auto it = f->predicted.find(row.ratio);
      return it == f->predicted.end() || !std::isfinite(it->second) ? kAllBitsLost : it->second;
    };
    double best = kAllBitsLost;
    for (const PrecisionFit* f : group) best = std::min(best, bits_of(f));
    std::vector<RankInput> inputs;
    for (const PrecisionFit* f : group) {
      inputs.push_back({.meets = bits_of(f) <= best + kResolvedBits,
                        .error = bits_of(f),
                        .cost = costs.lookup ? costs.lookup(f->cell) : std::nullopt});
    }
    const std::vector<RankPlace> ranked = Rank(inputs);
    for (const RankPlace& place : ranked) {
      if (inputs[place.candidate].meets) row.variants.emplace_back(group[place.candidate]->cell.variant_info().name);
    }
    const PrecisionFit& chosen = *group[ranked.front().candidate];
    row.cell = chosen.cell.Name();
    row.bits = Shown(bits_of(&chosen));
    for (const bound::CellBound& b : m.recommended_bounds) {
      if (b.cell.Name() == row.cell && std::isfinite(b.total)) row.proven_bits = Shown(bound::BoundBits(b.total));
    }
    // The interval of that very prediction (the fit's model at the far
    // plane of the ratio), not of a band's point: a band can sit elsewhere
    // (the infinite sweep's deepest band ends short of the span predicted).
    if (auto it = chosen.predicted_interval.find(row.ratio); it != chosen.predicted_interval.end() && row.bits) {
      row.bits_low = Shown(it->second.first);
      row.bits_high = Shown(it->second.second);
    }
    if (const std::optional<CandidateCost>& c = inputs[ranked.front().candidate].cost) row.cost = Shown(c->value);
    row.cost_kind = costs.kind;
    row.cost_unit = costs.unit;
    row.ratio_for_1e3 = Budget(chosen, "1e-3");
    row.ratio_for_1e6 = Budget(chosen, "1e-6");
    row.keeps_nothing = (row.bits_low ? *row.bits_low : bits_of(&chosen)) >= kKeepsNothingBits;
    row.bytes_per_pixel = FrameBytesOf(chosen.cell, false).moved();
    if (row.bits) {
      const double relative = std::exp2(*row.bits - 24.0);
      row.error_far_100m = Shown(100.0 * relative);
      row.error_far_10km = Shown(10000.0 * relative);
    }
    rows.push_back(std::move(row));
  }
  // The lever first: the combinations that keep the most bits lead.
  std::stable_sort(rows.begin(), rows.end(), [](const RecommendationRow& a, const RecommendationRow& b) {
    return a.bits.value_or(kAllBitsLost) < b.bits.value_or(kAllBitsLost);
  });
  return rows;
}

// The scene's choice on the backend the first screen speaks for (the
// Vulkan one where the report runs it), costed as the first screen is, at
// the scene's resolution and stencil.
Expected<ChooseResult> ChooseScene(const Scene& scene, const ReportPlan& plan, std::span<Backend* const> backends,
                                   const ReportMeasurements& m) {
  Backend* backend = backends.front();
  for (Backend* b : backends)
    if (b->name() == "vulkan") backend = b;
  const std::vector<Cell> candidates = scene.Candidates();
  const ScreenCosts costs = CostsForScreen(m, candidates, scene.resolution.value_or(kCostFrame), scene.stencil);
  CostSources sources{costs.kind == CostKind::kStaticModel ? CostLookup() : costs.lookup, costs.unit, m.static_costs,
                      ""};
  ChooseOptions options;
  options.samples = plan.main_samples;
  options.seed = plan.main_seed;
  return Choose(scene, *backend, sources, options);
}

// Bits lost per pixel of the scene's capture by its choice (or closest
// candidate), on the backend the choice was made on.
Expected<ReportMeasurements::CaptureBits> CaptureBitsOf(const Scene& scene, const ChooseResult& choice,
                                                        std::span<Backend* const> backends) {
  Backend* backend = backends.front();
  for (Backend* b : backends)
    if (b->name() == choice.backend) backend = b;
  ReportMeasurements::CaptureBits out;
  out.cell = choice.ranked.front().cell;
  out.backend = backend->name();
  out.width = scene.domain.capture->width;
  out.height = scene.domain.capture->height;
  DB_ASSIGN_OR_RETURN(out.bits, BitsLostPerPixel(scene.domain, out.cell, *backend));
  return out;
}

// The scene's first screen: each convention and format once, by its best
// candidate, in the order of the ranking.
SceneSection SceneScreen(const ChooseResult& choice) {
  SceneSection section{choice.scene, choice.requirement, choice.backend, choice.cost_unit, choice.unit,
                       choice.limit, choice.at_depth, {}, {}, {}, std::nullopt};
  for (const CandidateVerdict& v : choice.ranked) {
    const std::string convention(Info(v.cell.convention).name), format(Info(v.cell.format).name);
    const bool seen = std::any_of(section.rows.begin(), section.rows.end(), [&](const SceneRow& r) {
      return r.convention == convention && r.format == format;
    });
    if (seen) continue;
    SceneRow row;
    row.convention = convention;
    row.format = format;
    row.variant = std::string(v.cell.variant_info().name);
    row.measured = Shown(v.interval.high);
    row.far_end = Shown(v.far_end_measured);
    if (std::isfinite(v.proven)) row.proven = Shown(v.proven);
    row.meets = v.meets;
    row.times_limit = choice.limit > 0.0 ? v.Figure() / choice.limit : 0.0;
    if (v.cost) {
      row.bytes_per_pixel = v.cost->bytes_per_pixel;
      row.cost = Shown(v.cost->value);
    }
    for (const DepthFigure& f : v.by_depth) row.by_depth.push_back({f.depth_min, f.depth_max, Shown(f.value)});
    section.rows.push_back(std::move(row));
  }
  for (const WhatIf& w : choice.what_ifs) {
    section.what_ifs.push_back(w.candidate.empty() ? w.change
                                                   : fmt::format("{}: {} at {:.3g}, {}", w.change, w.candidate,
                                                                 w.figure, w.meets ? "meets it" : "still fails"));
  }
  section.not_candidates = choice.unusable_formats;
  section.proven = choice.proven;
  return section;
}

ReportEnvironment Environment(const ReportPlan& plan, const ReportMeasurements& m) {
  ReportEnvironment env;
  env.version = m.main.run.version;
  env.commit = m.main.run.commit;
  env.host = m.main.run.host;
  env.started_at = m.main.run.started_at;
  for (const BackendRecord& b : m.main.run.backends) env.backends.emplace_back(b.name, b.device);
  double seconds = 0.0;
  for (const auto& [stage, s] : m.stage_seconds) {
    env.stages.emplace_back(stage, Shown(s));
    seconds += s;
  }
  env.seconds = Shown(seconds);
  env.quick = plan.quick;
  env.fit_sweeps.seed = plan.fit.seed;
  env.fit_sweeps.samples_per_ratio = plan.fit.samples_per_ratio;
  for (double r : m.sweeps.ratios) env.fit_sweeps.ratios.push_back(RatioLabel(r));
  env.fit_sweeps.held_out = plan.fit.held_out;
  env.fit_sweeps.domain = plan.fit.domain.Describe();
  env.default_sweep = {m.main.run.seed, m.main.run.samples, m.main.run.reconstructions, m.main.run.domain.Describe()};
  for (const auto& [path, speed] : m.speed) env.speed_files.push_back(path.string());
  return env;
}

// The proven bounds of the first screen's recommended cells, over the
// population its figures describe: the fit sweeps' domain at the row's
// far/near (1e4, or an infinite far plane), the camera at the origin.
Expected<std::vector<bound::CellBound>> ProveRecommended(const ReportPlan& plan, const Domain& fit_domain,
                                                        const ReportMeasurements& m) {
  std::filesystem::path dir = plan.shader_dir;
  if (dir.empty()) DB_RETURN_IF_ERROR(StoreInto(DataPath("shaders"), dir));
  bound::BoundOptions options;
  options.splits = plan.bound_splits;
  std::vector<bound::CellBound> bounds;
  for (const RecommendationRow& row : Recommendations(m)) {
    const auto fit = std::find_if(m.fits.begin(), m.fits.end(),
                                  [&](const PrecisionFit& f) { return f.cell.Name() == row.cell; });
    if (fit == m.fits.end()) continue;
    Domain domain = fit_domain;
    domain.far.reset();
    domain.camera_distance = Range{0.0, 0.0};
    domain.finite_far = row.ratio != "inf";
    domain.infinite_far = !domain.finite_far;
    domain.ratio = Range{1e4, 1e4};
    const Cell cells[] = {fit->cell};
    DB_ASSIGN_OR_RETURN(std::vector<bound::CellBound> one, bound::BoundCells(domain, cells, dir, options));
    bounds.insert(bounds.end(), one.begin(), one.end());
  }
  return bounds;
}

}  // namespace

// Groups the history's changes by cell (HistorySection::worse_cells) and
// counts the cells better and unchanged of the `cells` compared.
void CountChangedCells(std::size_t cells, HistorySection& h) {
  std::map<std::pair<std::string, std::string>, std::vector<std::string>> worse;
  std::set<std::pair<std::string, std::string>> better;
  for (const HistorySection::Change& c : h.changes) {
    if (c.direction == HistorySection::Direction::kWorse) {
      worse[{c.cell, c.backend}].push_back(fmt::format("{}: {}", c.band, fmt::join(c.reasons, ", ")));
    }
  }
  for (const HistorySection::Change& c : h.changes) {
    if (c.direction == HistorySection::Direction::kBetter && !worse.count({c.cell, c.backend})) {
      better.insert({c.cell, c.backend});
    }
  }
  for (auto& [key, bands] : worse) h.worse_cells.push_back({key.first, key.second, std::move(bands)});
  h.better_cells = better.size();
  h.unchanged_cells = cells - std::min(cells, h.worse_cells.size() + h.better_cells);
}

// The headline's measured cells, worst first; a cell with the same figures
// on several backends once.
std::vector<Report::WorstCell> WorstCells(const std::vector<HeadlineRow>& headline) {
  std::vector<std::size_t> rows;
  for (std::size_t k = 0; k < headline.size(); ++k) {
    if (headline[k].measured) rows.push_back(k);
  }
  std::stable_sort(rows.begin(), rows.end(), [&](std::size_t i, std::size_t j) {
    const HeadlineRow* a = &headline[i];
    const HeadlineRow* b = &headline[j];
    const double a_p999 = a->measured->p999_bits.value_or(INFINITY), b_p999 = b->measured->p999_bits.value_or(INFINITY);
    if (a_p999 != b_p999) return a_p999 > b_p999;
    return a->measured->max_bits.value_or(INFINITY) > b->measured->max_bits.value_or(INFINITY);
  });
  std::vector<Report::WorstCell> worst;
  for (std::size_t k : rows) {
    const HeadlineRow& row = headline[k];
    auto same = std::find_if(worst.begin(), worst.end(), [&](const Report::WorstCell& w) {
      const HeadlineRow& other = headline[w.row];
      return other.cell.Name() == row.cell.Name() && other.measured->p999_bits == row.measured->p999_bits &&
             other.measured->max_bits == row.measured->max_bits;
    });
    if (same != worst.end()) {
      same->backends.push_back(row.cell.backend);
    } else {
      worst.push_back({k, {row.cell.backend}});
    }
  }
  return worst;
}

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
  plan.bound_splits = 50;
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

  // The speed files first: a bad one is refused before the sweeps.
  begin("speed files");
  const Catalogue& catalogue = plan.catalogue != nullptr ? *plan.catalogue : Catalogue::BuiltIn();
  std::vector<DeviceInfo> devices;
  for (const Backend* backend : backends) devices.push_back(backend->device());
  for (const std::filesystem::path& path : plan.speed_files) {
    DB_ASSIGN_OR_RETURN(SpeedResults speed, ReadSpeedResults(path, catalogue));
    if (SpeedFileApplies(speed, plan.speed_files_named, devices)) {
      m.speed.emplace_back(path, std::move(speed));
    } else {
      m.speed_of_other_devices.push_back(path);
    }
  }
  // A shader copy that does not compile leaves the front without its
  // instruction counts, not the report without its other parts.
  m.static_costs_status = StoreInto(StaticCostLookup(plan.shader_dir.string(), catalogue), m.static_costs);
  end("speed files",
      m.speed_of_other_devices.empty()
          ? fmt::format("{} read", m.speed.size())
          : fmt::format("{} of this report's devices read; {} measured on another device left out (name a file with "
                        "--speed to use its costs)",
                        m.speed.size(), m.speed_of_other_devices.size()));

  FitPlan fit_plan = plan.fit;
  fit_plan.cells = plan.cells;
  begin("sweeps at fixed far/near");
  DB_ASSIGN_OR_RETURN(m.sweeps, RunFitSweeps(fit_plan, backends, progress.sweep));
  end("sweeps at fixed far/near", fmt::format("{} far/near ratios", m.sweeps.ratios.size()));
  // After a signal no further stage starts: a report is made of whole
  // sweeps, and the command writes nothing of a cut one.
  const auto stopped = [] { return InterruptedError("nothing was written or recorded: the report's sweeps were cut short"); };
  if (Interrupted()) return stopped();

  begin("default-domain sweep");
  SweepOptions main;
  main.seed = plan.main_seed;
  main.samples = plan.main_samples;
  main.domain = plan.main_domain;
  main.cells = CellsForDomain(plan.cells.empty() ? AllCells() : plan.cells, main.domain);
  main.progress = progress.sweep;
  DB_ASSIGN_OR_RETURN(m.main, RunSweep(main, backends));
  end("default-domain sweep", fmt::format("{} cells", m.main.cells.size()));
  if (Interrupted()) return stopped();

  if (plan.scene) {
    begin("scene");
    DB_ASSIGN_OR_RETURN(m.scene_choice, ChooseScene(*plan.scene, plan, backends, m));
    if (plan.scene->domain.capture && !m.scene_choice->ranked.empty()) {
      DB_ASSIGN_OR_RETURN(m.capture_bits, CaptureBitsOf(*plan.scene, *m.scene_choice, backends));
    }
    end("scene", fmt::format("{} candidates", m.scene_choice->ranked.size()));
    if (Interrupted()) return stopped();
  }
  begin("error models");
  const Metric metrics[] = {Metric::kTotal};
  m.fits = FitPrecision(m.sweeps, fit_plan, metrics, kAllLevels, progress.fits);
  end("error models", fmt::format("{} fits", m.fits.size()));

  begin("proven bounds");
  // A domain the analysis does not cover leaves the first screen without
  // its bounds, not the report without its other parts.
  m.bounds_status = StoreInto(ProveRecommended(plan, fit_plan.domain, m), m.recommended_bounds);
  end("proven bounds", m.bounds_status.ok() ? fmt::format("{} cells bounded", m.recommended_bounds.size())
                                            : std::string(m.bounds_status.message()));

  return m;
}

Report BuildReport(const ReportPlan& plan, const ReportMeasurements& m) {
  Report report;
  for (const PrecisionFit& f : m.fits) {
    if (f.metric != Metric::kTotal) continue;
    if (std::find(std::begin(kChartLevels), std::end(kChartLevels), f.level) != std::end(kChartLevels)) {
      for (ModelPointRow& row : ModelAlongPoints(f, m.sweeps, plan.fit, true, {}, false)) {
        report.precision_points.push_back(std::move(row));
      }
    }
    if (f.level == Level::kP999) {
      for (ModelPointRow& row : ModelAlongPoints(f, m.sweeps, plan.fit, false, kDepthCurveRatios, true)) {
        report.depth_points.push_back(std::move(row));
      }
    }
  }
  std::vector<std::string> backends;
  for (const BackendRecord& b : m.main.run.backends) backends.push_back(b.name);
  report.environment = Environment(plan, m);
  report.headline = HeadlineRows(m);
  report.split = SplitRows(m.sweeps);
  report.backend_differences = Differences(m.sweeps, backends);
  Findings(m, report);
  report.speed = Speed(m);
  report.recommendations = Recommendations(m);
  if (m.scene_choice) report.scene = SceneScreen(*m.scene_choice);
  if (m.capture_bits && report.scene) {
    std::vector<float> judged;
    for (float b : m.capture_bits->bits)
      if (!std::isnan(b)) judged.push_back(b);
    std::sort(judged.begin(), judged.end());
    const auto at = [&](double q) {
      return judged.empty() ? 0.0 : judged[std::min(judged.size() - 1, static_cast<std::size_t>(q * judged.size()))];
    };
    report.scene->capture = SceneSection::CapturePicture{
        kCaptureImageName, m.capture_bits->cell.Name(), m.capture_bits->backend, plan.scene->domain.capture->source,
        judged.size(),     at(0.5),                     at(0.999),               judged.empty() ? 0.0 : judged.back()};
  }
  report.worst_cells = WorstCells(report.headline);
  return report;
}

std::vector<Baseline> HistoryFigures(const ReportMeasurements& m) {
  std::vector<Baseline> figures;
  for (const BackendRecord& b : m.main.run.backends) figures.push_back(BaselineFromResults(m.main, b.name));
  return figures;
}

Status AddHistory(Report& report, History& history, const HistoryRun& run, std::span<const Baseline> figures,
                  int trend_runs) {
  DB_ASSIGN_OR_RETURN(std::int64_t id, history.Record(run, figures));
  DB_ASSIGN_OR_RETURN(std::int64_t runs, history.RunCount());
  HistorySection section;
  section.database = history.path().string();
  section.run = id;
  section.runs_recorded = runs;
  const GateTolerance tolerance;
  section.tolerance_p999_bits = tolerance.p999_bits;
  section.tolerance_max_bits = tolerance.max_bits;
  for (const Baseline& now : figures) {
    DB_ASSIGN_OR_RETURN(std::vector<TrendPoint> points, history.Trend(id, now, trend_runs));
    for (const TrendPoint& p : points) {
      section.trend.push_back(
          {p.run, p.made_at, p.commit, p.backend, p.cell, Shown(p.total_p999), Shown(p.total_max), p.nonfinite});
    }
    DB_ASSIGN_OR_RETURN(auto before, history.Previous(id, now));
    if (!before) continue;
    const auto& [before_run, before_figures] = *before;
    section.previous.push_back({now.backend, before_run.id, before_run.made_at, before_run.commit});
    DB_ASSIGN_OR_RETURN(GateComparison comparison, CompareWithBaseline(before_figures, now, tolerance));
    for (const std::string& note : comparison.notes) section.notes.push_back(now.backend + ": " + note);
    for (const CellVerdict& v : comparison.cells) {
      auto add = [&](HistorySection::Direction direction, const std::string& band,
                     const std::vector<std::string>& reasons, double before_bits, double after_bits) {
        section.changes.push_back(
            {direction, now.backend, v.cell, band, reasons, Shown(before_bits), Shown(after_bits)});
      };
      constexpr auto kWorse = HistorySection::Direction::kWorse;
      if (v.disappeared) add(kWorse, "all", {"the cell is missing from this run"}, NAN, NAN);
      for (const BandChange& c : v.worse) add(kWorse, c.band, c.reasons, c.before.total_p999, c.after.total_p999);
      for (const BandChange& c : v.better)
        add(HistorySection::Direction::kBetter, c.band, c.reasons, c.before.total_p999, c.after.total_p999);
    }
  }
  CountChangedCells(report.headline.size(), section);
  report.history = std::move(section);
  return Status::Ok();
}

}  // namespace depthbench
