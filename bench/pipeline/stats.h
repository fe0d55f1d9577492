// Stats: streaming, exactly mergeable error statistics.
//
// Every error value x > 0 falls into a quarter-octave bin k = floor(4 log2 x),
// decided exactly from the bits of x^2 (no logarithm is evaluated). Bins
// are plain counts, so statistics of shards, batches and threads add up to
// exactly the statistics of the whole; the maximum is kept exactly, with the
// index of the sample that reached it (ties: the smallest index).
// Quantiles are read from the bins, interpolated within a bin.
//
// Five metrics per sample (relative ones are over the distance from the
// camera to the true point; "produced" is the point the pipeline's float
// denotes, "denoted" the point the fetched texel denotes, both under the
// pipeline's own mapping, encode.h):
//   total       |p - truth| / distance        what the engine gets
//   arith       |p - denoted| / distance      the shader's part: its float32
//                                             arithmetic on the value it
//                                             fetched and the constants it got
//   storage     |denoted - produced| / dist.  the format's rounding and fetch
//   production  |produced - truth| / distance the pipeline's float32 depth
//   absolute    |p - truth|                   in world units
// Bits lost = min(24, max(0, log2(relative error / 2^-24))).
#pragma once

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bench/base/simd.h"
#include "bench/base/status.h"
#include "bench/pipeline/bands.h"

namespace depthbench {

enum class Metric : int { kTotal = 0, kArith = 1, kStorage = 2, kProduction = 3, kAbsolute = 4 };
inline constexpr int kMetricCount = 5;
const char* MetricName(Metric m);

inline constexpr int kBinsPerOctave = 4;
// Bits-lost figures closer than this are the same accuracy: errors are kept
// in quarter-octave bins, so a quantile is known to a quarter of a bit and
// finer differences are interpolation. Ties between variants, the gate's
// p99.9 tolerance and the choice's resolution all use it.
inline constexpr double kResolvedBits = 1.0 / kBinsPerOctave;
inline constexpr int kOctavesKept = 64;
inline constexpr int kBinsKept = kBinsPerOctave * kOctavesKept;
// Lowest kept octave per metric: relative errors from 2^-56 (32 bits below
// float32's rounding, where every bit-lost figure is 0 anyway) up to 2^8;
// absolute errors from 2^-48 to 2^16 world units. Values outside fall into
// an underflow or overflow bin; exact zeros into the underflow bin.
inline constexpr std::array<int, kMetricCount> kLowestOctave = {-56, -56, -56, -56, -48};

// The bin arithmetic below is written once for one value (Int = int64_t,
// Real = double) and for four SIMD lanes (Int4, Double4): GCC's vector
// extensions give comparisons and ?: lane by lane, so each lane computes
// exactly what the scalar form does.

// floor(4 * log2(sqrt(q))) for q > 0 finite, from q's bits: the exponent
// gives whole octaves of q (half octaves of sqrt(q)); the significand is
// compared with sqrt(2)'s, which splits an octave of q in two.
template <class Int, class Real>
Int QuarterOctavesOfSqrt(Real q) {
  constexpr std::int64_t kSqrt2Fraction = 0x6A09E667F3BCDll;  // ceil(frac(sqrt 2) * 2^52)
  const Int bits = std::bit_cast<Int>(q);
  const Int exponent = (bits >> 52) - 1023;
  const Int upper = (bits & 0xFFFFFFFFFFFFFll) >= kSqrt2Fraction ? Int{} + 1 : Int{};
  return 2 * exponent + upper;
}
inline int QuarterOctaveOfSqrt(double q) { return static_cast<int>(QuarterOctavesOfSqrt<std::int64_t>(q)); }

// Bin slot of a squared error value in a dense histogram: 0 underflow
// (including 0 and subnormal squares), 1..kBinsKept kept bins, kBinsKept + 1
// overflow.
// Branch-free, so that loops over samples vectorize; NaN lands in the
// underflow bin (callers keep NaN outputs out).
template <class Int, class Real>
Int DenseBinsOfSquares(Real q, int lowest_octave) {
  Int slot = QuarterOctavesOfSqrt<Int>(q) - lowest_octave * kBinsPerOctave + 1;
  slot = slot < 0 ? Int{} : slot;
  slot = slot > kBinsKept + 1 ? Int{} + (kBinsKept + 1) : slot;
  return q >= 0x1p-1022 ? slot : Int{};
}
inline int DenseBinOfSquare(double q, int lowest_octave) {
  return static_cast<int>(DenseBinsOfSquares<std::int64_t>(q, lowest_octave));
}
inline constexpr int kDenseBins = kBinsKept + 2;

// The levels reported and modelled: three quantiles and the maximum.
enum class Level { kP50, kP99, kP999, kMax };
inline constexpr Level kAllLevels[] = {Level::kP50, Level::kP99, Level::kP999, Level::kMax};
const char* LevelName(Level level);
Expected<Level> ParseLevel(const std::string& name);
// The quantile a level stands for (1 for the maximum).
double LevelQuantile(Level level);
// Samples a band needs for a quantile at this level to mean something: a
// few beyond it, 4 / (1 - q).
std::uint64_t MinimumSamples(Level level);

// A quantile's 95% sampling interval.
struct Interval {
  double low = 0.0, high = 0.0;
};

// Statistics of one metric in one band: sparse bins keyed by dense slot.
struct MetricStats {
  std::map<int, std::uint64_t> bins;  // dense slot -> count
  // The largest value's square, exactly as recorded: squares are what the
  // judge compares, and the square root would merge values that differ.
  double max_square = 0.0;
  double max() const { return std::sqrt(max_square); }
  std::uint64_t worst_index = std::numeric_limits<std::uint64_t>::max();

