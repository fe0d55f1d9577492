#include "bench/judge.h"

#include <algorithm>
#include <cmath>

namespace depthbench {
namespace {

// The arithmetic of the judge, written once for the vectorized loop and for
// single samples. The output minus the camera position is exact in double
// (both are float32 values), so world-space magnitudes never enter the
// error; both reference points lie on the pixel's ray.
inline SampleErrors Errors(double px, double py, double pz, const glm::dvec3& camera, const glm::dvec3& ray,
                           double true_depth, double denoted_depth, double inverse_distance_sq) {
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

// What a sample is to one cell.
enum Kind : std::uint8_t { kJudged, kDegenerate, kOutside, kNan, kInf };

constexpr std::uint32_t kMaxRun = kSamplesPerFrame;  // a frame's samples at most

// Per-cell working set of one frame run, small enough to stay in L1.
struct RunScratch {
  std::array<double, kMaxRun> total, arith, absolute;
  std::array<std::int16_t, kMaxRun> total_bin, arith_bin, absolute_bin;
  std::array<std::uint8_t, kMaxRun> kind;
};

constexpr int kTotal = static_cast<int>(Metric::kTotal);
constexpr int kArith = static_cast<int>(Metric::kArith);
constexpr int kAbsolute = static_cast<int>(Metric::kAbsolute);

// Where one run of samples lives in the batch's arrays.
struct RunInputs {
  const float *x, *y, *z;                 // the cell's output components
  const double *ray_x, *ray_y, *ray_z;
  const double *true_depth, *denoted_depth, *inverse_distance_sq;
  const std::uint8_t* joint_band;
  const ReferenceStatus* status;
};

// Pass 1: errors, bins and kinds of a run of samples (no branches: the
// compiler vectorizes it).
void Measure(const RunInputs& in, const glm::dvec3& camera, std::uint32_t n, RunScratch& s) {
  for (std::uint32_t i = 0; i < n; ++i) {
    const SampleErrors e = Errors(in.x[i], in.y[i], in.z[i], camera, {in.ray_x[i], in.ray_y[i], in.ray_z[i]},
                                  in.true_depth[i], in.denoted_depth[i], in.inverse_distance_sq[i]);
    s.total[i] = e.total_sq;
    s.arith[i] = e.arith_sq;
    s.absolute[i] = e.absolute_sq;
    s.total_bin[i] = static_cast<std::int16_t>(DenseBinOfSquare(e.total_sq, kLowestOctave[kTotal]));
    s.arith_bin[i] = static_cast<std::int16_t>(DenseBinOfSquare(e.arith_sq, kLowestOctave[kArith]));
    s.absolute_bin[i] = static_cast<std::int16_t>(DenseBinOfSquare(e.absolute_sq, kLowestOctave[kAbsolute]));
  }
  // Kinds in a loop of their own, so that the one above stays vectorized.
  static_assert(static_cast<int>(ReferenceStatus::kJudged) == kJudged &&
                static_cast<int>(ReferenceStatus::kDegenerate) == kDegenerate &&
                static_cast<int>(ReferenceStatus::kOutside) == kOutside);
  for (std::uint32_t i = 0; i < n; ++i) {
    // A non-finite output: the sum of its components is NaN or infinite
    // exactly then (floats cannot overflow a double sum).
    const double sum = static_cast<double>(in.x[i]) + in.y[i] + in.z[i];
    const int nan = sum != sum;
    const int inf = (sum - sum) != 0.0 && !nan;
    const int status = static_cast<int>(in.status[i]);
    const int non_finite = status == kDegenerate ? 0 : nan | inf;
    s.kind[i] = static_cast<std::uint8_t>(non_finite ? kNan + inf : status);
  }
}

// Pass 2: counts and histograms.
void Record(const std::uint8_t* joint_band, std::uint64_t first_index, std::uint32_t n, const RunScratch& s,
            CellAccumulator& accumulator, CellAccumulator::Slot& distance) {
  for (std::uint32_t i = 0; i < n; ++i) {
    CellAccumulator::Slot& joint = accumulator.Joint(joint_band[i]);
    const std::uint64_t index = first_index + i;
    switch (s.kind[i]) {
      case kJudged:
        // Distance bands keep the total error only: what camera distance
        // does to a reconstruction shows there whole.
        joint.Record(Metric::kTotal, s.total_bin[i], s.total[i], index);
        joint.Record(Metric::kArith, s.arith_bin[i], s.arith[i], index);
        joint.Record(Metric::kAbsolute, s.absolute_bin[i], s.absolute[i], index);
        distance.Record(Metric::kTotal, s.total_bin[i], s.total[i], index);
        break;
      case kDegenerate:
        ++joint.degenerate;
        ++distance.degenerate;
        break;
      case kOutside:
        ++joint.outside;
        ++distance.outside;
        break;
      default:
        joint.RecordNonFinite(s.kind[i] == kNan, index);
        distance.RecordNonFinite(s.kind[i] == kNan, index);
        break;
    }
  }
}

}  // namespace

SampleErrors ErrorsOf(const ReferenceSample& r, const glm::dvec3& ray, const glm::dvec3& camera,
                      const float* position) {
  return Errors(position[0], position[1], position[2], camera, ray, r.true_depth, r.denoted_depth,
                r.inverse_distance_sq);
}

void JudgeSlot(const Batch& batch, std::uint32_t depth_slot, std::span<const JudgedCell> cells) {
  const std::uint32_t count = batch.count;
  const std::size_t offset = static_cast<std::size_t>(depth_slot) * count;
  const ReferenceArrays& ref = batch.reference;
  RunScratch scratch;
  // Frame by frame: the camera and the distance band are the frame's, and a
  // frame's reference stays in cache while every cell reads it.
  for (std::uint32_t begin = 0; begin < count;) {
    const std::uint32_t frame = batch.FrameOf(begin);
    const std::uint32_t end = std::min<std::uint32_t>(count, (frame + 1) * kSamplesPerFrame - batch.first_offset);
    const std::uint32_t n = end - begin;
    const glm::dvec3 camera = batch.frames[frame].camera_position;
    const std::size_t at = offset + begin;
    for (const JudgedCell& cell : cells) {
      const float* p = cell.positions.data();
      const RunInputs in{p + begin, p + count + begin, p + 2 * std::size_t{count} + begin,
                         batch.ray_x.data() + begin, batch.ray_y.data() + begin, batch.ray_z.data() + begin,
                         ref.true_depth.data() + at, ref.denoted_depth.data() + at,
                         ref.inverse_distance_sq.data() + at, ref.joint_band.data() + at, ref.status.data() + at};
      Measure(in, camera, n, scratch);
      Record(in.joint_band, batch.first_index + begin, n, scratch, *cell.accumulator,
             cell.accumulator->Distance(batch.distance_bands[frame]));
    }
    begin = end;
  }
  for (const JudgedCell& cell : cells) cell.accumulator->Count(count);
}

void RecordStorage(const Batch& batch, std::uint32_t depth_slot, CellAccumulator& accumulator) {
  const std::size_t offset = static_cast<std::size_t>(depth_slot) * batch.count;
  const ReferenceStatus* status = batch.reference.status.data() + offset;
  const std::uint8_t* joint_band = batch.reference.joint_band.data() + offset;
  const double* storage = batch.reference.storage_square.data() + offset;
  for (std::uint32_t i = 0; i < batch.count; ++i) {
    if (status[i] != ReferenceStatus::kJudged) continue;
    const std::uint64_t index = batch.first_index + i;
    accumulator.Joint(joint_band[i]).Record(Metric::kStorage, storage[i], index);
    accumulator.Distance(batch.distance_bands[batch.FrameOf(i)]).Record(Metric::kStorage, storage[i], index);
  }
  accumulator.Count(batch.count);
}

}  // namespace depthbench
