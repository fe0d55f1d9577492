#include "bench/pipeline/domain.h"

#include <array>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <numbers>

#include <fmt/format.h>

#include "bench/base/parse_number.h"
#include "bench/base/suggest.h"
#include "bench/pipeline/captured.h"

namespace depthbench {

const RangeLimits kFovLimits{0.0, 180.0, true, true, "degrees"};
const RangeLimits kAspectLimits{1e-4, 1e4, false, false, ""};
const RangeLimits kNearLimits{0.0, 1e6, true, false, "world units"};
const RangeLimits kFarLimits{0.0, 1e30, true, false, "world units"};
const RangeLimits kRatioLimits{1.0, 1e15, true, false, ""};
const RangeLimits kCameraDistanceLimits{0.0, 1e9, false, false, "world units"};
const RangeLimits kEyeDepthLimits{0.0, 1e30, true, false, "world units"};

Expected<double> ParseNumber(std::string_view text, std::string_view what) {
  std::string s(text);
  if (s.empty()) return InvalidArgument(fmt::format("{}: empty value", what));
  errno = 0;
  char* end = nullptr;
  double value = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(value)) {
    return InvalidArgument(fmt::format("{}: '{}' is not a finite number", what, s));
  }
  return value;
}

namespace {

std::string DescribeLimits(const RangeLimits& limits) {
  return fmt::format("{}{:g}, {:g}{}{}{}", limits.lowest_exclusive ? "(" : "[", limits.lowest, limits.highest,
                     limits.highest_exclusive ? ")" : "]", limits.unit.empty() ? "" : " ", limits.unit);
}

}  // namespace

std::string Range::ToString() const { return fixed() ? fmt::format("{:g}", min) : fmt::format("{:g}:{:g}", min, max); }

Status CheckRange(const Range& range, std::string_view what, const RangeLimits& limits) {
  auto outside = [&](double x) {
    return (limits.lowest_exclusive ? x <= limits.lowest : x < limits.lowest) ||
           (limits.highest_exclusive ? x >= limits.highest : x > limits.highest);
  };
  if (range.min > range.max) {
    return InvalidArgument(fmt::format("{}: minimum {:g} is above maximum {:g}", what, range.min, range.max));
  }
  if (outside(range.min) || outside(range.max)) {
    return InvalidArgument(
        fmt::format("{}: {} is out of range; allowed {}", what, range.ToString(), DescribeLimits(limits)));
  }
  return Status::Ok();
}

Expected<Range> ParseRange(std::string_view text, std::string_view what, const RangeLimits& limits) {
  Range range;
  auto colon = text.find(':');
  if (colon == std::string_view::npos) {
    DB_ASSIGN_OR_RETURN(double value, ParseNumber(text, what));
    range = {value, value};
  } else {
    DB_ASSIGN_OR_RETURN(double lo, ParseNumber(text.substr(0, colon), what));
    DB_ASSIGN_OR_RETURN(double hi, ParseNumber(text.substr(colon + 1), what));
    range = {lo, hi};
  }
  DB_RETURN_IF_ERROR(CheckRange(range, what, limits));
  return range;
}

Status ParseRatioInto(std::string_view text, Domain& domain) {
  std::string_view finite_part = text;
  bool infinite = false;
  if (text == "inf" || text == "infinite") {
    domain.finite_far = false;
    domain.infinite_far = true;
    return Status::Ok();
  }
  auto comma = text.find(',');
  if (comma != std::string_view::npos) {
    std::string_view rest = text.substr(comma + 1);
    if (rest != "inf" && rest != "infinite") {
      return InvalidArgument(
          fmt::format("--ratio: '{}' is not understood; use VALUE, MIN:MAX, inf, or MIN:MAX,inf", text));
    }
    infinite = true;
    finite_part = text.substr(0, comma);
  }
  DB_ASSIGN_OR_RETURN(Range ratio, ParseRange(finite_part, "--ratio", kRatioLimits));
  domain.ratio = ratio;
  domain.finite_far = true;
  domain.infinite_far = infinite;
  return Status::Ok();
}

const char* ProductionModelName(ProductionModel model) {
  switch (model) {
    case ProductionModel::kExact: return "exact";
    case ProductionModel::kRaster: return "raster";
    case ProductionModel::kFloat32: break;
  }
  return "float32";
}

Expected<ProductionModel> ParseProductionModel(std::string_view name) {
  if (name == "float32") return ProductionModel::kFloat32;
  if (name == "exact") return ProductionModel::kExact;
  if (name == "raster") return ProductionModel::kRaster;
  return InvalidArgument(fmt::format("production model '{}' is not one of float32, exact, raster", name));
}

