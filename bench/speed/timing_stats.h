// Timing statistics: what a set of repeated measurements of one pass says,
// and when two such sets can be told apart. Plain free functions over host
// numbers; no device, no I/O (the Vulkan timer and the CPU timer feed them).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "bench/base/status.h"

namespace depthbench {

// The order statistics of a set of timings (nanoseconds). Quartiles are
// read with linear interpolation between order statistics (the "type 7"
// rule of R and NumPy), so that a hand computation can check them.
struct TimingSummary {
  std::uint32_t count = 0;
  double median = 0.0;
  double q1 = 0.0;  // first quartile
  double q3 = 0.0;  // third quartile
  double min = 0.0;
  double max = 0.0;
  // The spread a difference must exceed to count: the interquartile range.
  // It ignores the odd outlier (a preempted pass) that a standard deviation
  // would let decide a ranking.
  double spread() const { return q3 - q1; }
};

// The q-quantile (q in [0, 1]) of sorted values, interpolated.
double QuantileOfSorted(std::span<const double> sorted, double q);
// InvalidArgument for an empty set or a value that is not finite.
Expected<TimingSummary> SummarizeTimings(std::span<const double> values);

// How one timed thing compares with another.
enum class Ordering {
  kFaster,             // its median is lower by more than the spread
  kSlower,             // its median is higher by more than the spread
  kIndistinguishable,  // the medians differ by no more than the spread
};
const char* OrderingName(Ordering ordering);

// The spread two summaries are compared with: the larger of their two
// interquartile ranges (either run's noise could make the difference).
double ComparisonSpread(const TimingSummary& a, const TimingSummary& b);
// a against b, by their medians (ns) and ComparisonSpread.
Ordering Compare(const TimingSummary& a, const TimingSummary& b);

// Ranks of a group of timings measured alike: rank 1 + the number of
// members that are distinguishably faster. Members that tie share a rank;
// a rank says nothing finer than the spread allows.
std::vector<std::uint32_t> RankByTiming(std::span<const TimingSummary> group);

}  // namespace depthbench
