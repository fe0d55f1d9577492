// The trade: for each convention and format, every variant's cost against
// its p99.9 bits lost, and which variants are on the Pareto front (no other
// variant is at least as cheap and at least as accurate, and better in one).
#pragma once

#include <span>
#include <string>
#include <vector>

#include "bench/base/status.h"
#include "bench/results/results.h"
#include "bench/speed/speed_results.h"

namespace depthbench {

// The frame a GPU cost is given for (a time per reconstruction times its
// pixels): what a frame budget is usually counted in.
inline constexpr Resolution kCostFrame{1920, 1080};

// A cell whose NaN and Inf outputs exceed this share of its judged samples
// has a non-finite p99.9: it counts as losing every bit.
inline constexpr double kNonfiniteShareAtP999 = 0.001;

struct FrontCandidate {
  double cost = 0.0;
  double spread = 0.0;  // the cost's spread: smaller differences are ties
  double bits_lost = 0.0;
};
// a dominates b: a is no costlier (cheaper by more than the larger spread,
// or a tie) and loses no more bits (fewer, or the same to kResolvedBits),
// and is strictly better in one of the two.
bool Dominates(const FrontCandidate& a, const FrontCandidate& b);
// For each candidate, whether no other dominates it.
std::vector<bool> ParetoFront(std::span<const FrontCandidate> candidates);

// p99.9 bits lost of a cell's total error with its 95% sampling interval
// (MetricStats::LevelInterval), and its NaN/Inf count.
struct CellAccuracy {
  double p999_bits_lost = 0.0;
  double p999_bits_low = 0.0, p999_bits_high = 0.0;
  std::uint64_t nonfinite = 0;
};
CellAccuracy AccuracyOf(const CellStats& stats);

// The backend whose errors the trade uses: "vulkan" when the results hold
// it (the errors of the shaders the GPU runs), else "cpu". NotFound when
// they hold neither.
Expected<std::string> TradeBackend(const Results& accuracy);

// One TradeFront per (convention, format) with a GPU timing at
// `resolution` in the ALU-bound regime; a variant without accuracy results
// or without a CPU cost is left out of its front and named in `left_out`.
std::vector<TradeFront> BuildTrade(const SpeedResults& speed, const Results& accuracy, const std::string& backend,
                                   Resolution resolution, std::vector<std::string>& left_out);

}  // namespace depthbench
