// Ranking: the one order in which depthbench puts candidates for a choice,
// used by `choose` for a scene and by the report's first screen. Those
// that meet the requirement and fit the budget come first, cheapest first;
// then those that meet it but cost too much; then those that fail, the
// closest first. Candidates whose costs a measurement cannot tell apart
// (CostsTie) go in order of accuracy and share a rank.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "bench/pipeline/cells.h"

namespace depthbench {

// The cost of a candidate, in the one unit of its ranking.
struct CandidateCost {
  double value = 0.0;
  double spread = 0.0;  // two costs closer than the larger spread are a tie (0: exact)
  std::string unit;     // "µs per 2560x1440 frame on llvmpipe", "FMA-equivalent slots"
  std::string source;   // where it came from
  // For a frame's cost (frame_cost.h): the bytes per pixel the choice makes
  // the frame move, and the parts in words; 0 and empty otherwise.
  std::uint32_t bytes_per_pixel = 0;
  std::string parts;
};

// Costs per cell; `nullopt` when none is known for a cell.
using CostLookup = std::function<std::optional<CandidateCost>(const Cell&)>;

// Two costs that the ranking cannot tell apart.
bool CostsTie(const CandidateCost& a, const CandidateCost& b);

// Where a ranking's costs come from: measured times when they cover every
// candidate, else the static model for all (a ranking never mixes units).
struct CostSources {
  CostLookup measured;  // empty: none given
  std::string measured_from;
  CostLookup static_model;
  std::string no_measured_note;  // why none was given, when none was
};
struct CostChoice {
  CostLookup lookup;      // empty where no source was given
  bool measured = false;  // the lookup is the measured one
  std::string note;       // why the static model ranks, where measured costs were given but left some out
};
CostChoice ChooseCosts(const CostSources& sources, std::span<const Cell> candidates);

// A candidate as the ranking sees it.
struct RankInput {
  bool meets = true;         // meets the requirement
  bool over_budget = false;  // costs more than the scene allows
  std::uint64_t nonfinite = 0;
  bool supported = true;  // enough samples for the figure
  double error = 0.0;     // how far from the truth, in any unit where less is better
  std::optional<CandidateCost> cost;
};

// A place in the ranking: the candidate (an index into the input), its rank
// (1 = the choice; candidates that tie on cost share one) and whether it
// shares it.
struct RankPlace {
  std::size_t candidate = 0;
  int rank = 0;
  bool tied = false;
};

// The candidates, best first.
std::vector<RankPlace> Rank(std::span<const RankInput> candidates);

}  // namespace depthbench
