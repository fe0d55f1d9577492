// The one ranking of choose and the report's first screen, on hand-made
// candidates.
#include <gtest/gtest.h>

#include "bench/choose/ranking.h"

namespace depthbench {
namespace {

CandidateCost Cost(double value, double spread = 0.0) {
  CandidateCost cost;
  cost.value = value;
  cost.spread = spread;
  cost.unit = "slots";
  cost.source = "test";
  return cost;
}

std::vector<std::size_t> Order(const std::vector<RankInput>& inputs) {
  std::vector<std::size_t> order;
  for (const RankPlace& p : Rank(inputs)) order.push_back(p.candidate);
  return order;
}

TEST(RankingTest, MeetingAndAffordableFirstCheapestFirstThenOverBudgetThenFailingClosestFirst) {
  const std::vector<RankInput> inputs{
      {.meets = false, .error = 3.0, .cost = Cost(1)},  // fails, closer
      {.meets = true, .error = 2.0, .cost = Cost(9)},   // meets, dearer
      {.meets = true, .over_budget = true, .error = 0.5, .cost = Cost(20)},
      {.meets = false, .error = 5.0, .cost = Cost(0.5)},    // fails, further
      {.meets = true, .error = 2.5, .cost = Cost(4)},       // meets, cheapest
      {.meets = true, .error = 0.1, .cost = std::nullopt},  // meets, cost unknown: last of its group
  };
  EXPECT_EQ(Order(inputs), (std::vector<std::size_t>{4, 1, 5, 2, 0, 3}));
}

// Costs within a measurement's spread tie: the more accurate goes first and
// both share the rank; exact costs (spread 0) tie only when equal.
TEST(RankingTest, CostsWithinTheSpreadTieAndGoInOrderOfAccuracy) {
  const std::vector<RankInput> inputs{
      {.error = 3.0, .cost = Cost(10.0, 0.5)},
      {.error = 1.0, .cost = Cost(10.4, 0.5)},
      {.error = 0.5, .cost = Cost(12.0, 0.5)},
  };
  const std::vector<RankPlace> places = Rank(inputs);
  ASSERT_EQ(places.size(), 3u);
  EXPECT_EQ(places[0].candidate, 1u);
  EXPECT_EQ(places[1].candidate, 0u);
  EXPECT_EQ(places[2].candidate, 2u);
  EXPECT_EQ(places[0].rank, 1);
  EXPECT_EQ(places[1].rank, 1);
  EXPECT_TRUE(places[0].tied && places[1].tied);
  EXPECT_EQ(places[2].rank, 3);
  EXPECT_FALSE(places[2].tied);
  const std::vector<RankInput> exact{{.error = 3.0, .cost = Cost(10.0)}, {.error = 1.0, .cost = Cost(10.4)}};
  EXPECT_EQ(Order(exact), (std::vector<std::size_t>{0, 1}));
}

// Among those that fail, findings and unsupported figures go last.
TEST(RankingTest, NonFiniteAndUnsupportedCandidatesComeAfterTheOthersThatFail) {
  const std::vector<RankInput> inputs{
      {.meets = false, .nonfinite = 2, .error = 0.1, .cost = std::nullopt},
      {.meets = false, .supported = false, .error = 0.2, .cost = std::nullopt},
      {.meets = false, .error = 7.0, .cost = std::nullopt},
  };
  EXPECT_EQ(Order(inputs), (std::vector<std::size_t>{2, 1, 0}));
}

TEST(RankingTest, MeasuredCostsRankOnlyWhenTheyCoverEveryCandidate) {
  const Cell a{Variant{0}, Convention::kStandard, Format::kX8D24Unorm};
  const Cell b{Variant{0}, Convention::kReversed, Format::kX8D24Unorm};
  CostSources sources;
  sources.static_model = [](const Cell&) { return Cost(1.0); };
  sources.measured = [a](const Cell& c) -> std::optional<CandidateCost> {
    if (c == a) return Cost(2.0);
    return std::nullopt;
  };
  sources.measured_from = "speed.json";
  const Cell both[] = {a, b};
  const CostChoice partial = ChooseCosts(sources, both);
  EXPECT_FALSE(partial.measured);
  EXPECT_EQ(partial.lookup(a)->value, 1.0);
  EXPECT_NE(partial.note.find("speed.json has no GPU time for 1 of the 2 candidates"), std::string::npos)
      << partial.note;
  const Cell only_a[] = {a};
  const CostChoice full = ChooseCosts(sources, only_a);
  EXPECT_TRUE(full.measured);
  EXPECT_EQ(full.lookup(a)->value, 2.0);
  EXPECT_TRUE(full.note.empty());
}

}  // namespace
}  // namespace depthbench
