// Gate: compares a run's figures with a committed baseline, cell by cell
// and band by band, and says what got worse and what got better.
//
// With the same seed, device and build, results are identical to the bit;
// the tolerances absorb what a driver or compiler update may legitimately
// change (the order of a float sum: a few units in the last place), not
// noise. In bits lost, a few ulps at the p99.9 (where errors are at least a
// few ulps) move the figure by less than the statistics resolve
// (kResolvedBits); the maximum is one sample and may move by up to 0.5 bit. Where a band's p99.9 has a wider sampling
// interval (few samples above it), that interval is the tolerance, and a
// band with too few samples for a p99.9 (MinimumSamples) is compared at
// its maximum only.
#pragma once

#include <string>
#include <vector>

#include "bench/gate/baseline.h"

namespace depthbench {

struct GateTolerance {
  double p999_bits = kResolvedBits;
  double max_bits = 0.5;
};

// The sweep a gate runs: fixed seed, every cell, the camera at the world
// origin (so that what a shader edit does to the arithmetic is not hidden
// under world-space rounding), sized to run in seconds.
SamplePlan GatePlan();

struct BandChange {
  std::string band;
  BandFigures before, after;
  std::vector<std::string> reasons;  // "total p99.9 +1.3 bits", "NaN appeared (0 -> 12)"
};

// Each band is classified once: worse when anything about it got worse
// (what got better in it then goes unreported), else better or unchanged. A
// band with no finite output on one side has no bits figure there: it is
// worse or better for that, with the reason, and its bits are not compared.
struct CellVerdict {
  std::string cell;
  std::vector<BandChange> worse;
  std::vector<BandChange> better;
  std::vector<std::string> not_compared;  // bands of the run that the baseline lacks
  bool disappeared = false;               // in the baseline, not in the run
  bool appeared = false;                  // in the run, not in the baseline: not compared
  bool failed() const { return disappeared || !worse.empty(); }
  bool improved() const { return !failed() && !better.empty(); }
  // Whether some of what the run measured in this cell was not compared.
  bool uncovered() const { return appeared || !not_compared.empty(); }
};

struct GateComparison {
  std::string backend;
  std::vector<CellVerdict> cells;  // every cell of either side
  std::vector<std::string> notes;  // different driver or compiler versions
  int failures() const;
  int improvements() const;
  int compared() const;  // cells in both
  // What the baseline does not cover, for a message: "2 cells not in the
  // baseline (a, b); 3 bands not in it (c: all, ...)"; empty when it covers
  // every cell and band of the run.
  std::string Uncovered() const;
};

// Why the two cannot be compared (another device, another sample plan), or
// the comparison. Cell names are those of `catalogue`.
Expected<GateComparison> CompareWithBaseline(const Baseline& baseline, const Baseline& run,
                                             const GateTolerance& tolerance,
                                             const Catalogue& catalogue = Catalogue::BuiltIn());

}  // namespace depthbench
