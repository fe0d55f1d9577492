#include "bench/pipeline/judge.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace depthbench {
namespace {

// The arithmetic of the judge, written once for one sample (Real = double)
// and for N SIMD lanes (Lanes<N>::Double), each lane computing exactly what
// the scalar form does. The output minus the camera position is exact in
// double (both are float32 values), so world-space magnitudes never enter
// the error; both reference points lie on the pixel's line, the offset
// (0 unless the frame is orthographic) plus eye depth times the ray.
template <class Real>
struct ErrorLanes {
  Real total_sq, arith_sq, absolute_sq;
};
template <class Real>
[[gnu::always_inline]] inline ErrorLanes<Real> Errors(Real px, Real py, Real pz, const glm::dvec3& camera, Real ox,
                                                      Real oy, Real oz, Real ray_x, Real ray_y, Real ray_z,
                                                      Real true_depth, Real denoted_depth, Real inverse_distance_sq) {
  const Real qx = (px - camera.x) - ox, qy = (py - camera.y) - oy, qz = (pz - camera.z) - oz;
  const Real tx = qx - true_depth * ray_x, ty = qy - true_depth * ray_y, tz = qz - true_depth * ray_z;
  const Real ax = qx - denoted_depth * ray_x, ay = qy - denoted_depth * ray_y, az = qz - denoted_depth * ray_z;
  const Real absolute_sq = tx * tx + ty * ty + tz * tz;
  return {absolute_sq * inverse_distance_sq, (ax * ax + ay * ay + az * az) * inverse_distance_sq, absolute_sq};
}

constexpr std::uint32_t kMaxRun = kSamplesPerFrame;  // a frame's samples at most
constexpr std::uint32_t kFramesPerGroup = 4;

// Everything JudgeSlot runs is inlined into it ([[gnu::always_inline]]), so
// that its two copies below are each compiled whole for their instruction
// set.

// Per-cell working set of one frame run, small enough to stay in L1.
struct RunScratch {
  std::array<double, kMaxRun> total, arith, absolute;
  // (64-bit, as the four-lane arithmetic makes them: narrowing costs shuffles.)
  std::array<std::int64_t, kMaxRun> total_bin, arith_bin, absolute_bin;
};

constexpr int kTotal = static_cast<int>(Metric::kTotal);
constexpr int kArith = static_cast<int>(Metric::kArith);
constexpr int kAbsolute = static_cast<int>(Metric::kAbsolute);

// Where one run of samples lives in the batch's arrays.
struct RunInputs {
  const float *x, *y, *z;  // the cell's output components
  const double *ray_x, *ray_y, *ray_z;
  const double *offset_x, *offset_y, *offset_z;  // null when the frame is perspective (offset 0)
  const double *true_depth, *denoted_depth, *inverse_distance_sq;
  const std::uint8_t* joint_band;
  const ReferenceStatus* status;
  const std::uint8_t* stored_holdable;
  const Coverage* coverage;
};

// Pass 1: errors and bins of a run of samples, N at a time; kOffset: the
// samples have offsets (an orthographic frame's).
template <int N, bool kOffset>
[[gnu::always_inline]] inline void Measure(const RunInputs& in, const glm::dvec3& camera, std::uint32_t n,
                                           RunScratch& s) {
  using D = typename Lanes<N>::Double;
  const auto store = [](auto* to, auto lanes) __attribute__((always_inline)) {
    std::memcpy(to, &lanes, sizeof(lanes));
  };
  const auto bins = [](D square, int metric) __attribute__((always_inline)) {
    return DenseBinsOfSquares<typename Lanes<N>::Int>(square, kLowestOctave[metric]);
  };
  std::uint32_t i = 0;
  for (; i + N <= n; i += N) {
    const auto wide = [&](const float* p) __attribute__((always_inline)) {
      typename Lanes<N>::Float f;
      std::memcpy(&f, p + i, sizeof(f));
      return __builtin_convertvector(f, D);
    };
    const auto load = [&](const double* p) __attribute__((always_inline)) {
      D d;
      std::memcpy(&d, p + i, sizeof(d));
      return d;
    };
    const D zero{};
    const ErrorLanes<D> e =
        Errors(wide(in.x), wide(in.y), wide(in.z), camera, kOffset ? load(in.offset_x) : zero,
               kOffset ? load(in.offset_y) : zero, kOffset ? load(in.offset_z) : zero, load(in.ray_x), load(in.ray_y),
               load(in.ray_z), load(in.true_depth), load(in.denoted_depth), load(in.inverse_distance_sq));
    store(&s.total[i], e.total_sq);
    store(&s.arith[i], e.arith_sq);
    store(&s.absolute[i], e.absolute_sq);
    store(&s.total_bin[i], bins(e.total_sq, kTotal));
    store(&s.arith_bin[i], bins(e.arith_sq, kArith));
    store(&s.absolute_bin[i], bins(e.absolute_sq, kAbsolute));
  }
  for (; i < n; ++i) {  // the tail of a batch that ends inside a frame
    const ErrorLanes<double> e = Errors<double>(
        in.x[i], in.y[i], in.z[i], camera, kOffset ? in.offset_x[i] : 0.0, kOffset ? in.offset_y[i] : 0.0,
        kOffset ? in.offset_z[i] : 0.0, in.ray_x[i], in.ray_y[i], in.ray_z[i], in.true_depth[i], in.denoted_depth[i],
        in.inverse_distance_sq[i]);
    s.total[i] = e.total_sq;
    s.arith[i] = e.arith_sq;
    s.absolute[i] = e.absolute_sq;
    s.total_bin[i] = DenseBinOfSquare(e.total_sq, kLowestOctave[kTotal]);
    s.arith_bin[i] = DenseBinOfSquare(e.arith_sq, kLowestOctave[kArith]);
    s.absolute_bin[i] = DenseBinOfSquare(e.absolute_sq, kLowestOctave[kAbsolute]);
  }
}

// Pass 2: counts and histograms. What a sample is to the cell follows from
// its reference's status and from its output, which is NaN when a component
// is NaN, and infinite when one is infinite (of either sign) and none is
// NaN. The absolute error's square tells those apart: it is a sum of
// squares (+inf and -inf components both give +inf, never NaN), of the
// output minus a point that is finite wherever the sample is not
// degenerate, and a finite float output cannot overflow it. A non-finite
// output is a finding only where the stored value denotes a point float32
// can hold; otherwise it is what any arithmetic returns.
//
// A sample of the natural distribution goes to its joint band, with every
// figure, and to its camera-distance band, with the total and the shader's
// part (what camera distance does shows there whole); a targeted pick to
// its coverage band alone (CellAccumulator::SlotsOf). Without distance
// bands (CellAccumulator::SkipDistanceBands) nothing goes to the
// discarded slot at all: kDistances is false.
template <bool kDistances>
[[gnu::always_inline]] inline void Record(const RunInputs& in, std::uint64_t first_index, std::uint32_t n,
                                          const RunScratch& s, CellAccumulator& accumulator,
                                          CellAccumulator::Slot& distance) {
  for (std::uint32_t i = 0; i < n; ++i) {
    const CellAccumulator::SampleSlots to = accumulator.SlotsOf(in.joint_band[i], in.coverage[i], distance);
    const std::uint64_t index = first_index + i;
    const double absolute_sq = s.absolute[i];
    const bool finite = absolute_sq < std::numeric_limits<double>::infinity();  // false for NaN
    const bool holdable = in.stored_holdable[i] != 0;
    if (in.status[i] == ReferenceStatus::kJudged && finite) {
      const int total_bin = static_cast<int>(s.total_bin[i]), arith_bin = static_cast<int>(s.arith_bin[i]);
      to.band.Record(Metric::kTotal, total_bin, s.total[i], index);
      to.band.Record(Metric::kAbsolute, static_cast<int>(s.absolute_bin[i]), absolute_sq, index);
      if constexpr (kDistances) to.distance.Record(Metric::kTotal, total_bin, s.total[i], index);
      // Against a stored value that denotes no holdable point, the shader
      // has no error to speak of.
      if (holdable) {
        to.band.Record(Metric::kArith, arith_bin, s.arith[i], index);
        if constexpr (kDistances) to.distance.Record(Metric::kArith, arith_bin, s.arith[i], index);
      }
    } else {
      const auto count = [&](CellAccumulator::Slot & slot) __attribute__((always_inline)) {
        if (in.status[i] == ReferenceStatus::kDegenerate) {
          ++slot.degenerate;
        } else if (in.status[i] == ReferenceStatus::kUndrawn) {
          ++slot.undrawn;
        } else if (in.status[i] == ReferenceStatus::kOutside) {
          // Outside the frustum or the range of depths asked for: not
          // judged, whatever the output (a texel beyond the far plane may
          // well reconstruct to infinity).
          ++slot.outside;
        } else if (!holdable) {
          ++slot.stored_nonfinite;
        } else {
          slot.RecordNonFinite(absolute_sq != absolute_sq, index);
        }
      };
      count(to.band);
      if constexpr (kDistances) count(to.distance);
    }
  }
}

// Calls run(frame, begin, end) for each frame's samples [begin, end) of
// the batch's samples [from, to), in order: the camera and the distance
// band are the frame's.
template <class Run>
[[gnu::always_inline]] inline void ForEachFrameRun(const Batch& batch, std::uint32_t from, std::uint32_t to, Run run) {
  for (std::uint32_t begin = from; begin < to;) {
    const std::uint32_t frame = batch.FrameOf(begin);
    const std::uint32_t end = std::min<std::uint32_t>(to, (frame + 1) * kSamplesPerFrame - batch.first_offset);
    run(frame, begin, end);
    begin = end;
  }
}
template <class Run>
[[gnu::always_inline]] inline void ForEachFrameRun(const Batch& batch, Run run) {
  ForEachFrameRun(batch, 0, batch.count, run);
}

}  // namespace

