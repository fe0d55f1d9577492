#include "bench/fuzz/case_check.h"

#include <cfloat>
#include <cmath>

#include "bench/fuzz/fuzz_case.h"
#include "bench/pipeline/judge.h"

namespace depthbench {

const char* FindingKindName(FindingKind kind) {
  switch (kind) {
    case FindingKind::kNaN: return "nan";
    case FindingKind::kInf: return "inf";
    case FindingKind::kBeyondBound: return "beyond_bound";
    case FindingKind::kBeyondProven: return "beyond_proven_bound";
  }
  return "?";
}

double ArithmeticBound(const Cell& cell, const Frame& frame, const f32::DepthParams& depth, float fetched,
                       double distance_from_camera) {
  const ConventionInfo& convention = Info(cell.convention);
  double depth_condition = 1.0;
  if (Info(cell.format).stores == DepthInput::kHardware) {
    const bool minus_one = (convention.bits & f32::DB_CONVENTION_CLIP_MINUS_ONE) != 0u;
    const double d = fetched;
    const double ndc = minus_one ? 2.0 * d - 1.0 : d;
    const double a = depth.coefficients.x;
    const double gap = std::abs(ndc - a);
    depth_condition = (std::abs(ndc) + std::abs(a) + (minus_one ? 2.0 : 0.0)) / gap + 1.0;
  }
  const double ray_condition = 1.0 + 2.0 * frame.tan_half_fov_y * (frame.aspect + 1.0);
  const double world_condition = 1.0 + frame.camera_distance() / distance_from_camera;
  // inverse_vp carries the camera's translation through the homogeneous
  // divide: the rounding of w scales the whole translated point, so the
  // depth and world conditions multiply instead of adding.
  const double conditions = cell.variant == Variant::kInverseVp ? depth_condition * world_condition + ray_condition
                                                                : depth_condition + ray_condition + world_condition;
  return kRoundings * 0x1.0p-24 * conditions;
}

CaseChecker::CaseChecker(std::vector<Cell> cells, std::vector<Backend*> backends, unsigned threads)
    : cells_(std::move(cells)),
      backends_(std::move(backends)),
      layout_(MakeRunLayout(cells_)),
      pool_(std::make_unique<ThreadPool>(threads)) {}

Expected<CaseChecker> CaseChecker::Make(std::vector<Cell> cells, std::vector<Backend*> backends, unsigned threads) {
  if (cells.empty()) return InvalidArgument("no cell to check");
  if (backends.empty()) return InvalidArgument("no backend to check on");
  CaseChecker checker(std::move(cells), std::move(backends), threads);
  for (Backend* b : checker.backends_) DB_RETURN_IF_ERROR(b->Prepare(checker.layout_.cells));
  return checker;
}

Status CaseChecker::Evaluate(const SampleSource& source, std::uint64_t first, std::uint32_t count) {
  const BatchBuilder builder(source, layout_.encodings);
  builder.Build(first, count, batch_, *pool_);
  judgements_.assign(cells_.size() * backends_.size() * count, Judgement{});
  std::vector<std::uint32_t> every(cells_.size());
  for (std::uint32_t c = 0; c < every.size(); ++c) every[c] = c;
  for (std::size_t b = 0; b < backends_.size(); ++b) {
    DB_ASSIGN_OR_RETURN(std::span<const float> out, backends_[b]->Run(batch_, every, scratch_));
    pool_->ParallelFor(
        cells_.size() * count,
        [&](std::size_t begin, std::size_t end, unsigned) {
          for (std::size_t job = begin; job < end; ++job) {
            const std::size_t c = job / count;
            const auto i = static_cast<std::uint32_t>(job % count);
            const CellPlan& plan = layout_.cells[c];
            const std::uint32_t f = batch_.FrameOf(i);
            const Frame& frame = batch_.frames[f];
            Judgement& j = judgements_[(c * backends_.size() + b) * count + i];
            const std::size_t at = static_cast<std::size_t>(plan.depth_slot) * count + i;
            const ReferenceSample r = batch_.reference.Get(at);
            if (!CellRunsOn(plan.cell, frame) || r.status == ReferenceStatus::kDegenerate) continue;
            j.checked = true;
            j.judged = r.status == ReferenceStatus::kJudged;
            if (!proven_.empty()) j.proven = proven_[c * backends_.size() + b];
            float p[3];
            for (int k = 0; k < 3; ++k) p[k] = out[(c * 3 + k) * count + i];
            j.nan = std::isnan(p[0]) || std::isnan(p[1]) || std::isnan(p[2]);
            j.inf = !j.nan && !(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]));
            const glm::dvec3 ray = batch_.Ray(i);
            const double distance = r.denoted_depth * glm::length(ray);
            // The judge measures errors relative to the true point's
            // distance; the bound is about the point the texel denotes.
            j.bound = ArithmeticBound(plan.cell, frame,
                                      batch_.depth_params[f * kHardwareConventionCount + plan.convention_slot],
                                      batch_.depths[at], distance) *
                      (r.denoted_depth / r.true_depth);
            if (!r.stored_holdable) {
              // The texel denotes a point float32 cannot hold (infinity,
              // the camera, beyond the float range: the pipeline or the
              // storage put it there): no arithmetic returns it finitely,
              // and rotating a direction scaled to infinity gives Inf or,
              // where a matrix entry is 0, NaN (0 * Inf). Neither is the
              // shader's fault; the sweep counts these as expected.
              j.checked = j.judged = false;
              continue;
            }
            if (j.nan || j.inf) {
              j.total = j.arith = NAN;
              continue;
            }
            const SampleErrors e = ErrorsOf(r, ray, batch_.Offset(i), frame.camera_position, p);
            j.total = std::sqrt(e.total_sq);
            j.arith = std::sqrt(e.arith_sq);
          }
        },
        256);
    if (sample_bound_) HoldWorstAgainstSampleBounds(b, count);
  }
  return Status::Ok();
}