  std::uint64_t Count() const;
  void Merge(const MetricStats& other);
  void Merge(MetricStats&& other);  // takes other's bins whole where this has none
  // The q-quantile (q in [0, 1]) of the metric's value; 0 when empty.
  // Underflow reads as the lowest kept edge (or the max, when smaller): an
  // upper bound, which BelowRange tells; overflow reads as the exact max.
  double Quantile(double q, int lowest_octave) const;
  // Whether the q-quantile lies below the kept bins (the absolute error of
  // a domain with a near plane far below 1e-6, say): Quantile is then only
  // an upper bound.
  bool BelowRange(double q) const;
  // The value at a level (a quantile, or the maximum) of metric `metric`.
  double AtLevel(Level level, Metric metric) const;
  // The 95% interval of the q-quantile: the values at the order-statistic
  // ranks n q -/+ 1.96 sqrt(n q (1 - q)) (the normal approximation of the
  // binomial count of samples below it), read from the bins as Quantile
  // reads them. The maximum's interval is the maximum itself.
  Interval LevelInterval(Level level, Metric metric) const;
  friend bool operator==(const MetricStats&, const MetricStats&) = default;

 private:
  void MergeBins(const std::map<int, std::uint64_t>& other);
  void MergeMax(const MetricStats& other);
};

// Statistics of one band of one cell.
struct BandStats {
  std::uint64_t finite = 0;  // samples with a finite output and a finite reference
  // Non-finite outputs by cause. A finding: exact arithmetic on the
  // shader's inputs is finite, the output is not (NaN when a component is
  // NaN, Inf when one is infinite and none NaN).
  std::uint64_t nan = 0;
  std::uint64_t inf = 0;
  // Expected: the stored value itself denotes infinity, the camera, or a
  // point float32 cannot hold, so no arithmetic could return it finitely.
  std::uint64_t stored_nonfinite = 0;
  std::uint64_t degenerate = 0;  // reference at the camera or at infinity: not judged
  std::uint64_t outside = 0;     // outside the frustum or the depths asked for: not judged
  // The raster form's rasterizer left the sample's texel unwritten (its
  // triangle was clipped or failed the depth test): what the texel holds is
  // the clear value, not a depth of the sample's, so it is not judged.
  std::uint64_t undrawn = 0;
  std::uint64_t first_nonfinite_index = std::numeric_limits<std::uint64_t>::max();
  std::array<MetricStats, kMetricCount> metrics;

  void Merge(const BandStats& other);
  void Merge(BandStats&& other);
  std::uint64_t judged() const { return finite + nan + inf; }
  const MetricStats& operator[](Metric m) const { return metrics[static_cast<int>(m)]; }
  friend bool operator==(const BandStats&, const BandStats&) = default;

 private:
  void MergeCounts(const BandStats& other);
};

// The quantile summary a table row shows.
struct Summary {
  double p50 = 0, p99 = 0, p999 = 0, max = 0;
  Interval p999_interval;
  bool p999_supported = false;    // enough samples for a p99.9 (MinimumSamples)
  bool p999_below_range = false;  // p999 is an upper bound: the quantile lies below the histogram's bins
  std::uint64_t worst_index = 0;
};
Summary Summarize(const BandStats& band, Metric metric);
// Bits lost of a relative error: log2(x / 2^-24), from 0 (as good as
// float32 rounding allows) to 24 (nothing left: an error as large as the
// distance, or larger).
inline constexpr double kAllBitsLost = 24.0;
double BitsLost(double relative_error);

// All statistics of one cell on one backend.
struct CellStats {
  std::map<int, BandStats> joint;     // JointBand(ratio, depth) -> stats
  std::map<int, BandStats> distance;  // DistanceBand -> stats
  std::map<int, BandStats> coverage;  // CoverageBand -> stats (bands.h)

