// The arithmetic of speed: quantiles and spreads against hand-computed
// values, timestamp conversion with known periods and counter widths,
// when two timings are told apart, ranks, and the Pareto front.
#include <cstdint>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "bench/backends/vulkan/timestamps.h"
#include "bench/speed/timing_stats.h"
#include "bench/speed/trade.h"

namespace depthbench {
namespace {

TimingSummary Summary(double q1, double median, double q3) {
  TimingSummary s;
  s.count = 5;
  s.q1 = q1;
  s.median = median;
  s.q3 = q3;
  s.min = q1;
  s.max = q3;
  return s;
}

TEST(TimingSummaryTest, OddCountQuartilesAreOrderStatistics) {
  const std::vector<double> values = {5, 1, 4, 2, 3};
  auto s = SummarizeTimings(values);
  ASSERT_TRUE(s.ok());
  EXPECT_EQ(s->count, 5u);
  EXPECT_EQ(s->median, 3.0);
  EXPECT_EQ(s->q1, 2.0);  // position 0.25 * 4 = 1 of 1..5
  EXPECT_EQ(s->q3, 4.0);
  EXPECT_EQ(s->min, 1.0);
  EXPECT_EQ(s->max, 5.0);
  EXPECT_EQ(s->spread(), 2.0);
}

TEST(TimingSummaryTest, EvenCountQuartilesInterpolate) {
  const std::vector<double> values = {4, 3, 2, 1};
  auto s = SummarizeTimings(values);
  ASSERT_TRUE(s.ok());
  // Positions 0.75, 1.5 and 2.25 of the sorted values 1, 2, 3, 4.
  EXPECT_EQ(s->q1, 1.75);
  EXPECT_EQ(s->median, 2.5);
  EXPECT_EQ(s->q3, 3.25);
}

TEST(TimingSummaryTest, RefusesEmptyAndNonFinite) {
  EXPECT_FALSE(SummarizeTimings(std::vector<double>{}).ok());
  const std::vector<double> bad = {1.0, std::numeric_limits<double>::quiet_NaN()};
  auto s = SummarizeTimings(bad);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.status().message().find("not a finite number"), std::string::npos);
}

TEST(TimestampTest, ConvertsTicksWithThePeriod) {
  // 1000 ticks of an 83.333 ns counter (Intel's period) are 83333 ns;
  // of a 1 ns counter (lavapipe, NVIDIA) 1000 ns.
  EXPECT_DOUBLE_EQ(TimestampIntervalNs(5000, 6000, 64, 83.333), 83333.0);
  EXPECT_DOUBLE_EQ(TimestampIntervalNs(5000, 6000, 64, 1.0), 1000.0);
  EXPECT_DOUBLE_EQ(TimestampIntervalNs(5000, 6000, 64, 40.0), 40000.0);
}

TEST(TimestampTest, NarrowCounterWrapsAndUpperBitsAreIgnored) {
  constexpr std::uint64_t kTop36 = std::uint64_t{1} << 36;
  // A 36-bit counter that wrapped: 10 ticks to the wrap, 5 after.
  EXPECT_DOUBLE_EQ(TimestampIntervalNs(kTop36 - 10, 5, 36, 1.0), 15.0);
  // Bits above the valid ones are not part of the time.
  EXPECT_DOUBLE_EQ(TimestampIntervalNs((std::uint64_t{0xabc} << 36) | 100, (std::uint64_t{0x123} << 36) | 300, 36, 2.0),
                   400.0);
  // A full 64-bit counter wraps modulo 2^64.
  EXPECT_DOUBLE_EQ(TimestampIntervalNs(std::numeric_limits<std::uint64_t>::max() - 1, 3, 64, 1.0), 5.0);
}

TEST(TimestampTest, RefusesQueuesThatCannotTime) {
  auto none = CheckedTimestampIntervalNs(0, 10, 0, 1.0);
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.status().message().find("timestampValidBits is 0"), std::string::npos);
  auto period = CheckedTimestampIntervalNs(0, 10, 64, 0.0);
  ASSERT_FALSE(period.ok());
  EXPECT_NE(period.status().message().find("timestampPeriod 0"), std::string::npos);
  auto good = CheckedTimestampIntervalNs(0, 10, 64, 2.5);
  ASSERT_TRUE(good.ok());
  EXPECT_DOUBLE_EQ(*good, 25.0);
}