SampleErrors ErrorsOf(const ReferenceSample& r, const glm::dvec3& ray, const glm::dvec3& offset,
                      const glm::dvec3& camera, const float* position) {
  const ErrorLanes<double> e =
      Errors<double>(position[0], position[1], position[2], camera, offset.x, offset.y, offset.z, ray.x, ray.y, ray.z,
                     r.true_depth, r.denoted_depth, r.inverse_distance_sq);
  return {e.total_sq, e.arith_sq, e.absolute_sq};
}

namespace {

template <int N>
[[gnu::always_inline]] inline void JudgeSlotBody(const Batch& batch, std::uint32_t depth_slot,
                                                 std::span<const JudgedCell> cells) {
  const std::uint32_t count = batch.count;
  const std::size_t offset = static_cast<std::size_t>(depth_slot) * count;
  const ReferenceArrays& ref = batch.reference;
  const bool offsets = !batch.offset_x.empty();
  RunScratch scratch;
  // A few frames at a time: their reference stays in cache while every
  // cell reads it, and each cell records them in one go, while the lines
  // of its accumulator that they reach are in L1.
  for (std::uint32_t from = 0; from < count;) {
    const std::uint32_t to =
        std::min<std::uint32_t>(count, (batch.FrameOf(from) + kFramesPerGroup) * kSamplesPerFrame - batch.first_offset);
    for (const JudgedCell& cell : cells) {
      const float* p = cell.positions.data();
      ForEachFrameRun(
          batch, from,
          to, [&](std::uint32_t frame, std::uint32_t begin, std::uint32_t end) __attribute__((always_inline)) {
            const std::size_t at = offset + begin;
            const RunInputs in{p + begin,
                               p + count + begin,
                               p + 2 * std::size_t{count} + begin,
                               batch.ray_x.data() + begin,
                               batch.ray_y.data() + begin,
                               batch.ray_z.data() + begin,
                               offsets ? batch.offset_x.data() + begin : nullptr,
                               offsets ? batch.offset_y.data() + begin : nullptr,
                               offsets ? batch.offset_z.data() + begin : nullptr,
                               ref.true_depth.data() + at,
                               ref.denoted_depth.data() + at,
                               ref.inverse_distance_sq.data() + at,
                               ref.joint_band.data() + at,
                               ref.status.data() + at,
                               ref.stored_holdable.data() + at,
                               batch.samples.coverage.data() + begin};
            const std::uint32_t n = end - begin;
            if (offsets) {
              Measure<N, true>(in, batch.frames[frame].camera_position, n, scratch);
            } else {
              Measure<N, false>(in, batch.frames[frame].camera_position, n, scratch);
            }
            CellAccumulator& accumulator = *cell.accumulator;
            CellAccumulator::Slot& distance = accumulator.Distance(batch.distance_bands[frame]);
            if (accumulator.records_distances()) {
              Record<true>(in, batch.first_index + begin, n, scratch, accumulator, distance);
            } else {
              Record<false>(in, batch.first_index + begin, n, scratch, accumulator, distance);
            }
          });
    }
    from = to;
  }
  for (const JudgedCell& cell : cells) cell.accumulator->Count(count);
}

// The errors that belong to the encoding, not the variant: storage and
// production.
template <int N>
[[gnu::always_inline]] inline void RecordEncodingBody(const Batch& batch, std::uint32_t depth_slot,
                                                      CellAccumulator& accumulator) {
  const std::size_t offset = static_cast<std::size_t>(depth_slot) * batch.count;
  const ReferenceArrays& ref = batch.reference;
  const ReferenceStatus* status = ref.status.data() + offset;
  const std::uint8_t* joint_band = ref.joint_band.data() + offset;
  const Coverage* coverage = batch.samples.coverage.data();
  constexpr Metric kMetrics[] = {Metric::kStorage, Metric::kProduction};
  const double* squares_of[] = {ref.storage_square.data() + offset, ref.production_square.data() + offset};
  std::array<std::array<std::int64_t, kMaxRun>, 2> bins;
  ForEachFrameRun(
      batch, [&](std::uint32_t /*frame*/, std::uint32_t begin, std::uint32_t end) __attribute__((always_inline)) {
        // The bins N at a time (as the judge's Measure does), then the counts.
        for (int m = 0; m < 2; ++m) {
          const double* squares = squares_of[m];
          const int lowest = kLowestOctave[static_cast<int>(kMetrics[m])];
          std::uint32_t i = begin;
          for (; i + N <= end; i += N) {
            typename Lanes<N>::Double lanes;
            std::memcpy(&lanes, squares + i, sizeof(lanes));
            const auto slots = DenseBinsOfSquares<typename Lanes<N>::Int>(lanes, lowest);
            std::memcpy(&bins[m][i - begin], &slots, sizeof(slots));
          }
          for (; i < end; ++i) bins[m][i - begin] = DenseBinOfSquare(squares[i], lowest);
        }
        // Into the sample's band only: camera distance bands keep what the
        // variant's arithmetic does (the total and the shader's part), and
        // neither part here depends on where the camera stands.
        for (std::uint32_t i = begin; i < end; ++i) {
          if (status[i] != ReferenceStatus::kJudged) continue;
          const std::uint64_t index = batch.first_index + i;
          CellAccumulator::Slot& band = accumulator.BandOf(joint_band[i], coverage[i]);
          for (int m = 0; m < 2; ++m) {
            band.Record(kMetrics[m], static_cast<int>(bins[m][i - begin]), squares_of[m][i], index);
          }
        }
      });
  accumulator.Count(batch.count);
}

}  // namespace

void JudgeSlot(const Batch& batch, std::uint32_t depth_slot, std::span<const JudgedCell> cells, Isa isa) {
  RunWith(
      isa, [&](auto lanes)
               __attribute__((always_inline)) { JudgeSlotBody<decltype(lanes)::value>(batch, depth_slot, cells); });
}

void RecordEncodingErrors(const Batch& batch, std::uint32_t depth_slot, CellAccumulator& accumulator, Isa isa) {
  RunWith(
      isa, [&](auto lanes) __attribute__((always_inline)) {
        RecordEncodingBody<decltype(lanes)::value>(batch, depth_slot, accumulator);
      });
}

}  // namespace depthbench
