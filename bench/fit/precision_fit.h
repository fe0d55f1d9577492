// Precision fits: the sweeps that feed the error models, and what the
// fitted models say per cell: bits lost per doubling of far/near with its
// confidence interval, predictions at chosen ratios, the ratio at which a
// cell stops meeting common error budgets, and how far the model misses on
// ratios it was not fitted to.
//
// The data come from sweeps at fixed far/near ratios (10^1, 10^1.5, ...,
// 10^8) and one with an infinite far plane, so every point's ratio is exact;
// eye depth is binned by decades of z/n. A point is one quantile of one
// metric in one (ratio, depth decade) with enough samples behind it.
#pragma once

#include <map>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/backends/backend.h"
#include "bench/base/json_reader.h"
#include "bench/base/text_table.h"
#include "bench/models/error_model.h"
#include "bench/results/results.h"
#include "bench/sweep/sweep.h"

namespace depthbench {

inline constexpr JsonSchema kFitSchema{"depthbench.fit", 1, "the models of depthbench fit --json"};

struct FitPlan {
  std::uint64_t seed = 7;
  std::uint64_t samples_per_ratio = 100000;
  std::vector<double> ratios;    // finite far/near ratios swept; empty: 10^1 .. 10^8 in half decades
  bool infinite = true;          // also sweep an infinite far plane
  Domain domain;                 // everything but the ratio (the camera defaults to the origin)
  std::vector<Cell> cells;       // empty: all
  std::vector<double> held_out;  // ratios kept out of the hold-out fit; empty: 10^3.5 and 10^6.5
  FitPlan();
};

// The sweeps of a plan: one Results per finite ratio, then the infinite one.
struct FitSweeps {
  std::vector<double> ratios;  // +infinity for the infinite sweep
  std::vector<Results> results;
};
// `progress` sees the sweeps as one: samples of every ratio together.
Expected<FitSweeps> RunFitSweeps(const FitPlan& plan, std::span<Backend* const> backends,
                                 const std::function<void(const SweepProgress&)>& progress = {});

// Every (ratio, eye-depth decade) of one cell, backend, metric and level
// with enough samples for the level's quantile, whether a model can follow
// it or not.
struct BandPoint {
  double ratio = 0.0;  // +infinity for the infinite sweep
  int depth_band = 0;
  FitPoint point;  // b = +infinity when the quantile is not finite
  // A point the models are fitted to: finite, and above the lowest kept
  // bin (a quantile in the underflow bin only says "tiny").
  bool modelled = false;
};
std::vector<BandPoint> CollectBandPoints(const FitSweeps& sweeps, const Cell& cell, const std::string& backend,
                                         Metric metric, Level level);

// The points of one cell, backend, metric and level that models are fitted to.
std::vector<FitPoint> CollectPoints(const FitSweeps& sweeps, const Cell& cell, const std::string& backend,
                                    Metric metric, Level level);

// What a fit says.
struct PrecisionFit {
  Cell cell;
  std::string backend;
  Metric metric = Metric::kTotal;
  Level level = Level::kP999;
  bool infinite_far = false;
  int points = 0;
  FittedModel model;                 // the chosen one
  std::vector<FittedModel> ranking;  // every candidate, best BIC first
  // Bits lost at the far plane per doubling of far/near, and its 95%
  // interval (0 for models without a far/near or depth term).
  double slope = 0.0, slope_low = 0.0, slope_high = 0.0;
  // Predicted bits lost at the far plane (floored at 0), by ratio.
  std::map<std::string, double> predicted;  // "1e2" ... "1e8", "inf"
  // Each prediction's 95% interval: the model's, at the same point, held
  // to 0..24 bits as the prediction is (so it always holds the prediction;
  // NaN where the fit has no covariance).
  std::map<std::string, std::pair<double, double>> predicted_interval;
  // The largest far/near ratio at which the far plane still meets a
  // relative-error budget, on the upper end of the prediction's 95%
  // interval (so that another run of the same cell agrees); nullopt
  // ("always") when that upper end meets it throughout the data, 0
  // ("never") only when even the interval's lower end misses it at the
  // lowest ratio. Where the upper end misses at the lowest ratio but the
  // lower end does not, the lowest ratio.
  std::map<std::string, std::optional<double>> budget_ratio;  // "1e-3", "1e-6"
  // Hold-out check: fitted without the held-out ratios, how far the model
  // misses their points, in bits.
  double holdout_max_miss = 0.0, holdout_rms_miss = 0.0;
  int holdout_points = 0;
};

// PrecisionFit::budget_ratio of a fitted model for a relative-error
// budget, over ratios from 10 to `highest_ratio`.
std::optional<double> BudgetRatioOf(const FittedModel& model, double budget, double highest_ratio);

// `progress` is told (cells fitted, cells to fit) after each (cell, backend).
std::vector<PrecisionFit> FitPrecision(const FitSweeps& sweeps, const FitPlan& plan, std::span<const Metric> metrics,
                                       std::span<const Level> levels,
                                       const std::function<void(std::size_t, std::size_t)>& progress = {});

nlohmann::json PrecisionFitsToJson(const std::vector<PrecisionFit>& fits, const FitPlan& plan);
// The headline table: one row per cell and backend (total error, one level).
void PrintPrecisionFits(const std::vector<PrecisionFit>& fits, Level level, const TextOutput& out);

}  // namespace depthbench
