#include "bench/fit/precision_fit.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <ostream>

#include <fmt/format.h>

#include "bench/base/interrupt.h"
#include "bench/base/text_table.h"
#include "bench/pipeline/bands.h"

namespace depthbench {
namespace {

constexpr double kInfiniteSpan = Domain::kInfiniteDepthSpan;
// Far/near range the budgets are searched over: the swept one, never
// beyond the data.
constexpr double kLowestRatio = 10.0;
// The relative-error budgets of the depth-precision literature: 1e-3 where
// z-fighting starts to show, 1e-6 "very good".
const std::pair<const char*, double> kBudgets[] = {{"1e-3", 1e-3}, {"1e-6", 1e-6}};
const std::pair<const char*, double> kPredictedRatios[] = {{"1e2", 1e2}, {"1e4", 1e4}, {"1e6", 1e6}, {"1e8", 1e8}};

bool InfiniteFar(const Cell& cell) {
  const ConventionInfo& c = Info(cell.convention);
  return c.hardware && (c.bits & 2u) != 0u;
}

// What `m` says at (x, y) with its 95% interval, each held to 0..24 bits:
// the interval is the unclamped prediction's, so that a prediction held at
// 24 keeps the interval's lower end, and clamping (monotone) keeps the
// value inside the interval.
Estimate ClampedEstimate(const FittedModel& m, double x, double y) {
  const Estimate e = EstimateOf(m, [x, y](const FittedModel& f) { return f.Predict(x, y); });
  const auto clamp = [](double b) { return std::isnan(b) ? b : std::clamp(b, 0.0, kAllBitsLost); };
  return {clamp(e.value), clamp(e.low), clamp(e.high)};
}

}  // namespace

// The interval's ends, where the fit has no covariance (NaN), fall back to
// the prediction.
std::optional<double> BudgetRatioOf(const FittedModel& m, double budget, double highest_ratio) {
  const double limit = 24.0 + std::log2(budget);
  const double lowest = std::log2(kLowestRatio);
  const auto ends = [&](double x) {
    const Estimate e = ClampedEstimate(m, x, x);
    return std::pair{std::isnan(e.low) ? e.value : e.low, std::isnan(e.high) ? e.value : e.high};
  };
  // The far plane: the point at eye depth = far, where the deepest band's
  // point sits (CollectBandPoints); bits lost saturate at 24.
  if (ends(lowest).first > limit) return 0.0;
  std::optional<double> last_met;
  for (double x = lowest; x <= std::log2(highest_ratio) + 1e-9; x += 0.05) {
    if (ends(x).second > limit) return last_met.value_or(kLowestRatio);
    last_met = std::exp2(x);
  }
  return std::nullopt;
}

namespace {

// Points at or above this carry no slope: the error has reached the
// distance itself (a quarter bit below 24: the statistics' resolution).
constexpr double kSaturatedBits = kAllBitsLost - kResolvedBits;

// Slope of the far-plane curve between f/n = 1e2 and 1e8, as a function of
// the parameters (exact for the linear models).
double SlopeOf(const FittedModel& m) {
  // The model's own line, not saturated: the loss per doubling while there
  // is precision left to lose.
  const double x1 = std::log2(1e2), x2 = std::log2(1e8);
  return (m.Predict(x2, x2) - m.Predict(x1, x1)) / (x2 - x1);
}

}  // namespace

FitPlan::FitPlan() {
  domain.camera_distance = {0.0, 0.0};
  for (int k = 2; k <= 16; ++k) ratios.push_back(std::pow(10.0, k / 2.0));
  held_out = {std::pow(10.0, 3.5), std::pow(10.0, 6.5)};
}

Expected<FitSweeps> RunFitSweeps(const FitPlan& plan, std::span<Backend* const> backends,
                                 const std::function<void(const SweepProgress&)>& progress) {
  FitSweeps sweeps;
  std::vector<double> ratios = plan.ratios;
  if (plan.infinite) ratios.push_back(INFINITY);
  SweepProgress total;
  total.samples_total = plan.samples_per_ratio * ratios.size();
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t k = 0; k < ratios.size(); ++k) {
    // After a signal the sweep just cut short is the last: what was
    // measured is returned, and the caller says it is partial.
    if (Interrupted()) break;
    SweepOptions options;
    // A seed of its own per ratio: with one seed every ratio would draw the
    // same pixels and depth units, their errors would move together, and
    // the fit's intervals would be too narrow.
    options.seed = plan.seed ^ (0x9E3779B97F4A7C15ull * (k + 1));
    options.samples = plan.samples_per_ratio;
    options.domain = plan.domain;
    options.domain.far.reset();
    if (std::isinf(ratios[k])) {
      options.domain.finite_far = false;
      options.domain.infinite_far = true;
    } else {
      options.domain.ratio = {ratios[k], ratios[k]};
      options.domain.finite_far = true;
      options.domain.infinite_far = false;
    }
    options.cells = CellsForDomain(plan.cells.empty() ? AllCells() : plan.cells, options.domain);
    if (options.cells.empty()) {
      total.samples_total -= plan.samples_per_ratio;
      continue;
    }
    const SweepProgress before = total;
    if (progress) {
      options.progress = [&](const SweepProgress& p) {
        total.samples_done = before.samples_done + p.samples_done;
        total.reconstructions_done = before.reconstructions_done + p.reconstructions_done;
        total.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        progress(total);
      };
    }
    auto results = RunSweep(options, backends);
    if (!results.ok()) return results.status().WithContext(fmt::format("sweep at far/near {:g}", ratios[k]));
    sweeps.ratios.push_back(ratios[k]);
    total.samples_done = before.samples_done + plan.samples_per_ratio;
    total.reconstructions_done = before.reconstructions_done + results->run.reconstructions;
    sweeps.results.push_back(std::move(*results));
  }
  return sweeps;
}

