#include "bench/pipeline/raster_model.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>

namespace depthbench {
namespace {

// The geometry is built in double: its corners only have to be good
// float32 values, and its checks hold a margin of a third of a pixel. Only
// the truth, the ray's meeting with the plane of the float corners, is
// worked out in long double. (In long double throughout, the x87 unit's
// arithmetic and the C library's long-double sine and cosine took nearly
// half of the build of a raster batch.)
using L = long double;
template <class T>
using Vec3 = glm::vec<3, T>;
using DVec2 = glm::dvec2;

// The pixel's ray at unit eye depth in view space (z = -1), through an
// off-centre lens too: from the pixel's centre in NDC (y up), as PixelRay
// takes it.
template <class T>
Vec3<T> PixelRayView(const Frame& frame, std::uint32_t x, std::uint32_t y) {
  const T ndc_x = (static_cast<T>(x) + T(0.5)) * T(2) / frame.width - T(1);
  const T ndc_y = T(1) - (static_cast<T>(y) + T(0.5)) * T(2) / frame.height;
  const T tan_y = frame.tan_half_fov_y, tan_x = static_cast<T>(frame.aspect) * tan_y;
  return {ndc_x * tan_x + frame.centre_x, ndc_y * tan_y + frame.centre_y, T(-1)};
}

template <class T>
Vec3<T> Rotate(const glm::dmat3& r, const Vec3<T>& v) {
  return Vec3<T>(r[0]) * v.x + Vec3<T>(r[1]) * v.y + Vec3<T>(r[2]) * v.z;
}
// The transpose: world directions into the camera's axes.
glm::dvec3 Unrotate(const glm::dmat3& r, const glm::dvec3& v) {
  return {glm::dot(r[0], v), glm::dot(r[1], v), glm::dot(r[2], v)};
}
template <class T>
glm::vec4 ToFloat4(const Vec3<T>& v, float w) {
  return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z), w};
}
template <class T>
Vec3<T> Xyz(const glm::vec4& v) {
  return {v.x, v.y, v.z};
}

// Where the exact camera puts world point q on the screen, in pixels (x
// right, y down), or nothing when q is not in front of the camera.
std::optional<DVec2> ExactScreen(const Frame& frame, const glm::dvec3& q) {
  const glm::dvec3 view = Unrotate(frame.rotation, q - frame.camera_position);
  if (!(view.z < 0.0)) return std::nullopt;
  const double tan_y = frame.tan_half_fov_y, tan_x = frame.aspect * tan_y;
  const double ndc_x = (view.x / -view.z - frame.centre_x) / tan_x, ndc_y = (view.y / -view.z - frame.centre_y) / tan_y;
  return DVec2((ndc_x + 1.0) * frame.width / 2.0, (1.0 - ndc_y) * frame.height / 2.0);
}

// Signed distance, in pixels, of p from the line a->b; positive on the
// left of a->b in a y-down frame for a clockwise-on-screen triangle.
double EdgeDistance(const DVec2& a, const DVec2& b, const DVec2& p) {
  const DVec2 e = b - a;
  return (e.x * (p.y - a.y) - e.y * (p.x - a.x)) / std::sqrt(e.x * e.x + e.y * e.y);
}

// Row `row` of GLSL's mat4 * vec4, in float32, one product and sum at a
// time in the order a shader compiler emits them (glm pairs the sums
// instead).
float TransformRow(const glm::mat4& m, const glm::vec4& v, int row) {
  float sum = m[0][row] * v.x;
  sum = sum + m[1][row] * v.y;
  sum = sum + m[2][row] * v.z;
  sum = sum + m[3][row] * v.w;
  return sum;
}
glm::vec4 Transform(const glm::mat4& m, const glm::vec4& v) {
  glm::vec4 out;
  for (int row = 0; row < 4; ++row) out[row] = TransformRow(m, v, row);
  return out;
}

