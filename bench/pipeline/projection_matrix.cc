#include "bench/pipeline/projection_matrix.h"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "bench/base/suggest.h"

namespace depthbench {
namespace {

struct ApiName {
  GraphicsApi api;
  const char* name;
};
constexpr ApiName kApiNames[] = {{GraphicsApi::kDirect3D, "d3d"},
                                 {GraphicsApi::kVulkan, "vulkan"},
                                 {GraphicsApi::kMetal, "metal"},
                                 {GraphicsApi::kOpenGL, "opengl"},
                                 {GraphicsApi::kOpenGLClipControl, "opengl-clip-control"}};

bool ClipsToMinusOne(GraphicsApi api) { return api == GraphicsApi::kOpenGL; }

// The projective convention of DB_CONVENTION_* bits.
Convention ConventionWithBits(std::uint32_t bits) {
  for (const ConventionInfo& c : AllConventions()) {
    if (c.hardware && c.bits == bits) return c.id;
  }
  return Convention::kStandard;  // unreachable: the eight combinations are all there
}

// "m32" names M's row 3, column 2 (0-based), as the messages do.
std::string Entry(const ProjectionMatrix& m, int row, int column) {
  return fmt::format("m{}{} = {:g}", row, column, m.At(row, column));
}

Status Refuse(std::string why) { return InvalidArgument("projection matrix: " + std::move(why)); }

double Degrees(double tangent) { return std::atan(tangent) * 180.0 / std::numbers::pi; }

// The side values at NDC -1 and +1 of `ndc = scale * t + offset`, in
// order (a negative scale mirrors the axis).
std::pair<double, double> Sides(double scale, double offset) {
  const double a = (-1.0 - offset) / scale, b = (1.0 - offset) / scale;
  return {std::min(a, b), std::max(a, b)};
}

// Near and far from window depth d = a + b / e (perspective) or d = a + b
// * e (orthographic), whichever way it runs.
Status DepthPlanes(double a, double b, bool orthographic, ProjectionFacts& facts) {
  if (b == 0.0) return Refuse("depth does not change with eye depth (m22 and m23 give a constant)");
  const auto eye_at = [&](double d) { return orthographic ? (d - a) / b : b / (d - a); };
  const bool reversed = orthographic ? b < 0.0 : b > 0.0;
  const double infinite_depth = reversed ? 0.0 : 1.0;  // the window depth an infinite far plane stores
  facts.near = eye_at(reversed ? 1.0 : 0.0);
  facts.far = !orthographic && a == infinite_depth ? INFINITY : eye_at(reversed ? 0.0 : 1.0);
  facts.convention = ConventionWithBits((reversed ? catalog::kRev : 0u) | (std::isinf(facts.far) ? catalog::kInf : 0u) |
                                        (orthographic ? catalog::kOrtho : 0u));
  if (!(facts.near > 0.0) || !std::isfinite(facts.near)) {
    return Refuse(fmt::format("its near plane lies at eye depth {:g}, not in front of the eye{}", facts.near,
                              orthographic ? " (eye depths are drawn log-uniformly from near: move the view's origin "
                                             "back until near is positive)"
                                           : ""));
  }
  if (!(facts.far > facts.near)) {
    return Refuse(fmt::format("its far plane (eye depth {:g}) is not beyond its near plane ({:g}): depth never "
                              "reaches {} (a far plane past infinity is not modelled)",
                              facts.far, facts.near, reversed ? 0 : 1));
  }
  return Status::Ok();
}

}  // namespace

Expected<GraphicsApi> ParseGraphicsApi(std::string_view name) {
  std::vector<std::string> names;
  for (const ApiName& a : kApiNames) {
    if (name == a.name) return a.api;
    names.emplace_back(a.name);
  }
  return InvalidArgument(fmt::format("API '{}' is not one of {}{}", name, kGraphicsApiNames, DidYouMean(name, names)));
}

const char* GraphicsApiName(GraphicsApi api) {
  for (const ApiName& a : kApiNames) {
    if (a.api == api) return a.name;
  }
  return "?";
}

Expected<MatrixLayout> ParseMatrixLayout(std::string_view name) {
  if (name == "column-major") return MatrixLayout::kColumnMajor;
  if (name == "row-major") return MatrixLayout::kRowMajor;
  return InvalidArgument(fmt::format("layout '{}' is not one of column-major (GLM, GLSL, a D3D matrix in memory), "
                                     "row-major (written row by row)",
                                     name));
}

double ProjectionMatrix::At(int row, int column) const {
  return layout == MatrixLayout::kColumnMajor ? numbers[column * 4 + row] : numbers[row * 4 + column];
}

bool ProjectionFacts::off_centre() const { return left != -right || bottom != -top; }

Expected<ProjectionFacts> ReadProjectionMatrix(const ProjectionMatrix& given) {
  for (double x : given.numbers) {
    if (!std::isfinite(x)) return Refuse("every number must be finite");
  }
  ProjectionFacts facts;
  // The w row decides the kind; the matrix is scaled so that w = eye depth
  // (perspective) or 1 (orthographic), which changes no NDC value.
  ProjectionMatrix m = given;
  const double w2 = m.At(3, 2), w3 = m.At(3, 3);
  if (m.At(3, 0) != 0.0 || m.At(3, 1) != 0.0 || (w2 == 0.0) == (w3 == 0.0) || w3 < 0.0) {
    return Refuse(fmt::format("its w row ({}, {}, {}, {}) is neither perspective (0, 0, -1 or +1, 0) nor "
                              "orthographic (0, 0, 0, 1)",
                              Entry(m, 3, 0), Entry(m, 3, 1), Entry(m, 3, 2), Entry(m, 3, 3)));
  }
  facts.orthographic = w2 == 0.0;
  if (!facts.orthographic && std::abs(w2) != 1.0) {
    return Refuse(fmt::format("{} must be -1 or +1 in a perspective matrix (clip w is the eye depth); is the layout "
                              "right? A matrix read in the other layout puts m23, the depth offset, there",
                              Entry(m, 3, 2)));
  }
  if (facts.orthographic && w3 != 1.0) {
    return Refuse(fmt::format("{} must be 1 in an orthographic matrix", Entry(m, 3, 3)));
  }
  const double scale = facts.orthographic ? w3 : std::abs(w2);
  for (double& x : m.numbers) x /= scale;
  facts.left_handed = !facts.orthographic && w2 > 0.0;
  const double z_sign = facts.left_handed ? 1.0 : -1.0;  // view z of eye depth 1

  if (m.At(2, 0) != 0.0 || m.At(2, 1) != 0.0) {
    return Refuse(fmt::format("an oblique near plane: clip z depends on x and y ({}, {}); depthbench models depth "
                              "as a function of eye depth alone, and an oblique plane tilts it across the screen",
                              Entry(given, 2, 0), Entry(given, 2, 1)));
  }
  if (m.At(0, 1) != 0.0 || m.At(1, 0) != 0.0) {
    return Refuse(fmt::format("x and y are mixed ({}, {}): a skewed or rotated projection is not modelled",
                              Entry(given, 0, 1), Entry(given, 1, 0)));
  }
  if (!(m.At(0, 0) > 0.0) || m.At(1, 1) == 0.0) {
    return Refuse(fmt::format("{} must be positive and {} nonzero: they scale x and y to the screen",
                              Entry(given, 0, 0), Entry(given, 1, 1)));
  }
  // NDC x = m00 * t + offset, with t = x / eye depth (perspective) or x.
  const int translation = facts.orthographic ? 2 : 3;  // the column that must be 0
  if (m.At(0, translation) != 0.0 || m.At(1, translation) != 0.0) {
    return Refuse(fmt::format("{} and {} must be 0 for {} projection", Entry(given, 0, translation),
                              Entry(given, 1, translation), facts.orthographic ? "an orthographic" : "a perspective"));
  }
  const double offset_x = facts.orthographic ? m.At(0, 3) : z_sign * m.At(0, 2);
  const double offset_y = facts.orthographic ? m.At(1, 3) : z_sign * m.At(1, 2);
  std::tie(facts.left, facts.right) = Sides(m.At(0, 0), offset_x);
  std::tie(facts.bottom, facts.top) = Sides(m.At(1, 1), offset_y);
  facts.y_flipped = m.At(1, 1) < 0.0;

  // NDC depth: A + B / e (perspective) or A + B * e (orthographic), then
  // the window depth the API stores.
  double a = facts.orthographic ? m.At(2, 3) : z_sign * m.At(2, 2);
  double b = facts.orthographic ? z_sign * m.At(2, 2) : m.At(2, 3);
  if (ClipsToMinusOne(given.api)) {
    a = (a + 1.0) / 2.0;
    b = b / 2.0;
  }
  DB_RETURN_IF_ERROR(DepthPlanes(a, b, facts.orthographic, facts));
  if (ClipsToMinusOne(given.api)) facts.convention = ConventionWithBits(Info(facts.convention).bits | catalog::kGl);
  return facts;
}

std::vector<std::string> ProjectionFacts::Describe() const {
  std::vector<std::string> lines;
  lines.push_back(fmt::format("{}, {}-handed view space (looking down {}z)",
                              orthographic ? "orthographic" : "perspective", left_handed ? "left" : "right",
                              left_handed ? "+" : "-"));
  const ConventionInfo& c = Info(convention);
  lines.push_back(fmt::format("depth convention {}: {}", c.name, c.description));
  lines.push_back(std::isinf(far) ? fmt::format("near {:g}, far plane at infinity", near)
                                  : fmt::format("near {:g}, far {:g} (far/near {:.4g})", near, far, far / near));
  if (orthographic) {
    lines.push_back(fmt::format("view volume x {:g} to {:g}, y {:g} to {:g}", left, right, bottom, top));
  } else {
    lines.push_back(fmt::format("field of view: left {:.4f}, right {:.4f}, up {:.4f}, down {:.4f} degrees "
                                "(vertical {:.4f}, aspect {:.4f})",
                                Degrees(left), Degrees(right), Degrees(top), Degrees(bottom),
                                Degrees(top) - Degrees(bottom), (right - left) / (top - bottom)));
  }
  if (off_centre()) {
    lines.push_back(fmt::format("off-centre: the frustum's centre is at ({:.6g}, {:.6g}) {} (a VR eye, a lens "
                                "shift, or a TAA jitter baked in); variants that assume a symmetric frustum are "
                                "wrong for it",
                                (left + right) / 2.0, (bottom + top) / 2.0,
                                orthographic ? "view units" : "at unit eye depth"));
  } else {
    lines.push_back(orthographic ? "view volume centred on the view axis" : "symmetric frustum");
  }
  if (y_flipped) lines.push_back("y flipped in clip space (as Vulkan engines flip it): mirrors the image, no precision change");
  return lines;
}

Status ApplyProjection(const ProjectionFacts& facts, Domain& domain) {
  domain.near = {facts.near, facts.near};
  domain.finite_far = std::isfinite(facts.far);
  domain.infinite_far = !domain.finite_far;
  if (domain.finite_far) domain.far = Range{facts.far, facts.far};
  if (facts.orthographic) {
    domain.eye_fov.reset();
    domain.orthographic = ViewVolume{facts.left, facts.right, facts.bottom, facts.top};
    return CheckViewVolume(*domain.orthographic, "projection matrix");
  }
  domain.orthographic.reset();
  domain.eye_fov = EyeFov{Degrees(facts.left), Degrees(facts.right), Degrees(facts.top), Degrees(facts.bottom)};
  return CheckEyeFov(*domain.eye_fov, "projection matrix");
}

Expected<ProjectionMatrix> ParseProjectionFlag(std::string_view text) {
  const auto usage = [&](std::string why) {
    return InvalidArgument(fmt::format("--projection: {}; expected API:LAYOUT:N0,...,N15 (API one of {}; LAYOUT "
                                       "column-major or row-major)",
                                       why, kGraphicsApiNames));
  };
  const std::size_t first = text.find(':');
  const std::size_t second = first == std::string_view::npos ? first : text.find(':', first + 1);
  if (second == std::string_view::npos) return usage(fmt::format("'{}' has no API and layout", text));
  ProjectionMatrix m;
  DB_RETURN_IF_ERROR(StoreInto(ParseGraphicsApi(text.substr(0, first)), m.api).WithContext("--projection"));
  DB_RETURN_IF_ERROR(
      StoreInto(ParseMatrixLayout(text.substr(first + 1, second - first - 1)), m.layout).WithContext("--projection"));
  std::size_t start = second + 1;
  for (int k = 0; k < 16; ++k) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    DB_ASSIGN_OR_RETURN(m.numbers[k], ParseNumber(text.substr(start, comma - start),
                                                  fmt::format("--projection: number {}", k)));
    if (k < 15 && comma == text.size()) return usage(fmt::format("it has {} numbers, not 16", k + 1));
    start = comma + 1;
  }
  if (start <= text.size()) return usage("it has more than 16 numbers");
  return m;
}