std::vector<BandPoint> CollectBandPoints(const FitSweeps& sweeps, const Cell& cell, const std::string& backend,
                                         Metric metric, Level level) {
  std::vector<BandPoint> points;
  for (std::size_t k = 0; k < sweeps.results.size(); ++k) {
    const CellResult* result = sweeps.results[k].Find(cell, backend);
    if (result == nullptr) continue;
    const double ratio = sweeps.ratios[k];
    const double span = std::isinf(ratio) ? kInfiniteSpan : ratio;
    for (int d = 0; d < kDepthBands; ++d) {
      const BandStats band = result->stats.ForDepth(d);
      // NaN and Inf outputs count: they are the top of the distribution.
      if (band.judged() < MinimumSamples(level)) continue;
      // The band's z/n runs between its edges (the top decade stops at the
      // far plane). Its point sits at the far edge: where errors grow with
      // depth, a band's high quantile is set by its deepest samples, and
      // the deepest band's point is then the far plane's figure, which is
      // what a run at that ratio reports for the samples nearest the far
      // plane.
      const double lo = std::max(1.0, DepthBandLow(d)), hi = std::min(DepthBandLow(d) * 10.0, span);
      if (!(hi > lo)) continue;
      // A share of NaN/Inf above 1 - q puts the quantile at infinity.
      const double q =
          static_cast<double>(band.nan + band.inf) > (1.0 - LevelQuantile(level)) * static_cast<double>(band.judged())
              ? INFINITY
              : band[metric].AtLevel(level, metric);
      BandPoint p;
      p.ratio = ratio;
      p.depth_band = d;
      p.point = {std::isinf(ratio) ? 0.0 : std::log2(ratio), std::log2(hi),
                 std::isfinite(q) ? std::log2(q) + 24.0 : INFINITY};
      p.modelled = q > std::ldexp(1.0, kLowestOctave[static_cast<int>(metric)]) && std::isfinite(q) &&
                   p.point.b < kSaturatedBits;
      points.push_back(p);
    }
  }
  return points;
}

std::vector<FitPoint> CollectPoints(const FitSweeps& sweeps, const Cell& cell, const std::string& backend,
                                    Metric metric, Level level) {
  std::vector<FitPoint> points;
  for (const BandPoint& p : CollectBandPoints(sweeps, cell, backend, metric, level)) {
    if (p.modelled) points.push_back(p.point);
  }
  return points;
}