const char* ConstantsModelName(ConstantsModel model) { return model == ConstantsModel::kFloat32 ? "float32" : "exact"; }

Expected<ConstantsModel> ParseConstantsModel(std::string_view name) {
  if (name == "exact") return ConstantsModel::kExact;
  if (name == "float32") return ConstantsModel::kFloat32;
  return InvalidArgument(fmt::format("constants model '{}' is not one of exact, float32", name));
}

bool operator==(const Domain& a, const Domain& b) {
  return a.fov_degrees == b.fov_degrees && a.aspect == b.aspect && a.near == b.near && a.ratio == b.ratio &&
         a.finite_far == b.finite_far && a.infinite_far == b.infinite_far && a.far == b.far &&
         a.camera_distance == b.camera_distance && a.eye_depth == b.eye_depth && a.resolutions == b.resolutions &&
         a.production == b.production && a.constants == b.constants && a.eye_fov == b.eye_fov &&
         a.orthographic == b.orthographic && a.jitter == b.jitter && a.depth_convention == b.depth_convention &&
         a.capture == b.capture;
}

Domain TypicalDomain() { return Domain{}; }

Domain WideDomain() {
  Domain d;
  d.name = "wide";
  d.fov_degrees = {1.0, 179.0};
  d.aspect = {0.1, 10.0};
  d.near = {1e-4, 10.0};
  d.ratio = {10.0, 1e8};
  d.camera_distance = {0.0, 1e6};
  d.resolutions = {{1280, 720}, {1920, 1080}, {2560, 1440}, {3840, 2160}, {1366, 768}, {800, 600}};
  return d;
}

Domain ExtremesDomain() {
  Domain d = WideDomain();
  d.name = "extremes";
  d.fov_degrees = {0.5, 179.5};
  d.aspect = {0.05, 20.0};
  d.near = {1e-6, 1e-2};
  d.ratio = {1e6, 1e9};
  d.camera_distance = {1e5, 1e7};
  return d;
}

Expected<Domain> NamedDomain(std::string_view name) {
  if (name == "typical") return TypicalDomain();
  if (name == "wide") return WideDomain();
  if (name == "extremes") return ExtremesDomain();
  const std::string names[] = {"typical", "wide", "extremes"};
  return InvalidArgument(fmt::format("domain '{}' is not one of {} (or a scene file, NAME.toml){}", name, kDomainNames,
                                     DidYouMean(name, names)));
}

Status Domain::Validate() const {
  DB_RETURN_IF_ERROR(CheckRange(fov_degrees, "fov", kFovLimits));
  DB_RETURN_IF_ERROR(CheckRange(aspect, "aspect", kAspectLimits));
  DB_RETURN_IF_ERROR(CheckRange(near, "near", kNearLimits));
  DB_RETURN_IF_ERROR(CheckRange(camera_distance, "camera distance", kCameraDistanceLimits));
  if (!finite_far && !infinite_far) {
    return InvalidArgument("the domain has neither finite nor infinite far planes");
  }
  if (finite_far) {
    if (far) {
      DB_RETURN_IF_ERROR(CheckRange(*far, "far", kFarLimits));
      if (far->min <= near.max) {
        return InvalidArgument(fmt::format("far must be greater than near: far {} does not exceed near {} everywhere",
                                           far->ToString(), near.ToString()));
      }
    } else {
      DB_RETURN_IF_ERROR(CheckRange(ratio, "ratio", kRatioLimits));
    }
  }
  if (eye_depth) {
    DB_RETURN_IF_ERROR(CheckRange(*eye_depth, "eye depth", kEyeDepthLimits));
    // The depths asked for must meet some frustum of the domain.
    if (eye_depth->max < near.min) {
      return InvalidArgument(fmt::format("eye depth {} lies nearer than every near plane of the domain (near {})",
                                         eye_depth->ToString(), near.ToString()));
    }
    const double deepest = infinite_far ? INFINITY : far ? far->max : near.max * ratio.max;
    if (eye_depth->min > deepest) {
      return InvalidArgument(fmt::format("eye depth {} lies beyond every far plane of the domain (at most {:g})",
                                         eye_depth->ToString(), deepest));
    }
  }
  if (eye_fov) DB_RETURN_IF_ERROR(CheckEyeFov(*eye_fov, "eye fov"));
  if (orthographic) {
    DB_RETURN_IF_ERROR(CheckViewVolume(*orthographic, "orthographic view volume"));
    if (eye_fov) return InvalidArgument("an orthographic view volume has no field of view; give one or the other");
    if (!finite_far || infinite_far) {
      return InvalidArgument("an orthographic projection has no infinite far plane; give --far or a finite --ratio");
    }
    if (production == ProductionModel::kRaster) {
      return InvalidArgument("the raster form does not draw orthographic projections yet; use the compute form");
    }
  }
  if (!(jitter >= 0.0 && jitter <= kMostJitterPixels)) {
    return InvalidArgument(fmt::format("jitter: {:g} pixels is out of range; allowed [0, {:g}] pixels", jitter,
                                       kMostJitterPixels));
  }
  if (resolutions.empty()) return InvalidArgument("the domain has no resolution");
  for (const auto& r : resolutions) {
    if (r.width == 0 || r.height == 0 || r.width > kMaxResolutionSide || r.height > kMaxResolutionSide) {
      return InvalidArgument(fmt::format("resolution {} is out of range; allowed 1 to {} pixels a side",
                                         ResolutionName(r), kMaxResolutionSide));
    }
  }
  return Status::Ok();
}