void CaseChecker::HoldWorstAgainstSampleBounds(std::size_t b, std::uint32_t count) {
  for (std::size_t c = 0; c < cells_.size(); ++c) {
    const CellPlan& plan = layout_.cells[c];
    Judgement* judged = &judgements_[(c * backends_.size() + b) * count];
    // The worst by error, and by error over the condition-based bound
    // (the sample whose inputs make it worst for its conditioning).
    std::uint32_t worst[2] = {count, count};
    for (std::uint32_t i = 0; i < count; ++i) {
      const Judgement& j = judged[i];
      if (!j.judged || j.nan || j.inf) continue;
      if (worst[0] == count || j.arith > judged[worst[0]].arith) worst[0] = i;
      if (worst[1] == count || j.arith * judged[worst[1]].bound > judged[worst[1]].arith * j.bound) worst[1] = i;
    }
    for (std::uint32_t i : worst) {
      if (i == count) continue;
      const std::size_t at = static_cast<std::size_t>(plan.depth_slot) * count + i;
      const ReferenceSample r = batch_.reference.Get(at);
      const std::uint32_t pixel = batch_.pixels[i];
      const double bound = sample_bound_(cells_[c], backends_[b]->name(), batch_.frames[batch_.FrameOf(i)],
                                         pixel & 0xFFFFu, pixel >> 16, batch_.depths[at]);
      // The judge measures against the true point's distance.
      const double held = bound * (r.denoted_depth / r.true_depth);
      judged[i].proven = std::min(judged[i].proven, held);
      ++reach_.held;
      // A bound of the whole distance or more (24 bits) says nothing a
      // sample could come close to in a telling way.
      if (!(held < 1.0)) continue;
      ++reach_.below_24_bits;
      if (judged[i].arith >= 0.5 * held) ++reach_.within_one_bit;
      if (judged[i].arith / held > reach_.closest) {
        reach_.closest = judged[i].arith / held;
        reach_.closest_cell = cells_[c].Name() + " on " + backends_[b]->name();
      }
    }
  }
}

}  // namespace depthbench
