// Binning, quantiles and merging of the streaming statistics.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "bench/pipeline/stats.h"

namespace depthbench {
namespace {

// The quarter-octave bin of x, computed slowly with a logarithm, for values
// not on a boundary.
int SlowQuarterOctave(double x) { return static_cast<int>(std::floor(4.0 * std::log2(x))); }

TEST(StatsTest, QuarterOctaveMatchesLogarithmAwayFromBoundaries) {
  for (double x = 1e-30; x < 1e30; x *= 1.0137) {
    ASSERT_EQ(QuarterOctaveOfSqrt(x * x), SlowQuarterOctave(x)) << x;
  }
}

TEST(StatsTest, QuarterOctaveIsExactAtBoundaries) {
  // sqrt(q) == 2^(k/4) exactly for q == 2^(k/2) when k is even; for odd k the
  // boundary sqrt(2)*2^j is irrational and the double just below/above it
  // must fall on either side.
  for (int k = -40; k <= 40; k += 2) {
    double q = std::ldexp(1.0, k / 2);
    EXPECT_EQ(QuarterOctaveOfSqrt(q), 2 * (k / 2)) << k;
    EXPECT_EQ(QuarterOctaveOfSqrt(std::nextafter(q, 0.0)), 2 * (k / 2) - 1) << k;
  }
  // The double nearest to sqrt(2) lies just above it, so its square root
  // lies above 2^(1/4) (bin 1); the double below it lies below (bin 0).
  const double sqrt2 = std::sqrt(2.0);
  EXPECT_EQ(QuarterOctaveOfSqrt(sqrt2), 1);
  EXPECT_EQ(QuarterOctaveOfSqrt(std::nextafter(sqrt2, 0.0)), 0);
}

TEST(StatsTest, DenseBinsClampAndKeepZeroAndNanApart) {
  const int low = kLowestOctave[0];
  EXPECT_EQ(DenseBinOfSquare(0.0, low), 0);
  EXPECT_EQ(DenseBinOfSquare(1e-300, low), 0);  // far below the kept range
  EXPECT_EQ(DenseBinOfSquare(1e300, low), kBinsKept + 1);
  EXPECT_EQ(DenseBinOfSquare(INFINITY, low), kBinsKept + 1);
  // 2^-24 relative error (bits lost 0) is bin (-24 - low) * 4 + 1.
  EXPECT_EQ(DenseBinOfSquare(std::ldexp(1.0, -48), low), (-24 - low) * kBinsPerOctave + 1);
}

// The judge bins four lanes at a time (DenseBinsOfSquares on Double4):
// every lane must land where the scalar form puts it, at bin edges too.
TEST(StatsTest, FourLaneBinsMatchTheScalarBins) {
  const double sqrt2 = std::sqrt(2.0);
  std::vector<double> values = {0.0, 1e-310, 0x1p-1022, 1e-300, 1e300, INFINITY, NAN, 0x1p-48, 0x1p-112, 0x1p-111};
  for (int k = -120; k <= 40; ++k) {
    const double edge = std::ldexp(k % 2 == 0 ? 1.0 : sqrt2, k / 2);
    values.insert(values.end(), {edge, std::nextafter(edge, 0.0), std::nextafter(edge, INFINITY)});
  }
  while (values.size() % 4 != 0) values.push_back(1.0);
  for (int metric = 0; metric < kMetricCount; ++metric) {
    const int low = kLowestOctave[metric];
    for (std::size_t i = 0; i < values.size(); i += 4) {
      const Double4 lanes = {values[i], values[i + 1], values[i + 2], values[i + 3]};
      const Int4 bins = DenseBinsOfSquares<Int4>(lanes, low);
      for (int lane = 0; lane < 4; ++lane) {
        ASSERT_EQ(bins[lane], DenseBinOfSquare(values[i + lane], low)) << values[i + lane] << " metric " << metric;
      }
    }
  }
}

MetricStats Fill(const std::vector<double>& values, int low) {
  CellAccumulator acc;
  std::uint64_t index = 0;
  for (double v : values) acc.Joint(0).Record(Metric::kTotal, v * v, index++);
  CellStats stats;
  acc.FlushInto(stats);
  (void)low;
  return stats.joint[0][Metric::kTotal];
}

TEST(StatsTest, QuantilesFallInTheRightQuarterOctave) {
  // 1000 values: 990 at 2^-20, 9 at 2^-10, 1 at 2^-4.
  std::vector<double> values(990, std::ldexp(1.0, -20));
  values.insert(values.end(), 9, std::ldexp(1.0, -10));
  values.push_back(std::ldexp(1.0, -4));
  const int low = kLowestOctave[0];
  MetricStats m = Fill(values, low);
  EXPECT_EQ(m.Count(), 1000u);
  EXPECT_EQ(m.max(), std::ldexp(1.0, -4));
  EXPECT_EQ(m.worst_index, 999u);
  // A quantile is interpolated inside its bin: within a quarter octave.
  auto within_bin = [](double got, double want) { return got >= want && got <= want * std::exp2(0.25); };
  EXPECT_TRUE(within_bin(m.Quantile(0.5, low), std::ldexp(1.0, -20))) << m.Quantile(0.5, low);
  EXPECT_TRUE(within_bin(m.Quantile(0.99, low), std::ldexp(1.0, -20))) << m.Quantile(0.99, low);
  EXPECT_TRUE(within_bin(m.Quantile(0.995, low), std::ldexp(1.0, -10))) << m.Quantile(0.995, low);
  EXPECT_TRUE(within_bin(m.Quantile(0.9995, low), std::ldexp(1.0, -4)));
  EXPECT_EQ(m.Quantile(1.0, low), std::ldexp(1.0, -4));
}

TEST(StatsTest, BitsLost) {
  EXPECT_EQ(BitsLost(std::ldexp(1.0, -24)), 0.0);
  EXPECT_EQ(BitsLost(std::ldexp(1.0, -30)), 0.0);  // floored at zero
  EXPECT_DOUBLE_EQ(BitsLost(std::ldexp(1.0, -14)), 10.0);
  EXPECT_EQ(BitsLost(0.0), 0.0);
}

// Slots start as zeros, and a flush leaves them so: an index is reported
// only where something set it, a band nothing reached is not reported, and
// a second flush adds only what came after the first.
TEST(StatsTest, AccumulatorReportsOnlyWhatWasRecordedAndStartsAgainAfterAFlush) {
  constexpr std::uint64_t kNone = std::numeric_limits<std::uint64_t>::max();
  CellAccumulator acc;
  acc.Joint(2).Record(Metric::kTotal, 0.0, 5);  // an exact result: no maximum above zero
  CellStats stats;
  acc.FlushInto(stats);
  ASSERT_EQ(stats.joint.size(), 1u);
  EXPECT_TRUE(stats.distance.empty());
  const BandStats& first = stats.joint.at(2);
  EXPECT_EQ(first.finite, 1u);
  EXPECT_EQ(first[Metric::kTotal].max_square, 0.0);
  EXPECT_EQ(first[Metric::kTotal].worst_index, kNone);
  EXPECT_EQ(first[Metric::kArith].worst_index, kNone);
  EXPECT_EQ(first.first_nonfinite_index, kNone);

  acc.Joint(2).RecordNonFinite(true, 9);
  acc.Joint(2).RecordNonFinite(false, 7);
  acc.Distance(1).Record(Metric::kTotal, 0.25, 8);
  acc.FlushInto(stats);
  const BandStats& second = stats.joint.at(2);
  EXPECT_EQ(second.finite, 1u);  // not counted twice
  EXPECT_EQ(second.nan, 1u);
  EXPECT_EQ(second.inf, 1u);
  EXPECT_EQ(second.first_nonfinite_index, 7u);
  ASSERT_EQ(stats.distance.size(), 1u);
  EXPECT_EQ(stats.distance.at(1)[Metric::kTotal].worst_index, 8u);
  EXPECT_EQ(stats.distance.at(1).first_nonfinite_index, kNone);
}

TEST(StatsTest, MergeIsExactAndKeepsTheEarliestWorstSample) {
  CellAccumulator a, b, whole;
  for (std::uint64_t i = 0; i < 100; ++i) {
    double v = std::ldexp(1.0 + (i % 7), -30 + static_cast<int>(i % 13));
    (i < 60 ? a : b).Joint(3).Record(Metric::kArith, v * v, i);
    whole.Joint(3).Record(Metric::kArith, v * v, i);
  }
  CellStats sa, sb, sw;
  a.FlushInto(sa);
  b.FlushInto(sb);
  whole.FlushInto(sw);
  CellStats merged = sb;  // order must not matter
  merged.Merge(sa);
  EXPECT_EQ(merged.joint[3][Metric::kArith].bins, sw.joint[3][Metric::kArith].bins);
  EXPECT_EQ(merged.joint[3][Metric::kArith].max_square, sw.joint[3][Metric::kArith].max_square);
  EXPECT_EQ(merged.joint[3][Metric::kArith].worst_index, sw.joint[3][Metric::kArith].worst_index);
}

}  // namespace
}  // namespace depthbench