bool Domain::OffCentre() const {
  return (eye_fov && eye_fov->OffAxis()) || (orthographic && orthographic->OffAxis()) || jitter > 0.0;
}

std::string Domain::ToFlags() const {
  auto range = [](const Range& r) { return r.fixed() ? fmt::format("{}", r.min) : fmt::format("{}:{}", r.min, r.max); };
  std::string flags = orthographic ? "--ortho " + orthographic->ToString()
                     : eye_fov    ? "--eye-fov " + eye_fov->ToString()
                                  : fmt::format("--fov {} --aspect {}", range(fov_degrees), range(aspect));
  flags += " --near " + range(near);
  if (jitter > 0.0) flags += fmt::format(" --jitter {}", jitter);
  if (!finite_far) {
    flags += " --ratio inf";
  } else if (far) {
    flags += " --far " + range(*far);
  } else {
    flags += " --ratio " + range(ratio) + (infinite_far ? ",inf" : "");
  }
  flags += " --camera-distance " + range(camera_distance);
  if (eye_depth) flags += " --depth " + range(*eye_depth);
  if (resolutions != Domain{}.resolutions) {
    std::string sizes;
    for (const Resolution& r : resolutions) sizes += (sizes.empty() ? "" : ",") + ResolutionName(r);
    flags += " --resolution " + sizes;
  }
  if (production == ProductionModel::kRaster) {
    flags += " --pipeline raster";
  } else if (production != ProductionModel::kFloat32) {
    flags += fmt::format(" --production {}", ProductionModelName(production));
  }
  if (constants != ConstantsModel::kExact) flags += fmt::format(" --constants {}", ConstantsModelName(constants));
  return flags;
}

std::string Domain::Describe() const {
  std::string far_text;
  if (finite_far) {
    far_text = far ? fmt::format("far {}", far->ToString()) : fmt::format("far/near {}", ratio.ToString());
    if (infinite_far) far_text += " and infinite";
  } else {
    far_text = "infinite far";
  }
  const std::string lens =
      orthographic ? fmt::format("orthographic, view volume x {:.6g} to {:.6g}, y {:.6g} to {:.6g}", orthographic->left,
                                 orthographic->right, orthographic->bottom, orthographic->top)
      : eye_fov    ? fmt::format("eye fov {:.6g}, {:.6g}, {:.6g}, {:.6g} deg (left, right, up, down)", eye_fov->left,
                                 eye_fov->right, eye_fov->up, eye_fov->down)
                   : fmt::format("fov {} deg, aspect {}", fov_degrees.ToString(), aspect.ToString());
  std::string text = fmt::format("{}, near {}, {}, camera distance {}", lens, near.ToString(), far_text,
                                 camera_distance.ToString());
  if (jitter > 0.0) text += fmt::format(", TAA jitter up to {:g} px", jitter);
  if (depth_convention) text += fmt::format(", {} depth only (the projection matrix's)", Info(*depth_convention).name);
  if (eye_depth) text += fmt::format(", eye depth {}", eye_depth->ToString());
  if (capture) text += fmt::format(", the pixels of {} ({}x{})", capture->source, capture->width, capture->height);
  if (production != ProductionModel::kFloat32) text += fmt::format(", {} production", ProductionModelName(production));
  if (constants != ConstantsModel::kExact) text += fmt::format(", {} constants", ConstantsModelName(constants));
  return fmt::format("{}: {}", name, text);
}

namespace {
double TanDegrees(double degrees) { return std::tan(degrees * std::numbers::pi / 180.0); }
}  // namespace

double EyeFov::TanLeft() const { return TanDegrees(left); }
double EyeFov::TanRight() const { return TanDegrees(right); }
double EyeFov::TanUp() const { return TanDegrees(up); }
double EyeFov::TanDown() const { return TanDegrees(down); }
std::string EyeFov::ToString() const { return fmt::format("{},{},{},{}", left, right, up, down); }