// A vertex after the vertex stage.
using ScreenVertex = RasterTexelModel::ScreenVertex;
ScreenVertex ToScreen(const glm::vec4& clip, const f32::FrameParams& frame) {
  const double x = static_cast<double>(clip.x) / clip.w, y = static_cast<double>(clip.y) / clip.w;
  return {{(x + 1.0) * frame.resolution.x / 2.0, (1.0 - y) * frame.resolution.y / 2.0}, clip.w};
}

// Whether two matrices put every point at the same clip x, y and w.
bool SameScreenRows(const glm::mat4& a, const glm::mat4& b) {
  for (int column = 0; column < 4; ++column) {
    for (int row : {0, 1, 3}) {
      if (std::bit_cast<std::uint32_t>(a[column][row]) != std::bit_cast<std::uint32_t>(b[column][row])) return false;
    }
  }
  return true;
}

// Screen-space barycentrics of p in the triangle, or nothing when p lies
// outside it (or the triangle has no area).
std::optional<glm::dvec3> Barycentrics(const std::array<ScreenVertex, 3>& v, const glm::dvec2& p) {
  const auto cross = [](const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  };
  const double area = cross(v[0].screen, v[1].screen, v[2].screen);
  if (area == 0.0 || !std::isfinite(area)) return std::nullopt;
  const glm::dvec3 b(cross(p, v[1].screen, v[2].screen) / area, cross(v[0].screen, p, v[2].screen) / area,
                     cross(v[0].screen, v[1].screen, p) / area);
  if (b.x < 0.0 || b.y < 0.0 || b.z < 0.0) return std::nullopt;
  return b;
}

// The attribute at barycentrics b, interpolated exactly: linearly in
// screen space, or perspective-correctly (weights b_k / w_k).
template <class T>
T Interpolate(const std::array<ScreenVertex, 3>& v, const glm::dvec3& b, const std::array<T, 3>& values,
              bool perspective) {
  glm::dvec3 weight = b;
  if (perspective) {
    weight = glm::dvec3(b.x / v[0].w, b.y / v[1].w, b.z / v[2].w);
    weight /= weight.x + weight.y + weight.z;
  }
  return values[0] * weight.x + values[1] * weight.y + values[2] * weight.z;
}

glm::dvec2 PixelCentre(std::uint32_t x, std::uint32_t y) { return {x + 0.5, y + 0.5}; }

bool HasGeometry(const f32::RasterSample& g) { return g.triangle0.w != 0.0f; }

// An angle by its cosine and sine.
struct UnitAngle {
  double cos, sin;
  UnitAngle Plus(const UnitAngle& o) const { return {cos * o.cos - sin * o.sin, sin * o.cos + cos * o.sin}; }
};
// 0, 1/3 and 2/3 of a turn.
constexpr double kSinThird = 0.866025403784438646763723170752936183;  // sqrt(3) / 2
constexpr std::array<UnitAngle, 3> kThirdTurns = {{{1.0, 0.0}, {-0.5, kSinThird}, {-0.5, -kSinThird}}};

// The angle of `turns` (in [0, 1)) of a full turn. The C library reduces an
// argument past pi/4 with a long remainder of pi/2; here the reduction is
// exact in the turns (multiplying by 8 and taking off whole eighths loses
// no bit), so only angles within [0, pi/4] reach sin and cos.
UnitAngle TurnOf(double turns) {
  const double eighths = turns * 8.0;
  const int octant = static_cast<int>(eighths);  // 0 to 7
  const double within = eighths - octant;        // [0, 1): of the octant, exactly
  // From the octant's start, or back from its end on the odd ones, so the
  // argument stays within [0, pi/4]:
  const bool odd = (octant & 1) != 0;
  const double angle = (odd ? 1.0 - within : within) * (std::numbers::pi / 4.0);
  const double c = std::cos(angle), s = std::sin(angle);
  // The octant's quarter turns, and the mirror of an odd octant in its
  // quarter's diagonal.
  const UnitAngle in_quarter = odd ? UnitAngle{s, c} : UnitAngle{c, s};
  switch (octant / 2) {
    case 0: return in_quarter;
    case 1: return {-in_quarter.sin, in_quarter.cos};
    case 2: return {-in_quarter.cos, -in_quarter.sin};
    default: return {in_quarter.sin, -in_quarter.cos};
  }
}

