#include "bench/judge.h"

#include <cmath>

namespace depthbench {

// The arithmetic of the judge, written once for the vectorized loop and for
// single samples. The output minus the camera position is exact in double
// (both are float32 values), so world-space magnitudes never enter the
// error; both reference points lie on the pixel's ray.
static inline SampleErrors Errors(double px, double py, double pz, const glm::dvec3& camera,
                                  const glm::dvec3& ray, double true_depth, double denoted_depth,
                                  double inverse_distance_sq) {
  const double qx = px - camera.x, qy = py - camera.y, qz = pz - camera.z;
  const double tx = qx - true_depth * ray.x, ty = qy - true_depth * ray.y, tz = qz - true_depth * ray.z;
  const double ax = qx - denoted_depth * ray.x, ay = qy - denoted_depth * ray.y,
               az = qz - denoted_depth * ray.z;
  SampleErrors e;
  e.absolute_sq = tx * tx + ty * ty + tz * tz;
  e.total_sq = e.absolute_sq * inverse_distance_sq;
  e.arith_sq = (ax * ax + ay * ay + az * az) * inverse_distance_sq;
  return e;
}

SampleErrors ErrorsOf(const ReferenceSample& r, const glm::dvec3& ray, const glm::dvec3& camera,
                      const float* position) {
  return Errors(position[0], position[1], position[2], camera, ray, r.true_depth, r.denoted_depth,
                r.inverse_distance_sq);
}

void JudgeCell(const Batch& batch, const CellPlan& plan, std::span<const float> positions,
               CellAccumulator& accumulator, JudgeScratch& scratch) {
  const std::uint32_t count = batch.count;
  const ReferenceSample* reference = batch.reference.data() + static_cast<std::size_t>(plan.depth_slot) * count;
  const float* p = positions.data();
  for (auto* v : {&scratch.total, &scratch.arith, &scratch.absolute}) v->resize(count);
  for (auto* v : {&scratch.total_bin, &scratch.arith_bin, &scratch.absolute_bin}) v->resize(count);
  double* total = scratch.total.data();
  double* arith = scratch.arith.data();
  double* absolute = scratch.absolute.data();
  std::int16_t* total_bin = scratch.total_bin.data();
  std::int16_t* arith_bin = scratch.arith_bin.data();
  std::int16_t* absolute_bin = scratch.absolute_bin.data();
  constexpr int kTotal = static_cast<int>(Metric::kTotal);
  constexpr int kArith = static_cast<int>(Metric::kArith);
  constexpr int kAbsolute = static_cast<int>(Metric::kAbsolute);

  // Pass 1, frame by frame so the camera is loop-invariant: the errors of
  // every sample, with no branches (vectorizable).
  for (std::uint32_t begin = 0; begin < count;) {
    const std::uint32_t frame = batch.FrameOf(begin);
    const std::uint32_t end = std::min<std::uint32_t>(count, (frame + 1) * kSamplesPerFrame - batch.first_offset);
    const glm::dvec3 camera = batch.frames[frame].camera_position;
    for (std::uint32_t i = begin; i < end; ++i) {
      const ReferenceSample& r = reference[i];
      SampleErrors e = Errors(p[3 * i], p[3 * i + 1], p[3 * i + 2], camera, batch.rays[i], r.true_depth,
                              r.denoted_depth, r.inverse_distance_sq);
      total[i] = e.total_sq;
      arith[i] = e.arith_sq;
      absolute[i] = e.absolute_sq;
    }
    begin = end;
  }
  for (std::uint32_t i = 0; i < count; ++i) {
    total_bin[i] = static_cast<std::int16_t>(DenseBinOfSquare(total[i], kLowestOctave[kTotal]));
    arith_bin[i] = static_cast<std::int16_t>(DenseBinOfSquare(arith[i], kLowestOctave[kArith]));
    absolute_bin[i] = static_cast<std::int16_t>(DenseBinOfSquare(absolute[i], kLowestOctave[kAbsolute]));
  }

  // Pass 2: counts and histograms.
  for (std::uint32_t i = 0; i < count; ++i) {
    const ReferenceSample& r = reference[i];
    const std::uint64_t index = batch.first_index + i;
    CellAccumulator::Slot& joint = accumulator.Joint(r.joint_band);
    CellAccumulator::Slot& distance = accumulator.Distance(batch.distance_bands[batch.FrameOf(i)]);
    if (r.status == ReferenceStatus::kDegenerate) {
      ++joint.degenerate;
      ++distance.degenerate;
      continue;
    }
    // Non-finite output: the sum of its components is NaN or infinite
    // exactly then (floats cannot overflow a double sum).
    const double sum = static_cast<double>(p[3 * i]) + p[3 * i + 1] + p[3 * i + 2];
    if (!std::isfinite(sum)) {
      const bool is_nan = std::isnan(p[3 * i]) || std::isnan(p[3 * i + 1]) || std::isnan(p[3 * i + 2]);
      joint.RecordNonFinite(is_nan, index);
      distance.RecordNonFinite(is_nan, index);
      continue;
    }
    if (r.status == ReferenceStatus::kOutside) {
      ++joint.outside;
      ++distance.outside;
      continue;
    }
    ++joint.finite;
    ++distance.finite;
    for (CellAccumulator::Slot* slot : {&joint, &distance}) {
      slot->Record(Metric::kTotal, total_bin[i], total[i], index);
      slot->Record(Metric::kArith, arith_bin[i], arith[i], index);
      slot->Record(Metric::kAbsolute, absolute_bin[i], absolute[i], index);
    }
  }
  accumulator.Count(count);
}

void RecordStorage(const Batch& batch, std::uint32_t depth_slot, CellAccumulator& accumulator) {
  const std::size_t offset = static_cast<std::size_t>(depth_slot) * batch.count;
  const ReferenceSample* reference = batch.reference.data() + offset;
  const double* storage = batch.storage_squares.data() + offset;
  for (std::uint32_t i = 0; i < batch.count; ++i) {
    if (reference[i].status != ReferenceStatus::kJudged) continue;
    const std::uint64_t index = batch.first_index + i;
    accumulator.Joint(reference[i].joint_band).Record(Metric::kStorage, storage[i], index);
    accumulator.Distance(batch.distance_bands[batch.FrameOf(i)]).Record(Metric::kStorage, storage[i], index);
  }
  accumulator.Count(batch.count);
}

}  // namespace depthbench