std::vector<PrecisionFit> FitPrecision(const FitSweeps& sweeps, const FitPlan& plan, std::span<const Metric> metrics,
                                       std::span<const Level> levels,
                                       const std::function<void(std::size_t, std::size_t)>& progress) {
  // Every (cell, backend) that appears in the sweeps, in order.
  std::vector<std::pair<Cell, std::string>> cells;
  for (const Results& r : sweeps.results) {
    for (const CellResult& c : r.cells) {
      std::pair<Cell, std::string> key{c.cell, c.backend};
      if (std::find(cells.begin(), cells.end(), key) == cells.end()) cells.push_back(key);
    }
  }
  std::vector<PrecisionFit> fits;
  std::size_t done = 0;
  for (const auto& [cell, backend] : cells) {
    if (progress) progress(done++, cells.size());
    for (Metric metric : metrics) {
      for (Level level : levels) {
        PrecisionFit fit;
        fit.cell = cell;
        fit.backend = backend;
        fit.metric = metric;
        fit.level = level;
        fit.infinite_far = InfiniteFar(cell);
        const std::vector<FitPoint> points = CollectPoints(sweeps, cell, backend, metric, level);
        fit.points = static_cast<int>(points.size());
        std::vector<ModelKind> candidates;
        for (ModelKind kind : kAllModels) {
          if (fit.infinite_far && Info(kind).uses_ratio) continue;  // one ratio: no x to fit
          candidates.push_back(kind);
        }
        fit.ranking = FitAndRank(points, candidates);
        if (fit.ranking.empty()) continue;
        fit.model = fit.ranking.front();
        const FittedModel& m = fit.model;

        if (!fit.infinite_far) {
          // Slope of the far plane and its interval.
          const Estimate slope = EstimateOf(m, SlopeOf);
          fit.slope = slope.value;
          fit.slope_low = slope.low;
          fit.slope_high = slope.high;
          double highest_ratio = kLowestRatio;
          for (double r : sweeps.ratios) {
            if (std::isfinite(r)) highest_ratio = std::max(highest_ratio, r);
          }
          for (const auto& [name, ratio] : kPredictedRatios) {
            // No prediction past the data.
            if (ratio > highest_ratio * (1.0 + 1e-9)) continue;
            const Estimate at = ClampedEstimate(m, std::log2(ratio), std::log2(ratio));
            fit.predicted[name] = at.value;
            fit.predicted_interval[name] = {at.low, at.high};
          }
          for (const auto& [name, budget] : kBudgets) {
            fit.budget_ratio[name] = BudgetRatioOf(m, budget, highest_ratio);
          }
          // Hold-out: refit the chosen kind without the held-out ratios.
          std::vector<FitPoint> train, test;
          for (const FitPoint& p : points) {
            const bool held = std::any_of(plan.held_out.begin(), plan.held_out.end(),
                                          [&](double r) { return std::fabs(p.x - std::log2(r)) < 1e-9; });
            (held ? test : train).push_back(p);
          }
          auto refit = FitModel(train, m.kind);
          if (refit.ok() && !test.empty()) {
            double sum = 0.0;
            for (const FitPoint& p : test) {
              const double miss = std::fabs(refit->Predict(p.x, p.y) - p.b);
              fit.holdout_max_miss = std::max(fit.holdout_max_miss, miss);
              sum += miss * miss;
            }
            fit.holdout_rms_miss = std::sqrt(sum / test.size());
            fit.holdout_points = static_cast<int>(test.size());
          }
        } else {
          const Estimate at = ClampedEstimate(m, 0.0, std::log2(kInfiniteSpan));
          fit.predicted["inf"] = at.value;
          fit.predicted_interval["inf"] = {at.low, at.high};
        }
        fits.push_back(std::move(fit));
      }
    }
  }
  if (progress) progress(cells.size(), cells.size());
  return fits;
}