TEST(CompareTest, DifferencesWithinTheSpreadAreIndistinguishable) {
  const TimingSummary a = Summary(9, 10, 11);         // spread 2
  const TimingSummary b = Summary(12, 12.5, 13);      // spread 1: differs by 2.5 > 2
  const TimingSummary c = Summary(11.5, 11.9, 12.5);  // differs from a by 1.9 <= 2
  EXPECT_EQ(Compare(a, b), Ordering::kFaster);
  EXPECT_EQ(Compare(b, a), Ordering::kSlower);
  EXPECT_EQ(Compare(a, c), Ordering::kIndistinguishable);
  EXPECT_EQ(Compare(c, a), Ordering::kIndistinguishable);
  // Exactly the spread apart is still a tie: "smaller than or equal".
  EXPECT_EQ(Compare(Summary(9, 10, 11), Summary(11, 12, 13)), Ordering::kIndistinguishable);
}

TEST(CompareTest, RanksShareTiesOnly) {
  const std::vector<TimingSummary> group = {Summary(19, 20, 21), Summary(9, 10, 11), Summary(10.5, 11, 11.5),
                                            Summary(29, 30, 31)};
  // 10 and 11 tie (difference 1 <= spread 2): both rank 1; 20 is slower
  // than both: rank 3; 30 rank 4.
  EXPECT_EQ(RankByTiming(group), (std::vector<std::uint32_t>{3, 1, 1, 4}));
}

TEST(ParetoTest, FrontKeepsTheUndominated) {
  const std::vector<FrontCandidate> points = {
      {1.0, 0.1, 10.0},   // cheapest
      {2.0, 0.1, 5.0},    // most accurate
      {3.0, 0.1, 6.0},    // dearer and less accurate than the second: dominated
      {1.05, 0.1, 10.1},  // the first's twin: cost within the spread, bits within 1/4
      {1.05, 0.1, 11.0},  // costs the same as the first, a bit more lost: dominated
  };
  EXPECT_EQ(ParetoFront(points), (std::vector<bool>{true, true, false, true, false}));
}

TEST(ParetoTest, DominanceNeedsOneStrictImprovement) {
  EXPECT_FALSE(Dominates({1.0, 0.0, 3.0}, {1.0, 0.0, 3.0}));
  EXPECT_TRUE(Dominates({1.0, 0.0, 3.0}, {1.5, 0.0, 3.0}));
  // Cheaper, but not beyond the spread, and as accurate: no dominance.
  EXPECT_FALSE(Dominates({1.0, 0.6, 3.0}, {1.5, 0.1, 3.0}));
  // A quarter bit is the resolution of the statistics.
  EXPECT_TRUE(Dominates({1.0, 0.0, 3.0}, {1.0, 0.0, 3.25}));
  EXPECT_FALSE(Dominates({1.0, 0.0, 3.0}, {1.0, 0.0, 3.2}));
}

TEST(AccuracyTest, NonFiniteOutputsBeyondOnePerMilleLoseEveryBit) {
  CellStats stats;
  stats.joint[0].finite = 999;
  stats.joint[0].nan = 2;  // 2 of 1001 judged: above 0.1%, the p99.9 sample is NaN
  EXPECT_EQ(AccuracyOf(stats).p999_bits_lost, kAllBitsLost);
  EXPECT_EQ(AccuracyOf(stats).nonfinite, 2u);
  stats.joint[0].nan = 1;  // 1 of 1000: the p99.9 is a finite sample's (no bins: no error)
  EXPECT_EQ(AccuracyOf(stats).p999_bits_lost, 0.0);
}

}  // namespace
}  // namespace depthbench
