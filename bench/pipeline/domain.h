// The domain: the scenes the sampler draws (its ranges, each with a stated
// distribution) and how their depth is produced. A named domain
// (TypicalDomain, WideDomain, ExtremesDomain) or a scene file sets it;
// CLI flags narrow or fix its ranges.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bench/base/status.h"
#include "bench/pipeline/cells.h"

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

// One finite number in any form strtod takes; `what` names the input in
// the error.
Expected<double> ParseNumber(std::string_view text, std::string_view what);
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
// The widest and tallest render target a domain may name, in pixels: what
// fits a 16-bit side, far above any device's image limit.
inline constexpr std::uint32_t kMaxResolutionSide = 65535;
std::string ResolutionName(Resolution resolution);  // "1920x1080"
// "WIDTHxHEIGHT", each side 1 to kMaxResolutionSide; `what` names the input
// in the error ("--resolution").
Expected<Resolution> ParseResolution(std::string_view text, std::string_view what);
// A comma-separated list of them ("1920x1080,3840x2160").
Expected<std::vector<Resolution>> ParseResolutions(std::string_view text, std::string_view what);

// How the pipeline produces the depth it stores from a scene point's eye
// depth z (encode.h):
//   kFloat32  as a GPU does: the float32 constants an engine uploads (the
//             projection's A and B of ndc = A + B / z, or the far plane of
//             linear depth), the view-space z as a float32, and every
//             operation in float32: clip z, the divide, the viewport
//             transform;
//   kExact    the exact value, correctly rounded to float32 once: the best
//             any pipeline could do, to measure the formats and the
//             variants alone;
//   kRaster   the raster pipeline (`--pipeline raster`): geometry through
//             the sample's point drawn with the float32 view-projection
//             matrix, the depth a rasterizer interpolates at the pixel
//             centre (bench/pipeline/raster_model.h models it on the host;
//             a raster backend renders its own). Decoded like kFloat32.
enum class ProductionModel : std::uint8_t { kFloat32, kExact, kRaster };
const char* ProductionModelName(ProductionModel model);  // "float32", "exact", "raster"
Expected<ProductionModel> ParseProductionModel(std::string_view name);

// How the per-frame constants the shaders receive (shared/params.h:
// matrices, A and B, P and Q, lens, frustum corners) are computed
// (bench/pipeline/shader_constants.h):
//   kExact    exactly (double-double) from the frame, then rounded once to
//             float32: the best an engine could upload;
//   kFloat32  as an engine computes them: the view and projection matrices
//             built in float32 from the float32 camera parameters, their
//             product and its 4x4 inverse (glm::inverse) in float32, and
//             every other constant derived from those floats in float32.
// The projection's A and B are the ones the pipeline produces depth with
// (kFloat32 production), so they follow this choice too; the truth does not.
enum class ConstantsModel : std::uint8_t { kExact, kFloat32 };
const char* ConstantsModelName(ConstantsModel model);  // "exact", "float32"
Expected<ConstantsModel> ParseConstantsModel(std::string_view name);

// An off-centre field of view, as a VR runtime gives one per eye (OpenXR's
// XrFovf, in that order): the angle of each side of the frustum from the
// view axis, in degrees; left and down are negative for a frustum around
// the axis. The projection is then fixed: a domain's fov and aspect ranges
// do not apply.
struct EyeFov {
  double left = 0.0;
  double right = 0.0;
  double up = 0.0;
  double down = 0.0;
  // The tangents of the four sides at unit eye depth.
  double TanLeft() const;
  double TanRight() const;
  double TanUp() const;
  double TanDown() const;
  std::string ToString() const;  // "-50,45,48,-52"
  // Whether the frustum's centre is off the view axis.
  bool OffAxis() const { return left != -right || up != -down; }
  friend bool operator==(const EyeFov&, const EyeFov&) = default;
};
// "LEFT,RIGHT,UP,DOWN" in degrees; `what` names the input in the error.
Expected<EyeFov> ParseEyeFov(std::string_view text, std::string_view what);
Status CheckEyeFov(const EyeFov& fov, std::string_view what);
// An orthographic projection's view volume across the view axis: x from
// left to right and y from bottom to top, in view-space units (world units:
// the view is a rigid transform). Its depth range is the domain's near and
// far.
struct ViewVolume {
  double left = 0.0;
  double right = 0.0;
  double bottom = 0.0;
  double top = 0.0;
  std::string ToString() const;  // "-50,50,-30,30"
  bool OffAxis() const { return left != -right || bottom != -top; }
  friend bool operator==(const ViewVolume&, const ViewVolume&) = default;
};
// "LEFT,RIGHT,BOTTOM,TOP" in view units; `what` names the input in the error.
Expected<ViewVolume> ParseViewVolume(std::string_view text, std::string_view what);
Status CheckViewVolume(const ViewVolume& volume, std::string_view what);
// The largest side of a view volume, in view units: float32 world
// coordinates hold 1e7 to about a metre's 1/1000 (2^-24 of it is 0.6).
inline constexpr double kMostViewVolumeSide = 1e7;

