#include "bench/choose/choose.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "bench/backends/vulkan/variant_program.h"
#include "bench/base/resources.h"
#include "bench/base/text_table.h"
#include "bench/bound/bound.h"
#include "bench/pipeline/captured.h"
#include "bench/speed/instruction_mix.h"
#include "bench/speed/speed_results.h"
#include "bench/speed/trade.h"
#include "bench/sweep/sweep.h"

namespace depthbench {
namespace {

// The special-function unit's operations among GLSL.std.450's.
bool OnSpecialFunctionUnit(const std::string& name) {
  static const std::set<std::string> kNames{"Sqrt", "InverseSqrt", "Exp", "Exp2", "Log",  "Log2", "Pow",
                                            "Sin",  "Cos",         "Tan", "Asin", "Acos", "Atan", "Atan2"};
  return kNames.count(name) != 0;
}

double WeighedCost(const InstructionMix& m) {
  const auto weight = [](std::size_t row) { return kOperationCosts[row].weight; };
  double special = 0.0, other = 0.0;
  for (const auto& [name, count] : m.extended_by_name) (OnSpecialFunctionUnit(name) ? special : other) += count.lanes;
  return weight(0) * (m.fadd.lanes + m.fmul.lanes) + weight(1) * m.fneg.lanes + weight(2) * m.fma.lanes +
         weight(3) * (m.dot.lanes + m.matrix_vector.lanes + m.matrix_matrix.lanes) + weight(4) * m.fdiv.lanes +
         weight(5) * special + weight(6) * other;
}

// The requirement's unit, from a band's statistics.
double InUnit(const Requirement& req, double value) {
  return req.kind == Requirement::Kind::kBitsLost ? BitsLost(value) : value;
}
Metric MetricOf(const Requirement& req) {
  return req.kind == Requirement::Kind::kAbsolute ? Metric::kAbsolute : Metric::kTotal;
}
double InUnit(const Requirement& req, const BandStats& band, Level level) {
  return InUnit(req, band[MetricOf(req)].AtLevel(level, MetricOf(req)));
}
Interval InUnitInterval(const Requirement& req, const BandStats& band, Level level) {
  const Interval i = band[MetricOf(req)].LevelInterval(level, MetricOf(req));
  return {InUnit(req, i.low), InUnit(req, i.high)};
}

std::string InUnitText(const Requirement& req, double v) {
  switch (req.kind) {
    case Requirement::Kind::kAbsolute: return fmt::format("{:.3g}", v);
    case Requirement::Kind::kRelative: return fmt::format("{:.3g}", v);
    case Requirement::Kind::kBitsLost: return fmt::format("{:.1f} bits", v);
  }
  return "";
}

// The deepest eye depth the scene's population reaches: the end of its
// range of interest, or the far plane; a capture's farthest pixel if that
// is nearer.
double DepthLimit(const Domain& d) {
  double limit = d.eye_depth ? d.eye_depth->max : d.finite_far ? d.far->max : d.near.max * Domain::kInfiniteDepthSpan;
  if (d.capture) limit = std::min(limit, DeepestPixel(*d.capture));
  return limit;
}

// A band's figure of `metric` at `level`, as a fit point's b (log2 + 24);
// nullopt when the band has too few samples or no positive finite figure.
std::optional<double> BandB(const BandStats& band, Metric metric, Level level) {
  if (band.finite < MinimumSamples(level)) return std::nullopt;
  const double q = band[metric].AtLevel(level, metric);
  if (!(q > 0.0) || !std::isfinite(q)) return std::nullopt;
  return std::log2(q) + 24.0;
}

// The far end's error, predicted from two parts (docs/choosing.md):
//   - the error with the camera at the world origin (what camera-relative
//     rendering leaves: the depth's production and storage, the shader's
//     arithmetic), modelled over eye depth on a sweep of the scene with its
//     camera there, each depth decade's figure at its far edge (where
//     errors grow with depth, a decade's high quantile is set by its
//     deepest samples; docs/error-model.md), evaluated at the far end;
//   - the error the scene's camera distance adds: float32 world
//     coordinates a distance D from the origin are about 2^-24 D apart,
//     an absolute error that does not depend on depth (in bits,
//     log2(D / distance to the point) plus a constant: docs/error-model.md).
//     It is taken from the scene's own samples: in the depth decade where
//     the scene's figure stands furthest above the camera-at-origin one,
//     A = sqrt(scene^2 - origin^2) in world units; relative to the far end
//     it is A / far end.
// The two add as independent errors do, in quadrature. A model over the
// scene's samples alone mixed them: near decades, where the camera's
// distance dominates and the error falls with depth, pulled the fit down
// at the far end (open_world: 0.004 predicted, 0.015 measured).
struct FarEndPrediction {
  double value = std::nan("");  // in the requirement's unit
  std::string model;            // "depth", "constant+camera", ...
  double camera_term = 0.0;     // A, world units
};

FarEndPrediction PredictAtFarEnd(const Scene& scene, const CellResult& in_scene, const CellResult& at_origin,
                                 Level level) {
  const Requirement& req = scene.requirement;
  const Metric metric = MetricOf(req);
  const double near = scene.domain.near.min, far_end = DepthLimit(scene.domain);
  const double lowest = scene.domain.eye_depth ? scene.domain.eye_depth->min : near;
  std::vector<FitPoint> points;
  double camera_term = 0.0, most_above = kResolvedBits;
  for (int d = 0; d < kDepthBands; ++d) {
    const double lo = std::max(lowest, near * DepthBandLow(d)), hi = std::min(far_end, near * DepthBandLow(d) * 10.0);
    if (!(hi > lo)) continue;
    const BandStats origin = at_origin.stats.ForDepth(d);
    if (const std::optional<double> b = BandB(origin, metric, level)) points.push_back({0.0, std::log2(hi / near), *b});
    const std::optional<double> scene_abs = BandB(in_scene.stats.ForDepth(d), Metric::kAbsolute, level);
    const std::optional<double> origin_abs = BandB(origin, Metric::kAbsolute, level);
    if (scene_abs && origin_abs && *scene_abs - *origin_abs > most_above) {
      most_above = *scene_abs - *origin_abs;
      camera_term = std::ldexp(std::sqrt(std::exp2(2.0 * *scene_abs) - std::exp2(2.0 * *origin_abs)), -24);
    }
  }
  const ModelKind candidates[] = {ModelKind::kConstant, ModelKind::kDepth};
  const std::vector<FittedModel> ranked = FitAndRank(points, candidates);
  FarEndPrediction p;
  if (ranked.empty()) {
    // Each depth decade needs the level's samples (4000 for a p99.9).
    p.model = "too few samples";
    return p;
  }
  const double at_far = std::ldexp(std::exp2(ranked.front().Predict(0.0, std::log2(far_end / near))), -24);
  const double camera = metric == Metric::kAbsolute ? camera_term : camera_term / far_end;
  const double value = std::hypot(at_far, camera);
  p.value = req.kind == Requirement::Kind::kBitsLost ? BitsLost(value) : value;
  p.model = std::string(Info(ranked.front().kind).name) + (camera_term > 0.0 ? "+camera" : "");
  p.camera_term = camera_term;
  return p;
}

// 5861 -> 5900: a sample count to suggest.
double RoundUpToTwoDigits(double x) {
  const double step = std::pow(10.0, std::max(0.0, std::floor(std::log10(x)) - 1.0));
  return std::ceil(x / step) * step;
}

// Which cause dominates, in words.
const char* CauseText(Metric cause) {
  switch (cause) {
    case Metric::kProduction: return "the depth the pipeline produces (float32 clip z and divide) dominates";
    case Metric::kStorage: return "the format's storage error dominates";
    default: return "the shader's arithmetic dominates";
  }
}

}  // namespace

const std::vector<OperationCost> kOperationCosts{
    {"add, subtract, multiply (OpFAdd, OpFSub, OpFMul)", 1.0, "one issue slot of the FMA pipes"},
    {"negate (OpFNegate)", 0.0, "folded into the instruction that uses it, as a source modifier"},
    {"fused multiply-add (GLSL.std.450 Fma)", 1.0, "one issue slot"},
    {"multiply-add of a dot or matrix product (OpDot, OpMatrixTimesVector, ...)", 1.0,
     "one FMA per multiply-add: a mat4 x vec4 is 16"},
    {"division or reciprocal (OpFDiv; SPIR-V has no reciprocal)", 9.0,
     "a reciprocal on the special-function unit, which issues at 1/8 of the FMA rate (16 against 128 lanes per "
     "clock on an NVIDIA SM), then a multiply"},
    {"square root, inverse square root, exp2, log2, trigonometry (GLSL.std.450)", 8.0,
     "the special-function unit, at 1/8 of the FMA rate"},
    {"other GLSL.std.450 (min, max, abs, clamp, floor, ...)", 1.0, "one issue slot"},
};

Expected<CostLookup> StaticCostLookup(const std::string& shader_dir, const Catalogue& catalogue) {
  std::filesystem::path dir = shader_dir;
  if (dir.empty()) DB_RETURN_IF_ERROR(StoreInto(DataPath("shaders"), dir));
  std::map<Variant, CandidateCost> by_variant;
  for (const VariantInfo& v : catalogue.variants()) {
    DB_ASSIGN_OR_RETURN(std::vector<std::uint32_t> spirv, CompileVariant(v, VariantPass::kAccuracy, dir));
    DB_ASSIGN_OR_RETURN(InstructionMix mix, CountInstructionMix(spirv, VariantFunctionName(v)));
    CandidateCost& cost = by_variant[v.id];
    cost.value = WeighedCost(mix);
    cost.unit = kStaticCostUnit;
    cost.source = "static model: the compiled shader's instructions, weighed per operation as choose --help lists";
  }
  return CostLookup(
      [by_variant](const Cell& cell) -> std::optional<CandidateCost> { return by_variant.at(cell.variant); });
}

namespace {

// The populations a choice is judged on: the whole scene; the scene with
// its camera at the world origin (the far-end model's input); the last
// tenth of depth before the requirement's depth, and before the far end.
// A population not swept separately is the scene itself (a camera that
// never leaves the origin) or the requirement's depth (at the far end).
struct Populations {
  Results scene, origin, depth, far;
  Domain judged_domain;  // the requirement's population (judged()'s)
  bool own_origin = false, own_depth = false, own_far = false;
  const Results& at_origin() const { return own_origin ? origin : scene; }
  const Results& judged() const { return own_depth ? depth : scene; }
  const Results& at_far() const { return own_far ? far : judged(); }
};

SweepOptions SceneSweep(const Domain& domain, const std::vector<Cell>& cells, const ChooseOptions& options) {
  SweepOptions sweep;
  sweep.seed = options.seed;
  sweep.samples = options.samples;
  sweep.domain = domain;
  sweep.cells = CellsForDomain(cells, domain);
  return sweep;
}

// The last tenth of eye depth before `depth` in `sweep`'s domain.
SweepOptions Before(SweepOptions sweep, double depth) {
  const Domain& d = sweep.domain;
  const double lowest = d.eye_depth ? d.eye_depth->min : d.near.min;
  sweep.domain.eye_depth = Range{std::max(lowest, depth / 1.1), depth};
  return sweep;
}

Expected<Populations> Measure(const Scene& scene, Backend& backend, const std::vector<Cell>& cells,
                              const ChooseOptions& options) {
  Backend* backends[] = {&backend};
  const Requirement& req = scene.requirement;
  const SweepOptions whole = SceneSweep(scene.domain, cells, options);
  Populations p;
  DB_ASSIGN_OR_RETURN(p.scene, RunSweep(whole, backends));
  if (scene.domain.camera_distance.max > 0.0) {
    SweepOptions origin = whole;
    origin.domain.camera_distance = Range{0.0, 0.0};
    DB_ASSIGN_OR_RETURN(p.origin, RunSweep(origin, backends));
    p.own_origin = true;
  }
  p.judged_domain = whole.domain;
  if (req.at_depth) {
    const SweepOptions before = Before(whole, *req.at_depth);
    p.judged_domain = before.domain;
    DB_ASSIGN_OR_RETURN(p.depth, RunSweep(before, backends));
    p.own_depth = true;
  }
  // The far end, directly: what a far-end prediction is checked against.
  const double far_end = DepthLimit(scene.domain);
  if (!req.at_depth || *req.at_depth != far_end) {
    DB_ASSIGN_OR_RETURN(p.far, RunSweep(Before(whole, far_end), backends));
    p.own_far = true;
  }
  return p;
}

// The figures of one candidate at the requirement's level and depth.
void JudgeFigures(const Requirement& req, const BandStats& band, CandidateVerdict& v) {
  v.samples = band.finite;
  v.supported = band.finite >= MinimumSamples(req.level);
  v.measured_p999 = InUnit(req, band, Level::kP999);
  v.measured_max = InUnit(req, band, Level::kMax);
  v.measured = req.level == Level::kMax ? v.measured_max : v.measured_p999;
  v.interval = InUnitInterval(req, band, req.level);
  double largest = -1.0;
  for (Metric cause : {Metric::kProduction, Metric::kStorage, Metric::kArith}) {
    const double p999 = band[cause].AtLevel(Level::kP999, cause);
    if (p999 > largest) {
      largest = p999;
      v.dominant = cause;
    }
  }
}

// A candidate's figure per decade of eye depth over the scene's own
// population, where the decade holds enough samples for the level.
std::vector<DepthFigure> ByDepth(const Scene& scene, const CellResult& in_scene) {
  const Requirement& req = scene.requirement;
  const Domain& d = scene.domain;
  const double lowest = d.eye_depth ? d.eye_depth->min : d.near.min, deepest = DepthLimit(d);
  std::vector<DepthFigure> figures;
  for (int k = 0; k < kDepthBands; ++k) {
    const BandStats band = in_scene.stats.ForDepth(k);
    if (band.finite < MinimumSamples(req.level)) continue;
    DepthFigure f;
    f.depth_min = std::max(lowest, d.near.min * std::pow(10.0, k));
    f.depth_max = std::min(deepest, d.near.max * std::pow(10.0, k + 1));
    f.value = InUnit(req, band, req.level);
    if (f.depth_max > f.depth_min && std::isfinite(f.value)) figures.push_back(f);
  }
  return figures;
}

// A proven relative bound (bound.h CellBound::total) in the requirement's
// unit: an absolute error at the requirement's depth is at most that
// depth times the longest ray per unit of eye depth times the bound.
double ProvenInUnit(const Requirement& req, const Domain& domain, double total) {
  switch (req.kind) {
    case Requirement::Kind::kAbsolute: return total * req.at_depth.value_or(DepthLimit(domain)) * bound::LongestRay(domain);
    case Requirement::Kind::kRelative: return total;
    case Requirement::Kind::kBitsLost: return bound::BoundBits(total);
  }
  return INFINITY;
}

// The proven bounds of `cells` over the requirement's population, in the
// order of `cells`; empty for a measured requirement.
Expected<std::vector<bound::CellBound>> ProveCandidates(const Scene& scene, const Populations& p,
                                                        const std::vector<Cell>& cells, const ChooseOptions& options) {
  if (!scene.requirement.proven) return std::vector<bound::CellBound>{};
  std::filesystem::path dir = options.shader_dir;
  if (dir.empty()) DB_RETURN_IF_ERROR(StoreInto(DataPath("shaders"), dir));
  bound::BoundOptions bound_options;
  bound_options.splits = options.bound_splits;
  Expected<std::vector<bound::CellBound>> bounds =
      bound::BoundCells(p.judged_domain, cells, dir, bound_options, options.bound_progress);
  if (!bounds.ok()) return bounds.status().WithContext("requirement.level = \"bound\"");
  return bounds;
}

// One candidate's verdict; nullopt when a population lacks it.
std::optional<CandidateVerdict> Judge(const Scene& scene, const Cell& cell, const Populations& p,
                                      const std::string& backend, const CostLookup& cost_of,
                                      const bound::CellBound* proven) {
  const Requirement& req = scene.requirement;
  const CellResult* at_depth = p.judged().Find(cell, backend);
  const CellResult* in_scene = p.scene.Find(cell, backend);
  const CellResult* origin = p.at_origin().Find(cell, backend);
  const CellResult* far = p.at_far().Find(cell, backend);
  if (at_depth == nullptr || in_scene == nullptr || origin == nullptr || far == nullptr) return std::nullopt;
  const BandStats band = at_depth->stats.All();
  const BandStats whole_band = in_scene->stats.All();
  CandidateVerdict v;
  v.cell = cell;
  v.wrong_lens = cell.variant_info().assumes_symmetric_frustum && scene.domain.OffCentre();
  JudgeFigures(req, band, v);
  v.by_depth = ByDepth(scene, *in_scene);
  const FarEndPrediction prediction = PredictAtFarEnd(scene, *in_scene, *origin, req.level);
  v.far_end_measured = InUnit(req, far->stats.All(), req.level);
  v.predicted = prediction.value;
  v.model = prediction.model;
  v.camera_term = prediction.camera_term;
  if (std::isfinite(v.predicted)) {
    // Published only where the whole 95% interval of the measurement is
    // within reach: another sample of the same population agrees too.
    const auto off = [&](double measured) {
      return req.kind == Requirement::Kind::kBitsLost ? v.predicted - measured : std::log2(v.predicted / measured);
    };
    const Interval far_interval = InUnitInterval(req, far->stats.All(), req.level);
    v.prediction_off_bits = off(v.far_end_measured);
    const double furthest = std::max({std::fabs(v.prediction_off_bits), std::fabs(off(far_interval.low)),
                                      std::fabs(off(far_interval.high))});
    if (!(furthest <= kPublishedPredictionBits)) v.predicted = std::nan("");
  }
  // Findings only: outputs that are NaN or Inf where exact arithmetic on
  // the same inputs is finite, for samples inside the scene's ranges.
  v.nonfinite = band.nan + band.inf + whole_band.nan + whole_band.inf;
  // On the upper end of the interval: a candidate meets the requirement
  // only if the sampling error cannot be what makes it pass.
  v.meets = v.supported && v.interval.high <= req.value && v.nonfinite == 0;
  v.too_close = v.supported && v.nonfinite == 0 && v.measured <= req.value && !v.meets;
  if (req.proven) {
    // The bound decides: it holds for every input of the population, so
    // no sampling interval or sample count enters.
    v.proven = proven != nullptr ? ProvenInUnit(req, p.judged_domain, proven->total) : INFINITY;
    if (!std::isfinite(v.proven)) v.unproven = proven != nullptr ? proven->unbounded : "not bounded";
    v.meets = v.nonfinite == 0 && v.proven <= req.value;
    v.too_close = false;
  }
  v.cost = cost_of ? cost_of(cell) : std::nullopt;
  v.over_budget = scene.max_cost && v.cost && v.cost->value > *scene.max_cost;
  return v;
}

// InvalidArgument when no candidate has the samples the level needs: no
// verdict can be given, and a ranking of unsupported figures would read
// as one.
Status CheckSupported(const ChooseResult& result, const Requirement& req, const ChooseOptions& options) {
  std::uint64_t most_samples = 0;
  bool any_supported = false;
  for (const CandidateVerdict& v : result.ranked) {
    most_samples = std::max(most_samples, v.samples);
    any_supported = any_supported || v.supported;
  }
  if (result.ranked.empty() || any_supported) return Status::Ok();
  const std::uint64_t needed = MinimumSamples(req.level);
  const double scale = static_cast<double>(needed) / static_cast<double>(std::max<std::uint64_t>(most_samples, 1));
  return InvalidArgument(fmt::format(
      "--samples {}: too few for a {} verdict: at most {} samples fall where the requirement is judged, and a {} "
      "needs {}; raise --samples to at least {:.0f}",
      options.samples, LevelName(req.level), most_samples, LevelName(req.level), needed,
      RoundUpToTwoDigits(static_cast<double>(options.samples) * scale * 1.1)));
}

// The ranking (ranking.h), on the upper end of each interval.
void RankVerdicts(ChooseResult& result, bool req_proven) {
  std::vector<RankInput> inputs;
  for (const CandidateVerdict& v : result.ranked) {
    inputs.push_back({v.meets, v.over_budget, v.nonfinite, v.supported || req_proven, v.Figure(), v.cost});
  }
  std::vector<CandidateVerdict> ranked;
  for (const RankPlace& place : Rank(inputs)) {
    ranked.push_back(result.ranked[place.candidate]);
    ranked.back().rank = place.rank;
    ranked.back().tied = place.tied;
  }
  result.ranked = std::move(ranked);
}

// The built-in variants that assume a symmetric frustum (or that do not),
// by name: "tan_aspect, divide, reciprocal, pq".
std::string BuiltInVariantsWhere(bool assume_symmetric_frustum) {
  std::vector<std::string_view> names;
  for (const VariantInfo& v : AllVariants()) {
    if (v.assumes_symmetric_frustum == assume_symmetric_frustum) names.push_back(v.name);
  }
  return fmt::format("{}", fmt::join(names, ", "));
}

// The scene's lens when it is off-centre, in words.
std::string LensText(const Domain& d) {
  if (!d.OffCentre()) return "";
  std::vector<std::string> parts;
  if (d.eye_fov && d.eye_fov->OffAxis()) {
    parts.push_back(fmt::format("an off-centre field of view ({:.4g}, {:.4g}, {:.4g}, {:.4g} degrees left, right, up, "
                                "down)",
                                d.eye_fov->left, d.eye_fov->right, d.eye_fov->up, d.eye_fov->down));
  }
  if (d.jitter > 0.0) parts.push_back(fmt::format("TAA jitter of up to {:g} px", d.jitter));
  return fmt::format("{}: variants that assume a symmetric frustum ({}) are measured with the error that assumption "
                     "makes",
                     fmt::join(parts, " and "), BuiltInVariantsWhere(true));
}

// Each verdict in one sentence.
void Explain(const Scene& scene, ChooseResult& result) {
  const Requirement& req = scene.requirement;
  const std::uint64_t needed = MinimumSamples(req.level);
  const double limit = req.value;
  for (CandidateVerdict& v : result.ranked) {
    const std::string measured =
        req.proven ? fmt::format("proven {} (measured max {})", InUnitText(req, v.proven), InUnitText(req, v.measured))
                   : InUnitText(req, v.interval.high);
    const std::string at_most =
        req.proven ? fmt::format("at most {} on any conformant Vulkan device (measured max {})",
                                 InUnitText(req, v.proven), InUnitText(req, v.measured))
                   : fmt::format("{} at most (95% interval)", measured);
    const std::string cost =
        v.cost ? fmt::format("{:.3g} {}", v.cost->value, v.cost->unit) : std::string("unknown cost");
    if (v.meets && v.rank == 1) {
      v.reason = fmt::format("{}: {} against {} ({:.1f}x margin), {}",
                             v.tied ? "tied for the cheapest that meets it" : "the cheapest that meets it", at_most,
                             InUnitText(req, limit), limit / std::max(v.Figure(), 1e-300), cost);
    } else if (v.meets && v.over_budget) {
      v.reason = fmt::format("meets it ({}), but {} is over the budget of {:g}", measured, cost, *scene.max_cost);
    } else if (v.meets) {
      v.reason = fmt::format("meets it ({}), but costs more: {}", measured, cost);
    } else if (req.proven && !std::isfinite(v.proven)) {
      v.reason = fmt::format("fails: no bound is proven ({}); measured max {}", v.unproven, InUnitText(req, v.measured));
    } else if (!v.supported && !req.proven) {
      v.reason = fmt::format("unsupported: {} samples at the requirement's depth, a {} needs {} (raise --samples)",
                             v.samples, LevelName(req.level), needed);
    } else if (v.nonfinite > 0) {
      v.reason = fmt::format("fails: {} NaN or Inf outputs inside the scene", v.nonfinite);
    } else if (v.too_close) {
      v.reason = fmt::format("fails: {} measured, but the interval reaches {}: too close to call",
                             InUnitText(req, v.measured), measured);
    } else {
      v.reason = fmt::format("fails: {}, {:.3g}x the limit; {}", measured, v.Figure() / limit,
                             v.wrong_lens ? "its formula assumes a symmetric frustum, and this scene's is off-centre "
                                            "(it puts NDC (0, 0) on the view axis)"
                                          : CauseText(v.dominant));
    }
  }

}

// What would have to change when nothing meets the requirement, in words.
void Suggest(const Scene& scene, ChooseResult& result) {
  const Requirement& req = scene.requirement;
  const double limit = req.value;
  if (!result.Met() && !result.ranked.empty()) {
    const CandidateVerdict& closest = result.ranked.front();
    result.suggestions.push_back(fmt::format("nothing meets {}; the closest is {} at {} ({:.3g}x the limit)",
                                             req.Describe(), closest.cell.Name(), InUnitText(req, closest.Figure()),
                                             closest.Figure() / limit));
    const bool depth = closest.dominant != Metric::kArith;  // production or storage: the depth buffer's own
    const bool reversed_float =
        closest.cell.format == Format::kD32Sfloat && (Info(closest.cell.convention).bits & 1u) != 0u;
    if (closest.wrong_lens) {
      result.suggestions.push_back(fmt::format(
          "its formula assumes a symmetric frustum and this scene's is off-centre: a variant that follows the "
          "frustum ({}), or the same formula with the frustum's centre added back (a variant file), removes that "
          "error",
          BuiltInVariantsWhere(false)));
    } else if (depth && !reversed_float) {
      result.suggestions.push_back(fmt::format(
          "{}: a float depth buffer with reversed Z (d32_sfloat, reversed, clip depth [0,1]) keeps the relative "
          "error of the stored depth flat across depth; with a unorm or standard-Z format it grows with z/near",
          CauseText(closest.dominant)));
      const double factor = closest.measured / limit;
      if (scene.domain.near.fixed()) {
        result.suggestions.push_back(fmt::format(
            "or raise the near plane: the storage error of standard Z and of unorm formats scales with z/near, so "
            "near = {:.3g} (x{:.2g}) would bring the closest candidate to the limit",
            scene.domain.near.min * factor, factor));
      }
    } else if (depth) {
      result.suggestions.push_back(
          fmt::format("{} even with reversed-Z float depth: only a larger near plane (or a smaller depth range) helps",
                      CauseText(closest.dominant)));
    } else {
      const double distance = scene.domain.camera_distance.max;
      result.suggestions.push_back(fmt::format(
          "the shader's arithmetic dominates{}: a variant with fewer roundings, or positions computed "
          "camera-relative{}",
          distance > 0.0
              ? fmt::format(" (the camera goes {:g} from the world origin, where float32 world "
                            "coordinates are {:.3g} apart)",
                            distance,
                            std::nextafter(static_cast<float>(distance), INFINITY) - static_cast<float>(distance))
              : "",
          distance > 0.0 ? " (subtract the camera position before, not after, reconstructing)" : ""));
    }
  }
}

// The best candidate among `cells` in `domain`, judged as the scene's
// requirement is; nullopt when no cell runs there.
Expected<std::optional<WhatIf>> TryWhatIf(const Scene& scene, Backend& backend, const ChooseOptions& options,
                                          std::string change, const Domain& domain, const std::vector<Cell>& cells) {
  const Requirement& req = scene.requirement;
  SweepOptions sweep = SceneSweep(domain, cells, options);
  if (sweep.cells.empty()) return std::optional<WhatIf>();
  if (req.at_depth) sweep = Before(sweep, *req.at_depth);
  Backend* backends[] = {&backend};
  DB_ASSIGN_OR_RETURN(const Results results, RunSweep(sweep, backends));
  WhatIf what_if{std::move(change), "", 0.0, false};
  for (const CellResult& c : results.cells) {
    const BandStats band = c.stats.All();
    CandidateVerdict v;
    JudgeFigures(req, band, v);
    if (!v.supported || band.nan + band.inf > 0) continue;
    if (what_if.candidate.empty() || v.interval.high < what_if.figure) {
      what_if.candidate = c.cell.Name();
      what_if.figure = v.interval.high;
    }
  }
  what_if.meets = !what_if.candidate.empty() && what_if.figure <= req.value;
  return std::optional<WhatIf>(std::move(what_if));
}

// When nothing meets the requirement: each change an engine could make,
// measured. Reversed Z with a float buffer; a float buffer under the
// scene's conventions; the near plane ten times further; positions
// computed camera-relative (the camera at the world origin); the depth
// range split in two at its geometric middle, the part that holds the
// requirement's depth with its own near or far plane.
Status AddWhatIfs(const Scene& scene, Backend& backend, const ChooseOptions& options, ChooseResult& result) {
  const Domain& d = scene.domain;
  const std::vector<Cell> cells = scene.Candidates();
  std::vector<std::pair<std::string, std::pair<Domain, std::vector<Cell>>>> changes;
  changes.push_back({"reversed Z with a float buffer (reversed, d32_sfloat)",
                     {d, scene.CellsWith({Convention::kReversed}, {Format::kD32Sfloat})}});
  changes.push_back({"a float buffer under the scene's conventions (d32_sfloat)",
                     {d, scene.CellsWith(scene.conventions, {Format::kD32Sfloat})}});
  const double depth = scene.requirement.at_depth.value_or(DepthLimit(d));
  if (d.near.fixed() && d.near.min * 10.0 < depth) {
    Domain moved = d;
    moved.near = Range{d.near.min * 10.0, d.near.min * 10.0};
    if (moved.eye_depth) moved.eye_depth->min = std::max(moved.eye_depth->min, moved.near.min);
    changes.push_back({fmt::format("the near plane at {:g} (x10)", moved.near.min), {moved, cells}});
  }
  if (d.camera_distance.max > 0.0) {
    Domain relative = d;
    relative.camera_distance = Range{0.0, 0.0};
    changes.push_back({fmt::format("positions camera-relative (the camera {:g} out, at the origin instead)",
                                   d.camera_distance.max),
                       {relative, cells}});
  }
  if (d.near.fixed() && d.finite_far && d.far && d.far->fixed()) {
    const double split = std::sqrt(d.near.min * d.far->min);
    Domain part = d;
    if (depth > split) {
      part.near = Range{split, split};
      part.eye_depth = Range{split, std::min(d.far->min, DepthLimit(d))};
    } else {
      part.far = Range{split, split};
      part.eye_depth = Range{d.near.min, split};
    }
    changes.push_back({fmt::format("the depth range split at {:.3g} (each part with its own near and far plane)", split),
                       {part, cells}});
  }
  for (const auto& [change, what] : changes) {
    if (what.second.empty()) continue;
    std::optional<WhatIf> w;
    DB_RETURN_IF_ERROR(StoreInto(TryWhatIf(scene, backend, options, change, what.first, what.second), w));
    if (w) result.what_ifs.push_back(std::move(*w));
  }
  return Status::Ok();
}

}  // namespace

Expected<ChooseResult> Choose(const Scene& scene, Backend& backend, const CostSources& costs,
                              const ChooseOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  const std::vector<Cell> cells = scene.Candidates();
  DB_ASSIGN_OR_RETURN(const Populations populations, Measure(scene, backend, cells, options));

  ChooseResult result;
  result.scene = scene.name;
  result.requirement = scene.requirement.Describe();
  result.proven = scene.requirement.proven;
  result.limit = scene.requirement.value;
  result.at_depth = scene.requirement.at_depth;
  result.unit = scene.requirement.kind == Requirement::Kind::kAbsolute ? "world units"
                : scene.requirement.kind == Requirement::Kind::kRelative ? "relative error"
                                                                          : "bits lost";
  result.backend = backend.name();
  result.device = backend.device().name;
  result.unusable_formats = scene.UnusableFormats();
  // One cost unit for the whole ranking.
  const CostChoice chosen_costs = ChooseCosts(costs, cells);
  result.cost_note = chosen_costs.note;
  DB_ASSIGN_OR_RETURN(const std::vector<bound::CellBound> bounds,
                      ProveCandidates(scene, populations, cells, options));
  for (std::size_t k = 0; k < cells.size(); ++k) {
    const bound::CellBound* proven = k < bounds.size() ? &bounds[k] : nullptr;
    if (auto v = Judge(scene, cells[k], populations, backend.name(), chosen_costs.lookup, proven))
      result.ranked.push_back(*v);
  }
  DB_RETURN_IF_ERROR(CheckSupported(result, scene.requirement, options));
  if (!result.ranked.empty() && result.ranked.front().cost) {
    result.cost_unit = result.ranked.front().cost->unit;
    result.cost_source = result.ranked.front().cost->source;
  }
  RankVerdicts(result, scene.requirement.proven);
  result.projection_facts = scene.projection_facts;
  result.lens = LensText(scene.domain);
  if (const auto& capture = scene.domain.capture) {
    result.population = fmt::format("the {} drawn pixels of {} within the frustum ({})",
                                    CapturedSource(scene.domain).sample_count(), capture->source, capture->description);
  }
  if (result.Met()) result.api_recipe = ApiRecipe(result.ranked.front().cell.convention);
  Explain(scene, result);
  Suggest(scene, result);
  // What-ifs are measured; a proven requirement's would need their own
  // bounds, so it has none.
  if (!result.Met() && !result.ranked.empty() && !scene.requirement.proven) {
    DB_RETURN_IF_ERROR(AddWhatIfs(scene, backend, options, result));
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

namespace {

// What holds a candidate back, in a word.
std::string Limit(const CandidateVerdict& v) {
  if (v.meets) return "";
  if (!std::isnan(v.proven) && !std::isfinite(v.proven)) return "no bound";
  if (!v.supported && std::isnan(v.proven)) return "samples";
  if (v.wrong_lens) return "symmetric lens";
  if (v.nonfinite > 0) return "NaN/Inf";
  if (v.too_close) return "interval";
  switch (v.dominant) {
    case Metric::kProduction: return "production";
    case Metric::kStorage: return "storage";
    default: return "shader";
  }
}

// Each what-if in one line.
std::vector<std::string> WhatIfLines(const ChooseResult& r) {
  std::vector<std::string> lines;
  for (const WhatIf& w : r.what_ifs) {
    lines.push_back(w.candidate.empty()
                        ? fmt::format("{}: no candidate has the samples there", w.change)
                        : fmt::format("{}: {} at {:.3g}, {}", w.change, w.candidate, w.figure,
                                      w.meets ? "meets it" : "still fails"));
  }
  return lines;
}

// The far-end model's prediction, or why it is not published.
std::string ModelText(const CandidateVerdict& v) {
  if (std::isfinite(v.predicted)) return fmt::format("{:.3g} ({})", v.predicted, v.model);
  if (v.prediction_off_bits != 0.0) return fmt::format("withheld: {:+.1f} bits off", v.prediction_off_bits);
  return v.model;
}

// The ranked candidates, best first; at most `rows` of them.
TextTable CandidateTable(const ChooseResult& r, std::size_t rows) {
  using Align = TextTable::Align;
  std::vector<TextTable::Column> columns{{"rank"}, {"candidate", Align::kLeft}, {"measured (upper)"}};
  if (r.proven) columns.push_back({"proven"});
  columns.insert(columns.end(), {{"far end"},
                                 {"model", Align::kLeft, true},
                                 {"NaN/Inf"},
                                 {"meets", Align::kLeft},
                                 {"held back by", Align::kLeft, true},
                                 {"B/px"},
                                 {"cost"}});
  TextTable table(std::move(columns));
  for (std::size_t k = 0; k < r.ranked.size() && k < rows; ++k) {
    const CandidateVerdict& v = r.ranked[k];
    std::vector<std::string> row{fmt::format("{}{}", v.rank, v.tied ? "=" : ""), v.cell.Name(),
                                 v.interval.high > v.measured
                                     ? fmt::format("{:.3g} (<={:.3g})", v.measured, v.interval.high)
                                     : fmt::format("{:.3g}", v.measured)};
    if (r.proven) row.push_back(std::isfinite(v.proven) ? fmt::format("{:.3g}", v.proven) : "none");
    row.insert(row.end(),
               {fmt::format("{:.3g}", v.far_end_measured), ModelText(v), std::to_string(v.nonfinite),
                v.meets ? (v.over_budget ? "over budget" : "yes") : "no", Limit(v),
                v.cost && v.cost->bytes_per_pixel > 0 ? std::to_string(v.cost->bytes_per_pixel) : "-",
                v.cost ? fmt::format("{:.3g}", v.cost->value) : "-"});
    table.AddRow(std::move(row));
  }
  return table;
}

}  // namespace

std::string ChoiceSummaryMarkdown(const ChooseResult& r) {
  std::ostringstream out;
  out << fmt::format("### depthbench choose: scene '{}'\n\n{}.\n\n", r.scene, r.requirement);
  if (!r.lens.empty()) out << "Lens: " << r.lens << ".\n\n";
  if (r.Met()) {
    out << fmt::format("Choice: **{}** ({}).\n\nTo store {}: {}.\n\n", r.ranked.front().cell.Name(),
                       r.ranked.front().reason, Info(r.ranked.front().cell.convention).name, r.api_recipe);
  } else {
    out << "No candidate meets it.\n\n";
    for (const std::string& line : WhatIfLines(r)) out << "- What if " << line << "\n";
    if (!r.what_ifs.empty()) out << "\n";
  }
  for (const std::string& u : r.unusable_formats) out << "Not a candidate: " << u << ".\n\n";
  constexpr std::size_t kRows = 10;
  CandidateTable(r, kRows).Print(TextOutput(out, TableStyle{TableFormat::kMarkdown, 0}));
  if (r.ranked.size() > kRows) {
    out << fmt::format("\n... and {} more candidates (choose --json has them all).\n", r.ranked.size() - kRows);
  }
  out << fmt::format("\n<sub>Cost: {} ({}). Backend {} on {}.</sub>\n", r.cost_unit, r.cost_source, r.backend,
                     r.device);
  return out.str();
}

void PrintChoice(const ChooseResult& r, const TextOutput& out) {
  out.text << fmt::format("scene '{}': {}\nbackend {} on {}; {:.1f} s\n", r.scene, r.requirement, r.backend, r.device,
                          r.seconds);
  out.text << fmt::format("cost: {} ({})\n", r.cost_unit, r.cost_source);
  if (!r.cost_note.empty()) out.text << "note: " << r.cost_note << "\n";
  for (const std::string& u : r.unusable_formats) out.text << "not a candidate: " << u << "\n";
  if (!r.projection_facts.empty()) {
    out.text << fmt::format("projection matrix: {}\n", fmt::join(r.projection_facts, "\n  "));
  }
  if (!r.lens.empty()) out.text << "lens: " << r.lens << "\n";
  if (!r.population.empty()) out.text << "population: " << r.population << "\n";
  out.text << "\n";
  if (r.Met()) {
    out.text << fmt::format("choice: {} ({})\n", r.ranked.front().cell.Name(), r.ranked.front().reason);
    out.text << fmt::format("to store {}: {}\n", Info(r.ranked.front().cell.convention).name, r.api_recipe);
    std::vector<std::string> tied;
    for (const CandidateVerdict& v : r.ranked)
      if (v.rank == 1 && &v != &r.ranked.front()) tied.push_back(v.cell.Name());
    if (!tied.empty()) out.text << fmt::format("tied on cost with it: {}\n", fmt::join(tied, ", "));
    out.text << "\n";
  }
  for (const std::string& s : r.suggestions) out.text << s << "\n";
  if (!r.suggestions.empty()) out.text << "\n";
  if (!r.what_ifs.empty()) {
    out.text << "what if (each change measured as the scene is, its best candidate's upper figure):\n";
    for (const std::string& line : WhatIfLines(r)) out.text << "  " << line << "\n";
    out.text << "\n";
  }
  CandidateTable(r, r.ranked.size()).Print(out);
  out.text << fmt::format(
      "measured: at the requirement's level and depth, with the upper end of its 95% interval where it differs "
      "(the verdict uses that);\nfar end: measured in the last tenth of depth before the scene's far end, with the "
      "scene's cameras; model: the error model's prediction there (constant or depth: over eye depth, camera at the "
      "world origin; +camera: with what the scene's camera distance adds; docs/choosing.md), published only within "
      "0.3 bit of the far end's measurement, else withheld with how far off it was; NaN/Inf: findings inside the scene's ranges;\nheld back by: the part of the error that "
      "dominates (production, storage or shader), or what else "
      "fails it (interval: the measured value meets it, the upper end of its interval does not; symmetric lens: the "
      "variant's formula assumes a symmetric frustum and the scene's is off-centre);\nrank: '=' marks "
      "costs that tie; B/px: bytes per pixel the depth makes a frame move (the attachment written and read, or "
      "the attachment written and the linear target written and read; none under the static model);\nexit status 0 when a candidate meets the requirement, 1 when none "
      "does\n");
}

namespace {
nlohmann::json WhatIfsJson(const ChooseResult& r) {
  nlohmann::json list = nlohmann::json::array();
  for (const WhatIf& w : r.what_ifs) {
    list.push_back({{"change", w.change},
                    {"candidate", w.candidate.empty() ? nlohmann::json(nullptr) : nlohmann::json(w.candidate)},
                    {"figure", JsonNumber(w.figure)},
                    {"meets", w.meets}});
  }
  return list;
}
}  // namespace

nlohmann::json ChoiceToJson(const ChooseResult& r) {
  nlohmann::json ranked = nlohmann::json::array();
  for (const CandidateVerdict& v : r.ranked) {
    ranked.push_back({{"rank", v.rank},
                      {"tied", v.tied},
                      {"cell", v.cell.Name()},
                      {"variant", v.cell.variant_info().name},
                      {"convention", Info(v.cell.convention).name},
                      {"format", Info(v.cell.format).name},
                      {"samples", v.samples},
                      {"supported", v.supported},
                      {"measured", JsonNumber(v.measured)},
                      {"interval", {JsonNumber(v.interval.low), JsonNumber(v.interval.high)}},
                      {"measured_p999", JsonNumber(v.measured_p999)},
                      {"measured_max", JsonNumber(v.measured_max)},
                      {"far_end_measured", JsonNumber(v.far_end_measured)},
                      {"predicted_far_end", JsonNumber(v.predicted)},
                      {"prediction_off_bits", JsonNumber(v.prediction_off_bits)},
                      {"model", v.model},
                      {"camera_term", JsonNumber(v.camera_term)},
                      {"nonfinite", v.nonfinite},
                      {"dominant_cause", MetricName(v.dominant)},
                      {"meets", v.meets},
                      {"wrong_lens", v.wrong_lens},
                      {"too_close", v.too_close},
                      {"proven", JsonNumber(v.proven)},
                      {"unproven", v.unproven},
                      {"over_budget", v.over_budget},
                      {"cost", v.cost ? nlohmann::json{{"value", v.cost->value},
                                                       {"spread", v.cost->spread},
                                                       {"bytes_per_pixel", v.cost->bytes_per_pixel},
                                                       {"parts", v.cost->parts}}
                                      : nlohmann::json(nullptr)},
                      {"reason", v.reason}});
  }
  nlohmann::json model = nlohmann::json::array();
  for (const OperationCost& c : kOperationCosts)
    model.push_back({{"operation", c.operation}, {"weight", c.weight}, {"why", c.why}});
  return WithSchema(kChooseSchema,
                    {{"scene", r.scene},
                     {"requirement", r.requirement},
                     {"backend", r.backend},
                     {"device", r.device},
                     {"seconds", r.seconds},
                     {"met", r.Met()},
                     {"unusable_formats", r.unusable_formats},
                     {"choice", r.Met() ? nlohmann::json(r.ranked.front().cell.Name()) : nlohmann::json(nullptr)},
                     {"api_recipe", r.api_recipe},
                     {"lens", r.lens},
                     {"population", r.population},
                     {"projection_matrix", r.projection_facts},
                     {"cost",
                      {{"unit", r.cost_unit},
                       {"source", r.cost_source},
                       {"note", r.cost_note},
                       {"static_model", r.cost_unit == kStaticCostUnit ? model : nlohmann::json(nullptr)}}},
                     {"suggestions", r.suggestions},
                     {"what_ifs", WhatIfsJson(r)},
                     {"ranked", ranked}});
}

}  // namespace depthbench