// The twelve triangles of the cube around `volume`, as corner indices
// (bit 0: +x, bit 1: +y, bit 2: +z), two per face; the face's outward axis
// is `axis` with sign `positive`.
struct CubeFace {
  int axis;
  bool positive;
  std::array<int, 4> corners;  // around the face
};
constexpr std::array<CubeFace, 6> kCubeFaces = {{
    {0, false, {0, 2, 6, 4}},
    {0, true, {1, 5, 7, 3}},
    {1, false, {0, 4, 5, 1}},
    {1, true, {2, 3, 7, 6}},
    {2, false, {0, 1, 3, 2}},
    {2, true, {4, 6, 7, 5}},
}};

// A cube corner as the vertex shader computes it: centre +- half in float32.
glm::vec4 CubeCorner(const glm::vec4& volume, int corner) {
  const float h = volume.w;
  return {(corner & 1) != 0 ? volume.x + h : volume.x - h, (corner & 2) != 0 ? volume.y + h : volume.y - h,
          (corner & 4) != 0 ? volume.z + h : volume.z - h, 1.0f};
}

}  // namespace

RasterGeometry MakeRasterGeometry(const Frame& frame, const PixelSample& sample) {
  RasterGeometry out;
  if (sample.pick != DepthPick::kEyeDepth) return out;
  const double d = sample.eye_depth;
  const double tan_y = frame.tan_half_fov_y, tan_x = frame.aspect * tan_y;
  const glm::dvec3 centre_view = PixelRayView<double>(frame, sample.x, sample.y) * d;
  // One pixel in view units at this depth, along x and (screen y down) y.
  const double pixel_x = 2.0 * tan_x * d / frame.width, pixel_y = 2.0 * tan_y * d / frame.height;
  // An equilateral triangle whose inscribed circle is centred on the pixel
  // centre; its orientation turns from sample to sample, by the golden
  // ratio's fraction of a turn (that fraction in long double: a sample's
  // index takes some 30 of its bits).
  const auto turns = static_cast<double>(std::fmod(static_cast<L>(sample.index) * 0.6180339887498948482L, 1.0L));
  const UnitAngle first = TurnOf(turns);
  std::array<glm::vec4, 3> corners;
  for (int k = 0; k < 3; ++k) {
    const UnitAngle corner = first.Plus(kThirdTurns[k]);
    const double dx = 2.0 * kTriangleInradius * corner.cos, dy = 2.0 * kTriangleInradius * corner.sin;
    const glm::dvec3 view = centre_view + glm::dvec3(dx * pixel_x, -dy * pixel_y, 0.0);
    corners[k] = ToFloat4(frame.camera_position + Rotate(frame.rotation, view), 1.0f);
  }

  // The float corners must still hold the pixel centre well inside, seen
  // by the exact camera (a device's float32 matrix moves them by about
  // 2^-24 of the screen more, far below the margin).
  std::array<DVec2, 3> screen;
  for (int k = 0; k < 3; ++k) {
    const auto s = ExactScreen(frame, Xyz<double>(corners[k]));
    if (!s) return out;
    screen[k] = *s;
  }
  const DVec2 centre(sample.x + 0.5, sample.y + 0.5);
  const double orientation = EdgeDistance(screen[0], screen[1], screen[2]) > 0.0 ? 1.0 : -1.0;
  for (int k = 0; k < 3; ++k) {
    const double inside = orientation * EdgeDistance(screen[k], screen[(k + 1) % 3], centre);
    if (!(inside > 0.5 * kTriangleInradius)) return out;
  }

  // The truth: the pixel's ray meets the plane of the float corners, in
  // long double (the corners' differences are exact; the products and
  // sums keep 11 bits more than double's).
  const Vec3<L> camera(frame.camera_position);
  const Vec3<L> ray = Rotate(frame.rotation, PixelRayView<L>(frame, sample.x, sample.y));
  const Vec3<L> c0 = Xyz<L>(corners[0]);
  const Vec3<L> normal = glm::cross(Xyz<L>(corners[1]) - c0, Xyz<L>(corners[2]) - c0);
  const L t = glm::dot(normal, c0 - camera) / glm::dot(normal, ray);
  if (!(t > 0.0L) || !std::isfinite(static_cast<double>(t))) return out;

  // The light volume: its centre must stay well inside around the ray too
  // (within half its half edge of the ray), or what the device covers is
  // not predictable either.
  const Vec3<L> point = camera + ray * t;
  const glm::vec4 volume = ToFloat4(point, static_cast<float>(d / 4.0));
  const glm::dvec3 off = Xyz<double>(volume) - frame.camera_position;
  const glm::dvec3 ray_world(ray);
  const double along = glm::dot(off, ray_world) / glm::dot(ray_world, ray_world);
  if (glm::length(off - ray_world * along) > 0.5 * volume.w) return out;

  out.sample = {corners[0], corners[1], corners[2], volume};
  out.rendered_depth = static_cast<double>(t);
  return out;
}

