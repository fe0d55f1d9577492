// Bands: how results are split. Three families, each by decades:
//   far/near ratio (the frame's f/n; "inf" for infinite-far conventions),
//   eye depth over near (z/n, where in the frustum the point lies),
//   camera distance from the world origin (how large world coordinates are).
// Ratio and depth are kept jointly (the error models need both at once);
// camera distance separately.
#pragma once

#include <cmath>
#include <string>

namespace depthbench {

inline constexpr int kRatioBands = 11;  // 1e0.., 1e1.., ..., 1e9 and above; infinity
inline constexpr int kInfiniteRatioBand = 10;
inline constexpr int kDepthBands = 10;  // z/n in 1e0.., ..., 1e9 and above
inline constexpr int kJointBands = kRatioBands * kDepthBands;
inline constexpr int kDistanceBands = 5;  // [0,1), [1,1e2), [1e2,1e4), [1e4,1e6), 1e6 and above

inline int DecadeBand(double x, int count) {
  if (!(x >= 10.0)) return 0;
  int decade = static_cast<int>(std::floor(std::log10(x)));
  return decade < count - 1 ? decade : count - 1;
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
