#include "bench/choose/ranking.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <fmt/format.h>

namespace depthbench {

bool CostsTie(const CandidateCost& a, const CandidateCost& b) {
  return std::fabs(a.value - b.value) <= std::max(a.spread, b.spread);
}

CostChoice ChooseCosts(const CostSources& sources, std::span<const Cell> candidates) {
  if (!sources.measured) return {sources.static_model, false, sources.no_measured_note};
  std::vector<std::string> missing;
  for (const Cell& cell : candidates) {
    if (!sources.measured(cell)) missing.push_back(cell.Name());
  }
  if (missing.empty()) return {sources.measured, true, ""};
  return {sources.static_model, false,
          fmt::format("{} has no GPU time for {} of the {} candidates ({}{}): every candidate is ranked by the "
                      "static cost model instead, so that one unit ranks them all",
                      sources.measured_from, missing.size(), candidates.size(), missing.front(),
                      missing.size() > 1 ? ", ..." : "")};
}

std::vector<RankPlace> Rank(std::span<const RankInput> candidates) {
  const auto group = [](const RankInput& v) { return !v.meets ? 2 : v.over_budget ? 1 : 0; };
  const auto value_of = [](const RankInput& v) { return v.cost ? v.cost->value : INFINITY; };
  std::vector<std::size_t> order(candidates.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) {
    const RankInput& a = candidates[i];
    const RankInput& b = candidates[j];
    if (group(a) != group(b)) return group(a) < group(b);
    if (group(a) < 2 && value_of(a) != value_of(b)) return value_of(a) < value_of(b);
    if (a.nonfinite != b.nonfinite) return a.nonfinite < b.nonfinite;
    if (a.supported != b.supported) return a.supported;
    return a.error < b.error;
  });
  // Cost ties among the candidates that meet it: a run of candidates whose
  // costs all tie with the run's first is put in order of accuracy.
  std::vector<RankPlace> places;
  for (std::size_t k = 0; k < order.size();) {
    const RankInput& first = candidates[order[k]];
    std::size_t end = k + 1;
    while (end < order.size() && group(candidates[order[end]]) == group(first) && group(first) < 2 && first.cost &&
           candidates[order[end]].cost && CostsTie(*first.cost, *candidates[order[end]].cost)) {
      ++end;
    }
    std::stable_sort(order.begin() + static_cast<std::ptrdiff_t>(k), order.begin() + static_cast<std::ptrdiff_t>(end),
                     [&](std::size_t i, std::size_t j) { return candidates[i].error < candidates[j].error; });
    for (std::size_t i = k; i < end; ++i) places.push_back({order[i], static_cast<int>(k) + 1, end - k > 1});
    k = end;
  }
  return places;
}

}  // namespace depthbench
