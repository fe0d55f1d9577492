// Bands: how results are split. The samples of the domain's natural
// distribution (log-uniform eye depth, uniform pixels) fall in three
// families, each by decades:
//   far/near ratio (the frame's f/n; "inf" for infinite-far conventions),
//   eye depth over near (z/n, where in the frustum the point lies),
//   camera distance from the world origin (how large world coordinates are).
// Ratio and depth are kept jointly (the error models need both at once);
// camera distance separately. Every band keeps every metric.
//
// The samples drawn on purpose where reconstructions break (stored values
// at the ends of the format, the first and last doubling of depth, the
// corners and edges of the screen) are coverage, not population: they fall
// in coverage bands of their own, one per kind, and never in the three
// families, so that the families' quantiles describe what a user renders.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>

namespace depthbench {

inline constexpr int kRatioBands = 11;  // 1e0.., 1e1.., ..., 1e9 and above; infinity
inline constexpr int kInfiniteRatioBand = 10;
inline constexpr int kDepthBands = 10;  // z/n in 1e0.., ..., 1e9 and above
inline constexpr int kJointBands = kRatioBands * kDepthBands;
inline constexpr int kDistanceBands = 5;  // [0,1), [1,1e2), [1e2,1e4), [1e4,1e6), 1e6 and above

// What a sample was drawn for: the natural distribution, or one of the
// coverage kinds (a stored-value pick first, then a depth band, then a
// pixel pick).
enum class Coverage : std::uint8_t {
  kNatural,
  kStoredZero,
  kStoredOne,
  kStoredAfterZero,
  kStoredBeforeOne,
  kNearDoubling,
  kFarDoubling,
  kCornerPixel,
  kEdgePixel,
};
inline constexpr int kCoverageBands = static_cast<int>(Coverage::kEdgePixel);  // the kinds but kNatural
// Band index of a coverage kind (not kNatural), and its label ("stored 0",
// "far doubling", "corner pixel", ...).
constexpr int CoverageBand(Coverage kind) { return static_cast<int>(kind) - 1; }
std::string CoverageBandName(int band);

// floor(log10(x)) clamped to [0, count), by comparison with exact powers of
// ten (cheaper than a logarithm, and exact at the edges): the number of
// powers up to x, counted without branches, which samples' random depths
// would mispredict. NaN is in band 0.
inline int DecadeBand(double x, int count) {
  constexpr double kPowers[] = {1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12};
  int band = 0;
  for (int k = 0; k < count - 1; ++k) band += x >= kPowers[k] ? 1 : 0;
  return band;
}

inline int RatioBand(double ratio) {
  return std::isinf(ratio) ? kInfiniteRatioBand : DecadeBand(ratio, kRatioBands - 1);
}
inline int DepthBand(double depth_over_near) { return DecadeBand(depth_over_near, kDepthBands); }
inline int DistanceBand(double distance) {
  if (distance < 1.0) return 0;
  int band = 1 + static_cast<int>(std::floor(std::log10(distance) / 2.0));
  return band < kDistanceBands - 1 ? band : kDistanceBands - 1;
}
inline int JointBand(int ratio_band, int depth_band) { return ratio_band * kDepthBands + depth_band; }
inline int RatioOfJoint(int joint) { return joint / kDepthBands; }
inline int DepthOfJoint(int joint) { return joint % kDepthBands; }

// Labels: "1e3" (meaning [1e3, 1e4)), "1e9+", "inf"; distance "1e2" etc.
std::string RatioBandName(int band);
std::string DepthBandName(int band);
std::string DistanceBandName(int band);
// Lower edges, for plots and models (the band's geometric middle is
// edge * sqrt(10) for decades).
double RatioBandLow(int band);
double DepthBandLow(int band);
double DistanceBandLow(int band);

}  // namespace depthbench
