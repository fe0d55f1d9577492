#include "bench/speed/timing_stats.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace depthbench {

double QuantileOfSorted(std::span<const double> sorted, double q) {
  if (sorted.empty()) return 0.0;
  const double position = q * static_cast<double>(sorted.size() - 1);
  const auto below = static_cast<std::size_t>(std::floor(position));
  const std::size_t above = std::min(below + 1, sorted.size() - 1);
  const double fraction = position - static_cast<double>(below);
  return sorted[below] + (sorted[above] - sorted[below]) * fraction;
}

Expected<TimingSummary> SummarizeTimings(std::span<const double> values) {
  if (values.empty()) return InvalidArgument("no timings to summarize");
  std::vector<double> sorted(values.begin(), values.end());
  for (double v : sorted) {
    if (!std::isfinite(v)) return InvalidArgument(fmt::format("a timing is not a finite number ({})", v));
  }
  std::sort(sorted.begin(), sorted.end());
  TimingSummary s;
  s.count = static_cast<std::uint32_t>(sorted.size());
  s.median = QuantileOfSorted(sorted, 0.5);
  s.q1 = QuantileOfSorted(sorted, 0.25);
  s.q3 = QuantileOfSorted(sorted, 0.75);
  s.min = sorted.front();
  s.max = sorted.back();
  return s;
}

const char* OrderingName(Ordering ordering) {
  switch (ordering) {
    case Ordering::kFaster: return "faster";
    case Ordering::kSlower: return "slower";
    case Ordering::kIndistinguishable: return "indistinguishable";
  }
  return "?";
}

double ComparisonSpread(const TimingSummary& a, const TimingSummary& b) { return std::max(a.spread(), b.spread()); }

Ordering Compare(const TimingSummary& a, const TimingSummary& b) {
  const double difference = a.median - b.median;
  const double spread = ComparisonSpread(a, b);
  if (std::fabs(difference) <= spread) return Ordering::kIndistinguishable;
  return difference < 0.0 ? Ordering::kFaster : Ordering::kSlower;
}

std::vector<std::uint32_t> RankByTiming(std::span<const TimingSummary> group) {
  std::vector<std::uint32_t> ranks(group.size(), 1);
  for (std::size_t i = 0; i < group.size(); ++i) {
    for (std::size_t j = 0; j < group.size(); ++j) {
      if (i != j && Compare(group[j], group[i]) == Ordering::kFaster) ++ranks[i];
    }
  }
  return ranks;
}

}  // namespace depthbench