  void Merge(const CellStats& other);
  // The domain's natural distribution: every joint band.
  BandStats All() const;
  // Every coverage band together.
  BandStats AllCoverage() const;
  // Every sample: the natural distribution and the coverage bands.
  BandStats Everything() const;
  BandStats ForRatio(int ratio_band) const;
  BandStats ForDepth(int depth_band) const;
  BandStats ForDistance(int distance_band) const;
  // What a camera-distance band holds when every natural sample is in it:
  // the counts and the total and shader metrics of All() (the figures a
  // distance band records).
  BandStats DistanceBandOf() const;
  friend bool operator==(const CellStats&, const CellStats&) = default;
};

// The hot accumulator for one cell: dense 32-bit bins for every joint band
// and distance band, each band at a fixed place, so that the judge finds a
// sample's bins by arithmetic alone. The slots live in memory mapped zeroed
// and untouched: a band no sample reaches costs no memory, and all zeros is
// an empty slot. Flush() moves everything into a CellStats; the sweep
// flushes well before a 32-bit count could overflow.
class CellAccumulator {
 public:
  CellAccumulator();

  // All zeros is empty (worst_index and first_nonfinite_index mean nothing
  // until a maximum or a non-finite output sets them).
  struct Slot {
    std::array<std::array<std::uint32_t, kDenseBins>, kMetricCount> bins;
    std::array<double, kMetricCount> max_square;
    std::array<std::uint64_t, kMetricCount> worst_index;
    // (Finite samples are not counted here: every one lands in a bin of the
    // total error, and the flush counts them from there.)
    std::uint64_t nan, inf, stored_nonfinite, degenerate, outside, undrawn;
    std::uint64_t first_nonfinite_index;

    // One value (squared) of one metric, in dense bin `bin`. Samples come
    // in increasing index order, so on a tie the earlier sample stays the
    // worst, as MetricStats::Merge decides across shards.
    void Record(Metric metric, int bin, double square, std::uint64_t index) {
      const int m = static_cast<int>(metric);
      ++bins[m][bin];
      if (square > max_square[m]) {
        max_square[m] = square;
        worst_index[m] = index;
      }
    }
    void Record(Metric metric, double square, std::uint64_t index) {
      Record(metric, DenseBinOfSquare(square, kLowestOctave[static_cast<int>(metric)]), square, index);
    }
    void RecordNonFinite(bool is_nan, std::uint64_t index) {
      if (nan + inf == 0 || index < first_nonfinite_index) first_nonfinite_index = index;
      ++(is_nan ? nan : inf);
    }
  };

  Slot& Joint(int band) { return slots_.get()[kDistanceBands + band]; }
  // Where a frame's camera-distance band is recorded: its own slot, or
  // the discarded one once SkipDistanceBands() is called.
  Slot& Distance(int band) { return slots_.get()[skip_distance_ ? kDiscarded : band]; }
  // For a run whose cameras all lie in one distance band: that band holds
  // what the whole natural distribution does, so it is not recorded sample
  // by sample; DistanceBandOf() makes it from the joint bands at the end.
  void SkipDistanceBands() { skip_distance_ = true; }
  bool records_distances() const { return !skip_distance_; }
  Slot& Coverage(int band) { return slots_.get()[kDistanceBands + kJointBands + band]; }
  // The slots a sample's figures go to, chosen without a branch (targeted
  // picks interleave with natural samples at random, and a mispredicted
  // branch per sample and cell costs more than counts thrown away): a
  // natural sample's joint band and the run's distance band `distance`; a
  // targeted pick's coverage band and a slot that every flush discards.
  struct SampleSlots {
    Slot& band;
    Slot& distance;
  };
  SampleSlots SlotsOf(std::uint8_t joint_band, depthbench::Coverage coverage, Slot& distance) {
    const bool natural = coverage == depthbench::Coverage::kNatural;
    return {BandOf(joint_band, coverage), natural ? distance : slots_.get()[kDiscarded]};
  }
  // A sample's joint band, or its coverage band if it is a targeted pick.
  Slot& BandOf(std::uint8_t joint_band, depthbench::Coverage coverage) {
    const bool natural = coverage == depthbench::Coverage::kNatural;
    return slots_.get()[natural ? kDistanceBands + joint_band : kDistanceBands + kJointBands + CoverageBand(coverage)];
  }

  // Every slot by number, in the order the device judge counts them too
  // (shared/judge.h): camera-distance bands, joint bands, coverage bands.
  static constexpr int kSlotCount = kDistanceBands + kJointBands + kCoverageBands;
  Slot& At(int slot) { return slots_.get()[slot]; }

  // Samples recorded since the last flush (the caller counts them).
  void Count(std::uint64_t samples) { pending_ += samples; }
  std::uint64_t pending() const { return pending_; }
  void FlushInto(CellStats& out);

 private:
  static constexpr int kSlots = kSlotCount;
  static constexpr int kDiscarded = kSlots;  // one past the slots flushed
  struct Unmap {
    void operator()(Slot* slots) const;
  };
  // [0, kDistanceBands): distance bands; then joint bands, then coverage,
  // then the discarded slot.
  std::unique_ptr<Slot, Unmap> slots_;
  std::uint64_t pending_ = 0;
  bool skip_distance_ = false;
};

}  // namespace depthbench