float RasterPipelineFloat(Encoding encoding, const f32::FrameParams& frame_params,
                          const f32::DepthParams& depth, std::uint32_t pixel_x, std::uint32_t pixel_y,
                          const f32::RasterSample& geometry) {
  return RasterTexelModel(frame_params, pixel_x, pixel_y, geometry).Value(encoding, depth);
}

RasterTexelModel::RasterTexelModel(const f32::FrameParams& frame_params, std::uint32_t pixel_x, std::uint32_t pixel_y,
                                   const f32::RasterSample& geometry)
    : frame_params_(frame_params),
      pixel_x_(pixel_x),
      pixel_y_(pixel_y),
      corners_{geometry.triangle0, geometry.triangle1, geometry.triangle2},
      has_geometry_(HasGeometry(geometry)) {}

float RasterTexelModel::Value(Encoding encoding, const f32::DepthParams& depth) {
  constexpr float kNothing = std::numeric_limits<float>::quiet_NaN();
  if (!has_geometry_) return kNothing;
  if (!screen_of_ || !SameScreenRows(*screen_of_, depth.view_projection)) {
    for (int k = 0; k < 3; ++k) vertices_[k] = ToScreen(Transform(depth.view_projection, corners_[k]), frame_params_);
    barycentrics_ = Barycentrics(vertices_, PixelCentre(pixel_x_, pixel_y_));
    screen_of_ = depth.view_projection;
    view_z_.reset();
  }
  if (!barycentrics_) return kNothing;
  const DepthInput stores = Info(encoding.format).stores;
  if (stores == DepthInput::kHardware) {
    const bool gl_clip = (Info(encoding.convention).bits & f32::DB_CONVENTION_CLIP_MINUS_ONE) != 0u;
    std::array<double, 3> window_z;
    for (int k = 0; k < 3; ++k) {
      const float ndc_z = TransformRow(depth.view_projection, corners_[k], 2) / static_cast<float>(vertices_[k].w);
      window_z[k] = gl_clip ? ndc_z * 0.5f + 0.5f : ndc_z;
    }
    return static_cast<float>(Interpolate(vertices_, *barycentrics_, window_z, false));
  }
  if (!view_z_) {
    std::array<double, 3> view_z;
    for (int k = 0; k < 3; ++k) view_z[k] = TransformRow(frame_params_.world_view, corners_[k], 2);
    view_z_ = Interpolate(vertices_, *barycentrics_, view_z, true);
  }
  const auto z = static_cast<float>(*view_z_);
  return stores == DepthInput::kLinear ? -z / frame_params_.camera_position.w : z;
}

