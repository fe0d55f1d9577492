// The domain: the ranges the sampler draws from. Defaults cover what the
// bench is for; CLI flags and scene files narrow or fix them.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bench/base/status.h"

namespace depthbench {

// A closed interval [min, max]; min == max fixes the value.
struct Range {
  double min = 0.0;
  double max = 0.0;
  bool fixed() const { return min == max; }
  bool Contains(double x) const { return x >= min && x <= max; }
  std::string ToString() const;
  friend bool operator==(const Range&, const Range&) = default;
};

// Parses "VALUE" or "MIN:MAX" (numbers in any form strtod takes, e.g. 1e-4).
// `what` names the flag or field for the message; the result must lie in
// [lowest, highest] (exclusive bounds where the flags say so).
struct RangeLimits {
  double lowest;
  double highest;
  bool lowest_exclusive = false;
  bool highest_exclusive = false;
  std::string_view unit;
};
Expected<Range> ParseRange(std::string_view text, std::string_view what, const RangeLimits& limits);
Status CheckRange(const Range& range, std::string_view what, const RangeLimits& limits);

struct Resolution {
  std::uint32_t width;
  std::uint32_t height;
  friend bool operator==(const Resolution&, const Resolution&) = default;
};

struct Domain {
  Range fov_degrees{1.0, 179.0};  // vertical field of view, uniform in degrees
  Range aspect{0.1, 10.0};        // width / height, log-uniform
  Range near{1e-4, 10.0};         // log-uniform
  // Far/near ratio of finite projections (log-uniform), and whether the
  // infinite-far conventions are sampled. Every frame has a finite ratio when
  // finite_far is set; infinite-far cells read the same frames with the far
  // plane at infinity.
  Range ratio{10.0, 1e8};
  bool finite_far = true;
  bool infinite_far = true;
  std::optional<Range> far;  // absolute far plane; the ratio then follows from near
  // Camera distance from the world origin. With min 0 and max > 0, a quarter
  // of the frames sit exactly at the origin and the rest are log-uniform in
  // [max * 1e-6, max]; otherwise log-uniform in [min, max] (or fixed).
  Range camera_distance{0.0, 1e6};
  std::optional<Range> eye_depth;  // absolute eye-depth range of interest (clipped to the frustum)
  std::vector<Resolution> resolutions{{1280, 720}, {1920, 1080}, {2560, 1440}, {3840, 2160}, {1366, 768}, {800, 600}};

  // Far/near span used by frames whose far plane is infinite only.
  static constexpr double kInfiniteDepthSpan = 1e8;

  Status Validate() const;
  std::string Describe() const;
  // The command-line flags that rebuild this domain exactly (numbers with
  // 17 significant digits), e.g. "--fov 1:179 --near 0.0001:10 ...".
  std::string ToFlags() const;
  friend bool operator==(const Domain&, const Domain&) = default;
};

// The limits the flags enforce (also what --help prints).
extern const RangeLimits kFovLimits;
extern const RangeLimits kAspectLimits;
extern const RangeLimits kNearLimits;
extern const RangeLimits kFarLimits;
extern const RangeLimits kRatioLimits;
extern const RangeLimits kCameraDistanceLimits;
extern const RangeLimits kEyeDepthLimits;

// "--ratio": "10:1e8", "1e4", "inf", or either of the first two with ",inf".
Status ParseRatioInto(std::string_view text, Domain& domain);

}  // namespace depthbench