std::string ApiRecipe(Convention c) {
  const ConventionInfo& info = Info(c);
  if (!info.hardware) return "any API: a shader writes eye depth / far (or view z) to a colour target";
  const bool reversed = (info.bits & catalog::kRev) != 0u, infinite = (info.bits & catalog::kInf) != 0u;
  const std::string projection =
      fmt::format("{} projection that maps near to {}{}", info.orthographic() ? "an orthographic" : "a",
                  reversed ? "1 and far to 0" : "0 and far to 1", infinite ? ", with its far plane at infinity" : "");
  const std::string test = reversed ? ", depth test GREATER, depth cleared to 0" : ", depth test LESS, cleared to 1";
  if ((info.bits & catalog::kGl) != 0u) {
    return fmt::format("OpenGL without glClipControl (its default [-1, 1] clip depth), {}{}; Direct3D, Vulkan and "
                       "Metal always clip depth to [0, 1] and never store this",
                       projection, test);
  }
  return fmt::format("Direct3D, Vulkan, Metal: {}{}; OpenGL: the same after glClipControl(GL_LOWER_LEFT, "
                     "GL_ZERO_TO_ONE) (OpenGL 4.5 or ARB_clip_control), without which it gets {}",
                     projection, test, Info(ConventionWithBits(info.bits | catalog::kGl)).name);
}

}  // namespace depthbench