f32::FrameParams RasterFrameParams(const f32::FrameParams& frame_params,
                                   const f32::DepthParams& standard_depth, std::uint32_t pixel_x,
                                   std::uint32_t pixel_y, const f32::RasterSample& geometry) {
  f32::FrameParams out = frame_params;
  const glm::dvec2 centre = PixelCentre(pixel_x, pixel_y);
  const glm::vec4 zero(0.0f);
  // The full-screen triangle: vertices at uv (0,0), (2,0), (0,2), that is
  // screen (0,0), (2W,0), (0,2H), with w = 1.
  const double width = frame_params.resolution.x, height = frame_params.resolution.y;
  const std::array<ScreenVertex, 3> screen_triangle = {ScreenVertex{{0.0, 0.0}, 1.0},
                                                       ScreenVertex{{2.0 * width, 0.0}, 1.0},
                                                       ScreenVertex{{0.0, 2.0 * height}, 1.0}};
  const glm::dvec3 b(1.0 - centre.x / (2.0 * width) - centre.y / (2.0 * height), centre.x / (2.0 * width),
                     centre.y / (2.0 * height));
  const auto interpolate = [&](glm::vec4& origin, glm::vec4& du, glm::vec4& dv) {
    std::array<glm::dvec3, 3> at;
    const std::array<glm::vec2, 3> uvs = {glm::vec2(0.0f, 0.0f), glm::vec2(2.0f, 0.0f), glm::vec2(0.0f, 2.0f)};
    for (int k = 0; k < 3; ++k) {
      // screen.h's interpolate_screen_attribute, in float32, at the vertex.
      const glm::vec3 value =
          glm::vec3(origin) + glm::vec3(du) * uvs[k].x + glm::vec3(dv) * uvs[k].y;
      at[k] = glm::dvec3(value);
    }
    origin = glm::vec4(glm::vec3(Interpolate(screen_triangle, b, at, false)), origin.w);
    du = dv = zero;
  };
  interpolate(out.frustum_ray_origin, out.frustum_ray_du, out.frustum_ray_dv);
  interpolate(out.eye_ray_view_origin, out.eye_ray_view_du, out.eye_ray_view_dv);
  interpolate(out.eye_ray_world_origin, out.eye_ray_world_du, out.eye_ray_world_dv);

  // The light volume: the back face that covers the pixel centre.
  if (!HasGeometry(geometry)) return out;
  const glm::dvec3 camera(glm::vec3(frame_params.camera_position));
  for (const CubeFace& face : kCubeFaces) {
    // A back face has the camera on the cube's side of its plane.
    const double plane = geometry.volume[face.axis] + (face.positive ? 1.0 : -1.0) * geometry.volume.w;
    const bool back = face.positive ? camera[face.axis] < plane : camera[face.axis] > plane;
    if (!back) continue;
    for (int half = 0; half < 2; ++half) {
      const std::array<int, 3> tri = {face.corners[0], face.corners[1 + half], face.corners[2 + half]};
      std::array<ScreenVertex, 3> vertices;
      std::array<glm::dvec3, 3> view;
      for (int k = 0; k < 3; ++k) {
        const glm::vec4 corner = CubeCorner(geometry.volume, tri[k]);
        vertices[k] = ToScreen(Transform(standard_depth.view_projection, corner), frame_params);
        view[k] = glm::dvec3(glm::vec3(Transform(frame_params.world_view, corner)));
      }
      const auto weights = Barycentrics(vertices, centre);
      if (!weights) continue;
      out.volume_position_origin = glm::vec4(glm::vec3(Interpolate(vertices, *weights, view, true)), 0.0f);
      out.volume_position_du = out.volume_position_dv = zero;
      return out;
    }
  }
  return out;
}

void RasterAgreement::Merge(const RasterAgreement& other) {
  texels += other.texels;
  differing += other.differing;
  uncovered += other.uncovered;
  max_code_distance = std::max(max_code_distance, other.max_code_distance);
}

}  // namespace depthbench
