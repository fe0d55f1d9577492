// Choose: the cheapest (variant, convention, format) that meets a scene's
// requirement, with the evidence. Every candidate the scene's engine can
// use is measured inside the scene's ranges (and, for a requirement at a
// given depth, at that depth), modelled over eye depth so that the error at
// the scene's far end is predicted, and costed; the ranking puts the
// cheapest candidate that meets the requirement first.
#pragma once

#include <cmath>
#include <filesystem>
#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/base/json_reader.h"
#include "bench/base/text_table.h"
#include "bench/choose/ranking.h"
#include "bench/choose/scene.h"
#include "bench/models/error_model.h"
#include "bench/speed/speed_results.h"

namespace depthbench {

inline constexpr JsonSchema kChooseSchema{"depthbench.choose", 2, "a choice of depthbench choose --json"};

class Backend;  // bench/backends/backend.h

// The static cost model: the compiled shader's floating-point instructions,
// lane by lane, each weighed by what it costs on GPU hardware relative to
// one fused multiply-add (kOperationCosts).
struct OperationCost {
  const char* operation;
  double weight;  // FMA-equivalent issue slots per lane
  const char* why;
};
extern const std::vector<OperationCost> kOperationCosts;
inline constexpr const char* kStaticCostUnit = "FMA-equivalent slots";
// For every variant of `catalogue`.
Expected<CostLookup> StaticCostLookup(const std::string& shader_dir, const Catalogue& catalogue = Catalogue::BuiltIn());

// A candidate's error over one decade of eye depth in the scene (z/near in
// [10^k, 10^(k+1)), clipped to the scene's depths), at the requirement's
// level and in its unit.
struct DepthFigure {
  double depth_min = 0.0, depth_max = 0.0;  // eye depths, world units
  double value = 0.0;
};

struct CandidateVerdict {
  Cell cell;
  // In the requirement's own unit (world units, relative error or bits).
  double measured_p999 = 0.0, measured_max = 0.0;
  double measured = 0.0;  // at the requirement's level: the point estimate
  Interval interval;      // its 95% sampling interval; the verdict uses `high`
  bool supported = true;  // enough samples at the requirement's depth for the level
  std::uint64_t samples = 0;
  // The scene's far end measured directly (its last tenth of depth, the
  // scene's cameras), in the requirement's unit and level.
  double far_end_measured = 0.0;
  // The model's value at the far end, same unit and level, published only
  // within kPublishedPredictionBits of far_end_measured and of both ends of
  // its 95% interval; NaN when withheld
  // (prediction_off_bits says by how much it missed) or not fitted.
  double predicted = 0.0;
  double prediction_off_bits = 0.0;
  // The error model used for the prediction: over eye depth with the camera
  // at the world origin ("constant", "depth"), "+camera" where the scene's
  // camera distance adds its own (choose.cc PredictAtFarEnd).
  std::string model;
  double camera_term = 0.0;     // what the camera distance adds, in world units (0: nothing)
  std::uint64_t nonfinite = 0;  // NaN or Inf findings inside the scene's ranges
  // The cause with the largest p99.9 at the requirement's depth:
  // kProduction, kStorage or kArith (the shader's part).
  Metric dominant = Metric::kArith;
  bool meets = false;
  // The variant assumes a symmetric frustum and the scene's is off-centre
  // (VariantInfo::assumes_symmetric_frustum, Domain::OffCentre): what it
  // measures is that assumption's error.
  bool wrong_lens = false;
  // The error against eye depth over the scene's cameras: the decades with
  // enough samples for the level.
  std::vector<DepthFigure> by_depth;
  // The point estimate is within the limit but the interval's upper end is
  // not: more samples could tell.
  bool too_close = false;
  bool over_budget = false;
  // With a proven requirement (level = "bound"): the candidate's proven
  // bound over the requirement's population, in its unit; +infinity where
  // none holds (`unproven` says why); NaN for a measured requirement.
  double proven = std::nan("");
  std::string unproven;
  // What the verdict and the ranking hold against the limit: the proven
  // bound, or the upper end of the measured level's interval.
  double Figure() const { return std::isnan(proven) ? interval.high : proven; }
  std::optional<CandidateCost> cost;
  int rank = 0;        // 1 = the choice; candidates that tie share a rank
  bool tied = false;   // shares its rank with another candidate
  std::string reason;  // one sentence
};

// A far-end prediction further than this from the direct measurement of
// the same population is not published: 0.3 bit is about three times the
// sampling interval of a p99.9 from 1e5 samples (about 0.1 bit).
inline constexpr double kPublishedPredictionBits = 0.3;

struct ChooseOptions {
  std::uint64_t samples = 100000;
  std::uint64_t seed = 11;
  // For a proven requirement: the programs bounded (empty: the installed
  // shaders), the splits per cell (bound.h BoundOptions), and a progress
  // callback per cell bounded.
  std::filesystem::path shader_dir;
  int bound_splits = 200;
  std::function<void(std::size_t, std::size_t)> bound_progress;
};

// What one change to the scene would give, measured as the scene is (at
// the requirement's level and depth): the best candidate of the changed
// scene and its figure.
struct WhatIf {
  std::string change;     // "reversed Z with a float buffer (reversed, d32_sfloat)"
  std::string candidate;  // the best candidate; empty when none has the samples
  double figure = 0.0;    // the upper end of its 95% interval, in the requirement's unit
  bool meets = false;
};

struct ChooseResult {
  std::string scene;
  std::string requirement;
  double limit = 0.0;  // the requirement's limit, in its own unit
  std::optional<double> at_depth;  // the eye depth the requirement applies at, if any
  std::string unit;                // the requirement's unit: "world units", "relative error" or "bits lost"
  std::string backend, device;
  std::string cost_unit, cost_source;
  std::string cost_note;                 // why the static model ranks, when a speed file was given
  bool proven = false;                   // the requirement is proven (level = "bound")
  std::vector<CandidateVerdict> ranked;  // best first
  std::vector<std::string> suggestions;  // when nothing meets the requirement
  std::vector<std::string> unusable_formats;  // listed but never a candidate (Scene::UnusableFormats)
  std::vector<WhatIf> what_ifs;               // when nothing meets the requirement
  std::vector<std::string> projection_facts;  // what the scene's projection matrix holds (Scene)
  std::string lens;                           // the scene's off-centre lens, in words; empty when centred
  // The scene's population when it is a captured frame's pixels, in
  // words; empty for the random draw over the scene's ranges.
  std::string population;
  // What Direct3D, Vulkan, Metal and OpenGL must do to store the choice's
  // depth (projection_matrix.h ApiRecipe); empty when nothing meets it.
  std::string api_recipe;
  bool Met() const { return !ranked.empty() && ranked.front().meets; }
  double seconds = 0.0;
};

Expected<ChooseResult> Choose(const Scene& scene, Backend& backend, const CostSources& costs,
                              const ChooseOptions& options);

void PrintChoice(const ChooseResult& result, const TextOutput& out);
// A short Markdown summary for a CI job's page: the requirement, the
// choice (or that none meets it), the first ten candidates.
std::string ChoiceSummaryMarkdown(const ChooseResult& result);
nlohmann::json ChoiceToJson(const ChooseResult& result);

}  // namespace depthbench