Status CheckEyeFov(const EyeFov& fov, std::string_view what) {
  for (const double angle : {fov.left, fov.right, fov.up, fov.down}) {
    if (!(std::abs(angle) <= kMostEyeFovAngle)) {
      return InvalidArgument(fmt::format("{}: angle {:g} is out of range; each side lies within [-{:g}, {:g}] degrees "
                                         "of the view axis",
                                         what, angle, kMostEyeFovAngle, kMostEyeFovAngle));
    }
  }
  if (!(fov.right > fov.left) || !(fov.up > fov.down)) {
    return InvalidArgument(fmt::format("{}: {} has no area: right must exceed left and up must exceed down "
                                       "(left and down are negative for a frustum around the view axis)",
                                       what, fov.ToString()));
  }
  return Status::Ok();
}

namespace {

// Four comma-separated numbers; `usage` says what they are in the error.
Expected<std::array<double, 4>> ParseFourNumbers(std::string_view text, std::string_view what, std::string_view usage) {
  std::array<double, 4> numbers;
  std::size_t start = 0;
  for (int k = 0; k < 4; ++k) {
    const std::size_t comma = k < 3 ? text.find(',', start) : text.size();
    if (comma == std::string_view::npos || (k == 3 && text.find(',', start) != std::string_view::npos)) {
      return InvalidArgument(fmt::format("{}: '{}' is not {}", what, text, usage));
    }
    DB_ASSIGN_OR_RETURN(numbers[k], ParseNumber(text.substr(start, comma - start), what));
    start = comma + 1;
  }
  return numbers;
}

}  // namespace

Expected<EyeFov> ParseEyeFov(std::string_view text, std::string_view what) {
  DB_ASSIGN_OR_RETURN(const auto angles,
                      ParseFourNumbers(text, what, "LEFT,RIGHT,UP,DOWN in degrees (four numbers, e.g. -50,45,48,-52)"));
  const EyeFov fov{angles[0], angles[1], angles[2], angles[3]};
  DB_RETURN_IF_ERROR(CheckEyeFov(fov, what));
  return fov;
}

std::string ViewVolume::ToString() const { return fmt::format("{},{},{},{}", left, right, bottom, top); }

Status CheckViewVolume(const ViewVolume& volume, std::string_view what) {
  for (const double side : {volume.left, volume.right, volume.bottom, volume.top}) {
    if (!(std::abs(side) <= kMostViewVolumeSide)) {
      return InvalidArgument(fmt::format("{}: side {:g} is out of range; each side lies within [-{:g}, {:g}] view "
                                         "units of the view axis",
                                         what, side, kMostViewVolumeSide, kMostViewVolumeSide));
    }
  }
  if (!(volume.right > volume.left) || !(volume.top > volume.bottom)) {
    return InvalidArgument(fmt::format("{}: {} has no area: right must exceed left and top must exceed bottom", what,
                                       volume.ToString()));
  }
  return Status::Ok();
}

Expected<ViewVolume> ParseViewVolume(std::string_view text, std::string_view what) {
  DB_ASSIGN_OR_RETURN(
      const auto sides,
      ParseFourNumbers(text, what, "LEFT,RIGHT,BOTTOM,TOP in view units (four numbers, e.g. -50,50,-30,30)"));
  const ViewVolume volume{sides[0], sides[1], sides[2], sides[3]};
  DB_RETURN_IF_ERROR(CheckViewVolume(volume, what));
  return volume;
}

std::string ResolutionName(Resolution resolution) { return fmt::format("{}x{}", resolution.width, resolution.height); }

Expected<Resolution> ParseResolution(std::string_view text, std::string_view what) {
  const std::size_t x = text.find_first_of("xX");
  const auto side = [&](std::string_view digits) -> std::uint32_t {
    const std::optional<std::uint32_t> n = ParseDigits<std::uint32_t>(digits);
    return n && *n <= kMaxResolutionSide ? *n : 0;
  };
  const Resolution r = x == std::string_view::npos ? Resolution{0, 0}
                                                    : Resolution{side(text.substr(0, x)), side(text.substr(x + 1))};
  if (r.width == 0 || r.height == 0) {
    return InvalidArgument(fmt::format("{}: '{}' is not WIDTHxHEIGHT with each side 1 to {} (e.g. 1920x1080)", what,
                                       text, kMaxResolutionSide));
  }
  return r;
}

Expected<std::vector<Resolution>> ParseResolutions(std::string_view text, std::string_view what) {
  std::vector<Resolution> out;
  for (std::size_t start = 0; start <= text.size();) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    DB_ASSIGN_OR_RETURN(const Resolution r, ParseResolution(text.substr(start, comma - start), what));
    out.push_back(r);
    start = comma + 1;
  }
  return out;
}

}  // namespace depthbench
