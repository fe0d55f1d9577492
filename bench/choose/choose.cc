#include "bench/choose/choose.h"
#include "bench/base/resources.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>

#include <fmt/format.h>

#include "bench/backends/vulkan/shader_compiler.h"
#include "bench/base/text_table.h"
#include "bench/speed/instruction_mix.h"
#include "bench/speed/speed_results.h"
#include "bench/sweep/sweep.h"

namespace depthbench {
namespace {

std::uint32_t ArithmeticLanes(const InstructionMix& m) {
  return m.fdiv.lanes + m.fmul.lanes + m.fadd.lanes + m.fneg.lanes + m.fma.lanes + m.dot.lanes + m.matrix_vector.lanes +
         m.matrix_matrix.lanes + m.extended.lanes;
}

// The requirement's unit, from a band's statistics.
double InUnit(const Requirement& req, const BandStats& band, Level level) {
  switch (req.kind) {
    case Requirement::Kind::kAbsolute: return band[Metric::kAbsolute].AtLevel(level, Metric::kAbsolute);
    case Requirement::Kind::kRelative: return band[Metric::kTotal].AtLevel(level, Metric::kTotal);
    case Requirement::Kind::kBitsLost: return BitsLost(band[Metric::kTotal].AtLevel(level, Metric::kTotal));
  }
  return 0.0;
}

std::string InUnitText(const Requirement& req, double v) {
  switch (req.kind) {
    case Requirement::Kind::kAbsolute: return fmt::format("{:.3g}", v);
    case Requirement::Kind::kRelative: return fmt::format("{:.3g}", v);
    case Requirement::Kind::kBitsLost: return fmt::format("{:.1f} bits", v);
  }
  return "";
}

double DepthLimit(const Domain& d) {
  if (d.eye_depth) return d.eye_depth->max;
  return d.finite_far ? d.far->max : d.near.max * Domain::kInfiniteDepthSpan;
}

// The error model over eye depth inside the scene (its far/near ratio is
// fixed, so only depth can matter) and its prediction at the far end.
std::pair<double, std::string> PredictAtFarEnd(const Scene& scene, const CellResult& cell, Level level) {
  const Requirement& req = scene.requirement;
  const double near = scene.domain.near.min, far_end = DepthLimit(scene.domain);
  const double lowest = scene.domain.eye_depth ? scene.domain.eye_depth->min : near;
  std::vector<FitPoint> points;
  for (int d = 0; d < kDepthBands; ++d) {
    const BandStats band = cell.stats.ForDepth(d);
    if (band.finite < 100) continue;
    const double q = band[Metric::kTotal].AtLevel(level, Metric::kTotal);
    if (!(q > 0.0) || !std::isfinite(q)) continue;
    const double lo = std::max(lowest, near * DepthBandLow(d)), hi = std::min(far_end, near * DepthBandLow(d) * 10.0);
    if (!(hi > lo)) continue;
    points.push_back({0.0, 0.5 * (std::log2(lo / near) + std::log2(hi / near)), std::log2(q) + 24.0});
  }
  const ModelKind candidates[] = {ModelKind::kConstant, ModelKind::kDepth};
  const std::vector<FittedModel> ranked = FitAndRank(points, candidates);
  if (ranked.empty()) return {std::nan(""), "none (too few depth bands)"};
  const double b = ranked.front().Predict(0.0, std::log2(far_end / near));
  const double relative = std::ldexp(1.0, -24) * std::exp2(b);
  double value = relative;
  if (req.kind == Requirement::Kind::kAbsolute) value = relative * far_end;
  if (req.kind == Requirement::Kind::kBitsLost) value = std::max(0.0, b);
  return {value, Info(ranked.front().kind).name};
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

Expected<CostLookup> StaticCostLookup(const std::string& shader_dir) {
  std::filesystem::path dir = shader_dir;
  if (dir.empty()) DB_RETURN_IF_ERROR(StoreInto(DataPath("shaders"), dir));
  std::map<Variant, CandidateCost> by_variant;
  for (const VariantInfo& v : AllVariants()) {
    DB_ASSIGN_OR_RETURN(std::vector<std::uint32_t> spirv, CompileComputeShader(dir / (std::string(v.name) + ".comp")));
    DB_ASSIGN_OR_RETURN(InstructionMix mix, CountInstructionMix(spirv, std::string(v.name) + "_world_position"));
    by_variant[v.id] = {static_cast<double>(ArithmeticLanes(mix)), "SPIR-V arithmetic lanes",
                        "the compiled shader's instruction mix"};
  }
  return CostLookup(
      [by_variant](const Cell& cell) -> std::optional<CandidateCost> { return by_variant.at(cell.variant); });
}

Expected<CostLookup> SpeedCostLookup(const std::string& speed_file, CostLookup fallback) {
  DB_ASSIGN_OR_RETURN(SpeedResults speed, ReadSpeedResults(speed_file));
  std::map<Cell, CandidateCost> measured;
  for (const TradeFront& front : speed.trade) {
    for (const TradePoint& p : front.points) {
      if (!(p.gpu_ns_per_reconstruction > 0.0)) continue;
      measured[Cell{p.variant, front.convention, front.format}] = {
          p.gpu_ns_per_reconstruction, "ns per reconstruction on " + speed.run.device.name, speed_file};
    }
  }
  return CostLookup([measured, fallback](const Cell& cell) -> std::optional<CandidateCost> {
    auto it = measured.find(cell);
    if (it != measured.end()) return it->second;
    return fallback ? fallback(cell) : std::nullopt;
  });
}

Expected<ChooseResult> Choose(const Scene& scene, Backend& backend, const CostLookup& costs,
                              const ChooseOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  const Requirement& req = scene.requirement;
  const std::vector<Cell> cells = scene.Candidates();
  Backend* backends[] = {&backend};

  // The whole scene, and (for a requirement at a depth) that depth.
  SweepOptions whole;
  whole.seed = options.seed;
  whole.samples = options.samples;
  whole.domain = scene.domain;
  whole.cells = cells;
  DB_ASSIGN_OR_RETURN(Results scene_results, RunSweep(whole, backends));
  Results depth_results;
  const Results* judged = &scene_results;
  if (req.at_depth) {
    SweepOptions at = whole;
    const double lowest = scene.domain.eye_depth ? scene.domain.eye_depth->min : scene.domain.near.min;
    // The last tenth of depth before the requirement's depth.
    at.domain.eye_depth = Range{std::max(lowest, *req.at_depth / 1.1), *req.at_depth};
    DB_ASSIGN_OR_RETURN(depth_results, RunSweep(at, backends));
    judged = &depth_results;
  }

  ChooseResult result;
  result.scene = scene.name;
  result.requirement = req.Describe();
  result.backend = backend.name();
  result.device = backend.device().name;
  for (const Cell& cell : cells) {
    const CellResult* at_depth = judged->Find(cell, backend.name());
    const CellResult* in_scene = scene_results.Find(cell, backend.name());
    if (at_depth == nullptr || in_scene == nullptr) continue;
    const BandStats band = at_depth->stats.All();
    const BandStats whole_band = in_scene->stats.All();
    CandidateVerdict v;
    v.cell = cell;
    v.measured_p999 = InUnit(req, band, Level::kP999);
    v.measured_max = InUnit(req, band, Level::kMax);
    v.measured = req.level == Level::kMax ? v.measured_max : v.measured_p999;
    std::tie(v.predicted, v.model) = PredictAtFarEnd(scene, *in_scene, req.level);
    v.nonfinite = band.nan + band.inf + whole_band.nan + whole_band.inf;
    double largest = -1.0;
    for (Metric cause : {Metric::kProduction, Metric::kStorage, Metric::kArith}) {
      const double p999 = band[cause].AtLevel(Level::kP999, cause);
      if (p999 > largest) {
        largest = p999;
        v.dominant = cause;
      }
    }
    v.meets = v.measured <= req.value && v.nonfinite == 0;
    v.cost = costs ? costs(cell) : std::nullopt;
    v.over_budget = scene.max_cost && v.cost && v.cost->value > *scene.max_cost;
    result.ranked.push_back(v);
  }

  // Meeting and affordable, cheapest first; then meeting but too costly;
  // then failing, closest first. Ties go to the more precise.
  auto group = [](const CandidateVerdict& v) { return !v.meets ? 2 : v.over_budget ? 1 : 0; };
  auto cost_of = [](const CandidateVerdict& v) { return v.cost ? v.cost->value : INFINITY; };
  std::stable_sort(result.ranked.begin(), result.ranked.end(),
                   [&](const CandidateVerdict& a, const CandidateVerdict& b) {
                     if (group(a) != group(b)) return group(a) < group(b);
                     if (group(a) < 2 && cost_of(a) != cost_of(b)) return cost_of(a) < cost_of(b);
                     if (a.nonfinite != b.nonfinite) return a.nonfinite < b.nonfinite;
                     return a.measured < b.measured;
                   });

  const double limit = req.value;
  const CandidateVerdict* cheapest =
      result.ranked.empty() || !result.ranked.front().meets ? nullptr : &result.ranked.front();
  for (CandidateVerdict& v : result.ranked) {
    const std::string measured = InUnitText(req, v.measured);
    const std::string cost =
        v.cost ? fmt::format("{:.3g} {}", v.cost->value, v.cost->unit) : std::string("unknown cost");
    if (v.meets && &v == cheapest) {
      v.reason = fmt::format("the cheapest that meets it: {} against {} ({:.1f}x margin), {}", measured,
                             InUnitText(req, limit), limit / std::max(v.measured, 1e-300), cost);
    } else if (v.meets && v.over_budget) {
      v.reason = fmt::format("meets it ({}), but {} is over the budget of {:g}", measured, cost, *scene.max_cost);
    } else if (v.meets) {
      v.reason = fmt::format("meets it ({}), but costs more: {}", measured, cost);
    } else if (v.nonfinite > 0) {
      v.reason = fmt::format("fails: {} NaN or Inf outputs inside the scene", v.nonfinite);
    } else {
      v.reason = fmt::format("fails: {}, {:.3g}x the limit; {}", measured, v.measured / limit, CauseText(v.dominant));
    }
  }

  if (cheapest == nullptr && !result.ranked.empty()) {
    const CandidateVerdict& closest = result.ranked.front();
    result.suggestions.push_back(fmt::format("nothing meets {}; the closest is {} at {} ({:.3g}x the limit)",
                                             req.Describe(), closest.cell.Name(), InUnitText(req, closest.measured),
                                             closest.measured / limit));
    const bool depth = closest.dominant != Metric::kArith;  // production or storage: the depth buffer's own
    const bool reversed_float =
        closest.cell.format == Format::kD32Sfloat && (Info(closest.cell.convention).bits & 1u) != 0u;
    if (depth && !reversed_float) {
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
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

void PrintChoice(const ChooseResult& r, std::ostream& out) {
  using Align = TextTable::Align;
  out << fmt::format("scene '{}': {}\nbackend {} on {}; {:.1f} s\n\n", r.scene, r.requirement, r.backend, r.device,
                     r.seconds);
  if (!r.ranked.empty() && r.ranked.front().meets) {
    out << fmt::format("choice: {} ({})\n\n", r.ranked.front().cell.Name(), r.ranked.front().reason);
  }
  for (const std::string& s : r.suggestions) out << s << "\n";
  if (!r.suggestions.empty()) out << "\n";
  TextTable table({{"rank"},
                   {"candidate", Align::kLeft},
                   {"p99.9"},
                   {"max"},
                   {"far end (model)"},
                   {"NaN/Inf"},
                   {"meets"},
                   {"cost"},
                   {"why", Align::kLeft}});
  int rank = 0;
  for (const CandidateVerdict& v : r.ranked) {
    table.AddRow({std::to_string(++rank), v.cell.Name(), fmt::format("{:.3g}", v.measured_p999),
                  fmt::format("{:.3g}", v.measured_max), fmt::format("{:.3g} ({})", v.predicted, v.model),
                  std::to_string(v.nonfinite), v.meets ? (v.over_budget ? "over budget" : "yes") : "no",
                  v.cost ? fmt::format("{:.3g}", v.cost->value) : "-", v.reason});
  }
  table.Print(out);
  if (!r.ranked.empty() && r.ranked.front().cost) out << "cost: " << r.ranked.front().cost->unit << "\n";
}

nlohmann::json ChoiceToJson(const ChooseResult& r) {
  nlohmann::json ranked = nlohmann::json::array();
  for (const CandidateVerdict& v : r.ranked) {
    ranked.push_back(
        {{"cell", v.cell.Name()},
         {"variant", Info(v.cell.variant).name},
         {"convention", Info(v.cell.convention).name},
         {"format", Info(v.cell.format).name},
         {"measured_p999", JsonNumber(v.measured_p999)},
         {"measured_max", JsonNumber(v.measured_max)},
         {"predicted_far_end", JsonNumber(v.predicted)},
         {"model", v.model},
         {"nonfinite", v.nonfinite},
         {"dominant_cause", MetricName(v.dominant)},
         {"meets", v.meets},
         {"over_budget", v.over_budget},
         {"cost", v.cost ? nlohmann::json{{"value", v.cost->value}, {"unit", v.cost->unit}, {"source", v.cost->source}}
                         : nlohmann::json(nullptr)},
         {"reason", v.reason}});
  }
  return WithSchema(kChooseSchema, {{"scene", r.scene},
                                    {"requirement", r.requirement},
                                    {"backend", r.backend},
                                    {"device", r.device},
                                    {"seconds", r.seconds},
                                    {"choice", r.ranked.empty() || !r.ranked.front().meets
                                                   ? nlohmann::json(nullptr)
                                                   : nlohmann::json(r.ranked.front().cell.Name())},
                                    {"suggestions", r.suggestions},
                                    {"ranked", ranked}});
}

}  // namespace depthbench