nlohmann::json PrecisionFitsToJson(const std::vector<PrecisionFit>& fits, const FitPlan& plan) {
  nlohmann::json out = nlohmann::json::array();
  for (const PrecisionFit& f : fits) {
    nlohmann::json ranking = nlohmann::json::array();
    for (const FittedModel& m : f.ranking) {
      nlohmann::json parameters = nlohmann::json::array();
      for (std::size_t i = 0; i < m.parameters.size(); ++i) {
        parameters.push_back({{"name", Info(m.kind).parameter_names[i]},
                              {"value", m.parameters[i]},
                              {"standard_error", JsonNumber(m.StandardError(static_cast<int>(i)))}});
      }
      ranking.push_back({{"model", Info(m.kind).name},
                         {"bic", m.bic},
                         {"sigma_bits", m.sigma},
                         {"converged", m.converged},
                         {"parameters", parameters}});
    }
    nlohmann::json intervals = nlohmann::json::object();
    for (const auto& [name, interval] : f.predicted_interval) {
      intervals[name] = {JsonNumber(interval.first), JsonNumber(interval.second)};
    }
    nlohmann::json budgets = nlohmann::json::object();
    for (const auto& [name, ratio] : f.budget_ratio) {
      budgets[name] = ratio ? JsonNumber(*ratio) : nlohmann::json("met throughout");
    }
    out.push_back(
        {{"cell", f.cell.Name()},
         {"backend", f.backend},
         {"metric", MetricName(f.metric)},
         {"level", LevelName(f.level)},
         {"infinite_far", f.infinite_far},
         {"points", f.points},
         {"model", Info(f.model.kind).name},
         {"slope_bits_per_doubling", f.slope},
         {"slope_interval_95", {f.slope_low, f.slope_high}},
         {"predicted_bits_lost", f.predicted},
         {"predicted_interval_95", intervals},
         {"last_ratio_meeting_budget", budgets},
         {"holdout",
          {{"points", f.holdout_points}, {"max_miss_bits", f.holdout_max_miss}, {"rms_miss_bits", f.holdout_rms_miss}}},
         {"models", ranking}});
  }
  nlohmann::json ratios = nlohmann::json::array();
  for (double r : plan.ratios) ratios.push_back(r);
  return WithSchema(kFitSchema, {{"plan",
                                  {{"seed", plan.seed},
                                   {"samples_per_ratio", plan.samples_per_ratio},
                                   {"ratios", ratios},
                                   {"infinite", plan.infinite},
                                   {"held_out", plan.held_out},
                                   {"domain", DomainToJson(plan.domain)}}},
                                 {"fits", out}});
}

void PrintPrecisionFits(const std::vector<PrecisionFit>& fits, Level level, const TextOutput& out) {
  using Align = TextTable::Align;
  TextTable table({{"cell", Align::kLeft},
                   {"backend", Align::kLeft},
                   {"model", Align::kLeft},
                   {"bits/doubling f/n [95%]"},
                   {"1e2", Align::kRight, true},
                   {"1e4"},
                   {"1e6", Align::kRight, true},
                   {"1e8"},
                   {"inf", Align::kRight, true},
                   {"f/n 1e-3"},
                   {"f/n 1e-6"},
                   {"held-out miss", Align::kRight, true}});
  auto ratio_text = [](const std::map<std::string, std::optional<double>>& budgets, const char* name) {
    auto it = budgets.find(name);
    if (it == budgets.end()) return std::string("-");
    if (!it->second) return std::string("always");
    if (*it->second == 0.0) return std::string("never");
    return fmt::format("{:.2g}", *it->second);
  };
  auto predicted = [](const PrecisionFit& f, const char* name) {
    auto it = f.predicted.find(name);
    return it == f.predicted.end() ? std::string("-") : fmt::format("{:.1f}", it->second);
  };
  for (const PrecisionFit& f : fits) {
    if (f.metric != Metric::kTotal || f.level != level) continue;
    table.AddRow({f.cell.Name(), f.backend, Info(f.model.kind).name,
                  f.infinite_far ? "-" : fmt::format("{:.2f} [{:.2f}, {:.2f}]", f.slope, f.slope_low, f.slope_high),
                  predicted(f, "1e2"), predicted(f, "1e4"), predicted(f, "1e6"), predicted(f, "1e8"),
                  predicted(f, "inf"), ratio_text(f.budget_ratio, "1e-3"), ratio_text(f.budget_ratio, "1e-6"),
                  f.holdout_points == 0 ? "-" : fmt::format("{:.2f} bit", f.holdout_max_miss)});
  }
  out.text << fmt::format(
      "{} bits lost of the total error at the far plane, from the fitted model chosen by BIC; f/n 1e-3 and 1e-6: "
      "the far/near ratio up to which the far plane meets a relative error of 1e-3 and 1e-6 ('always': up to 1e12, "
      "'never': not even "
      "at 10); the largest miss on held-out ratios\n",
      LevelName(level));
  table.Print(out);
}

}  // namespace depthbench