// The largest angle a side may make with the view axis, in degrees.
inline constexpr double kMostEyeFovAngle = 89.0;
// The largest TAA jitter, in pixels: jitter is sub-pixel, a few pixels
// already means something else.
inline constexpr double kMostJitterPixels = 4.0;

// The members' defaults are the `typical` domain (TypicalDomain).
struct CapturedPixels;  // captured.h

struct Domain {
  std::string name = "typical";    // the named domain or scene it started from ("custom" once narrowed)
  Range fov_degrees{30.0, 100.0};  // vertical field of view, uniform in degrees
  Range aspect{1.0, 2.4};          // width / height, log-uniform
  Range near{0.01, 1.0};           // log-uniform
  // Far/near ratio of finite projections (log-uniform), and whether the
  // infinite-far conventions are sampled. Every frame has a finite ratio when
  // finite_far is set; infinite-far cells read the same frames with the far
  // plane at infinity.
  Range ratio{1e2, 1e5};
  bool finite_far = true;
  bool infinite_far = true;
  std::optional<Range> far;  // absolute far plane; the ratio then follows from near
  // Camera distance from the world origin. With min 0 and max > 0, a quarter
  // of the frames sit exactly at the origin and the rest are log-uniform in
  // [max * 1e-6, max]; otherwise log-uniform in [min, max] (or fixed).
  Range camera_distance{0.0, 0.0};
  std::optional<Range> eye_depth;  // absolute eye-depth range of interest (clipped to the frustum)
  // An off-centre frustum (a VR eye, a projection matrix's), in place of
  // fov and aspect.
  std::optional<EyeFov> eye_fov;
  // An orthographic projection (a directional light's shadow map, a CAD
  // view), in place of fov and aspect: only the orthographic conventions'
  // cells run, with a finite far plane.
  std::optional<ViewVolume> orthographic;
  // TAA jitter: each frame's projection is shifted by an offset drawn
  // uniformly from [-jitter, jitter] pixels in x and in y, as temporal
  // anti-aliasing shifts it by a sub-pixel amount every frame.
  double jitter = 0.0;
  // The one projective convention an engine's projection matrix stores
  // (projection_matrix.h); the others' cells do not run. Not among
  // ToFlags' flags: a cell names its convention itself.
  std::optional<Convention> depth_convention;
  std::vector<Resolution> resolutions{{1280, 720}, {1920, 1080}, {2560, 1440}, {3840, 2160}};
  ProductionModel production = ProductionModel::kFloat32;
  ConstantsModel constants = ConstantsModel::kExact;
  // A captured frame (captured.h, made by CaptureDomain): its pixels are
  // the population, in place of random draws. Not among ToFlags' flags: a
  // scene file names it.
  std::shared_ptr<const CapturedPixels> capture;

  // Far/near span used by frames whose far plane is infinite only.
  static constexpr double kInfiniteDepthSpan = 1e8;

  Status Validate() const;
  // Whether frames may have an off-centre lens: an eye fov not centred on
  // the view axis, or TAA jitter.
  bool OffCentre() const;
  std::string Describe() const;
  // The command-line flags that rebuild this domain exactly (numbers with
  // 17 significant digits), e.g. "--fov 1:179 --near 0.0001:10 ...".
  std::string ToFlags() const;
  // Domains are equal when they draw the same samples: the name is left out.
  friend bool operator==(const Domain& a, const Domain& b);
};

// The named domains. `typical`: what games and viewers render, camera-relative
// (the camera at the world origin, as engines with large worlds render):
// vertical fov 30 to 100 degrees, aspect 1 to 2.4, near 0.01 to 1, far/near
// 1e2 to 1e5 and infinite, the common render-target sizes. `wide`: far
// beyond that (fov 1 to 179, aspect 0.1 to 10, near 1e-4 to 10, far/near
// 1e1 to 1e8 and infinite, cameras up to 1e6 from the origin). `extremes`:
// the edges a fuzzer looks for (near 1e-6 to 1e-2, far/near 1e6 to 1e9 and
// infinite, fov 0.5 to 179.5, aspect 0.05 to 20, cameras 1e5 to 1e7 out).
Domain TypicalDomain();
Domain WideDomain();
Domain ExtremesDomain();
// "typical", "wide" or "extremes"; InvalidArgument naming them otherwise.
Expected<Domain> NamedDomain(std::string_view name);
inline constexpr const char* kDomainNames = "typical, wide, extremes";

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
