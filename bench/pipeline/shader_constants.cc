#include "bench/pipeline/shader_constants.h"

namespace depthbench {
namespace {

using DD = DoubleDouble;

hp::vec3 Rotate(const glm::dmat3& r, const hp::vec3& v) {
  hp::vec3 out;
  for (int row = 0; row < 3; ++row) {
    out[row] = DD(r[0][row]) * v.x + DD(r[1][row]) * v.y + DD(r[2][row]) * v.z;
  }
  return out;
}

hp::vec4 Vec4(const hp::vec3& v, DD w = DD(0.0)) { return hp::vec4(v.x, v.y, v.z, w); }

// The three corner values of an attribute that is `at(ndc)` at NDC point ndc
// and linear in it: its value at uv (0, 0) and its steps along u and v.
template <class At>
void ScreenAttribute(At at, hp::vec4& origin, hp::vec4& du, hp::vec4& dv) {
  hp::vec3 top_left = at(DD(-1.0), DD(1.0));
  hp::vec3 top_right = at(DD(1.0), DD(1.0));
  hp::vec3 bottom_left = at(DD(-1.0), DD(-1.0));
  origin = Vec4(top_left);
  du = Vec4(top_right - top_left);
  dv = Vec4(bottom_left - top_left);
}

float Round(DD x) { return RoundToFloat(x); }
glm::vec4 Round(const hp::vec4& v) { return {Round(v.x), Round(v.y), Round(v.z), Round(v.w)}; }
glm::mat4 Round(const hp::mat4& m) { return glm::mat4(Round(m[0]), Round(m[1]), Round(m[2]), Round(m[3])); }

}  // namespace

hp::FrameParams BuildFrameParams(const Frame& frame) {
  const DD tan_y(frame.tan_half_fov_y);
  const DD tan_x = DD(frame.aspect) * tan_y;
  const DD far = frame.finite() ? DD(frame.far) : DD(0.0);
  const glm::dmat3& r = frame.rotation;
  const glm::dvec3& c = frame.camera_position;

  hp::FrameParams p;
  for (int col = 0; col < 3; ++col) {
    p.camera_world[col] = hp::vec4(DD(r[col][0]), DD(r[col][1]), DD(r[col][2]), DD(0.0));
  }
  p.camera_world[3] = hp::vec4(DD(c.x), DD(c.y), DD(c.z), DD(1.0));
  p.camera_position = hp::vec4(DD(c.x), DD(c.y), DD(c.z), far);
  p.lens = hp::vec4(tan_x, tan_y, DD(1.0) / tan_x, DD(1.0) / tan_y);
  p.resolution = hp::vec4(DD(frame.width), DD(frame.height), DD(1.0) / DD(frame.width), DD(1.0) / DD(frame.height));

  // View-space point of the pixel ray at eye depth `depth`.
  auto view_at = [&](DD depth) {
    return [=](DD ndc_x, DD ndc_y) { return hp::vec3(ndc_x * tan_x * depth, ndc_y * tan_y * depth, -depth); };
  };
  // Pettineo 2009: far-plane corners rotated to world space.
  ScreenAttribute([&](DD x, DD y) { return Rotate(r, view_at(far)(x, y)); }, p.frustum_ray_origin, p.frustum_ray_du,
                  p.frustum_ray_dv);
  // Pettineo 2009, light volume: the surface's view-space position.
  ScreenAttribute(view_at(DD(frame.volume_depth)), p.volume_position_origin, p.volume_position_du,
                  p.volume_position_dv);
  // The eye-ray post 2011: the eye ray at w = 1 in view space and rotated to world space.
  ScreenAttribute(view_at(DD(1.0)), p.eye_ray_view_origin, p.eye_ray_view_du, p.eye_ray_view_dv);
  ScreenAttribute([&](DD x, DD y) { return Rotate(r, view_at(DD(1.0))(x, y)); }, p.eye_ray_world_origin,
                  p.eye_ray_world_du, p.eye_ray_world_dv);
  return p;
}

hp::DepthParams BuildDepthParams(const Frame& frame, const hp::FrameParams& f, Convention convention) {
  const ConventionInfo& info = Info(convention);
  const DD near(frame.near);
  const DD far = frame.finite() ? DD(frame.far) : DD(0.0);
  hp::vec2 ab = hp::ndc_depth_coefficients(near, far, info.bits);
  const DD a = ab.x, b = ab.y;

  hp::DepthParams d;
  d.coefficients = hp::vec4(a, b, DD(1.0) / b, -a / b);
  d.convention = info.bits;
  d.reserved0 = d.reserved1 = d.reserved2 = 0;

  // Inverse projection for view = (x/H, y/V, -1) * z and ndc_z = A + B/z:
  // (ndc.x, ndc.y, ndc_z, 1) -> (ndc.x/H, ndc.y/V, -1, (ndc_z - A)/B).
  const DD zero(0.0);
  hp::mat4 inverse_projection;
  inverse_projection[0] = hp::vec4(f.lens.x, zero, zero, zero);  // 1/H = tan_x
  inverse_projection[1] = hp::vec4(zero, f.lens.y, zero, zero);  // 1/V = tan_y
  inverse_projection[2] = hp::vec4(zero, zero, zero, d.coefficients.z);
  inverse_projection[3] = hp::vec4(zero, zero, DD(-1.0), d.coefficients.w);
  d.inverse_view_projection = f.camera_world * inverse_projection;
  return d;
}

f32::FrameParams RoundToFloat(const hp::FrameParams& p) {
  f32::FrameParams o;
  o.camera_world = Round(p.camera_world);
  o.camera_position = Round(p.camera_position);
  o.lens = Round(p.lens);
  o.resolution = Round(p.resolution);
  o.frustum_ray_origin = Round(p.frustum_ray_origin);
  o.frustum_ray_du = Round(p.frustum_ray_du);
  o.frustum_ray_dv = Round(p.frustum_ray_dv);
  o.volume_position_origin = Round(p.volume_position_origin);
  o.volume_position_du = Round(p.volume_position_du);
  o.volume_position_dv = Round(p.volume_position_dv);
  o.eye_ray_view_origin = Round(p.eye_ray_view_origin);
  o.eye_ray_view_du = Round(p.eye_ray_view_du);
  o.eye_ray_view_dv = Round(p.eye_ray_view_dv);
  o.eye_ray_world_origin = Round(p.eye_ray_world_origin);
  o.eye_ray_world_du = Round(p.eye_ray_world_du);
  o.eye_ray_world_dv = Round(p.eye_ray_world_dv);
  return o;
}

f32::DepthParams RoundToFloat(const hp::DepthParams& p) {
  f32::DepthParams o;
  o.inverse_view_projection = Round(p.inverse_view_projection);
  o.coefficients = Round(p.coefficients);
  o.convention = p.convention;
  o.reserved0 = o.reserved1 = o.reserved2 = 0;
  return o;
}

}  // namespace depthbench
