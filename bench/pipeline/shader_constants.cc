#include "bench/pipeline/shader_constants.h"

namespace depthbench {
namespace {

using DD = DoubleDouble;

// The formulas below are written once for a `Real` that is DoubleDouble
// (the exact constants: every conversion from double exact) or float (the
// engine's: every conversion rounds, every operation rounds).
template <class Real>
glm::vec<3, Real> Rotate(const glm::dmat3& r, const glm::vec<3, Real>& v) {
  glm::vec<3, Real> out;
  for (int row = 0; row < 3; ++row) {
    out[row] = Real(r[0][row]) * v.x + Real(r[1][row]) * v.y + Real(r[2][row]) * v.z;
  }
  return out;
}

template <class Real>
glm::vec<4, Real> Vec4(const glm::vec<3, Real>& v, Real w = Real(0.0)) {
  return glm::vec<4, Real>(v.x, v.y, v.z, w);
}

// The three corner values of an attribute that is `at(ndc)` at NDC point ndc
// and linear in it: its value at uv (0, 0) and its steps along u and v.
template <class Real, class At>
void ScreenAttribute(At at, glm::vec<4, Real>& origin, glm::vec<4, Real>& du, glm::vec<4, Real>& dv) {
  const glm::vec<3, Real> top_left = at(Real(-1.0), Real(1.0));
  const glm::vec<3, Real> top_right = at(Real(1.0), Real(1.0));
  const glm::vec<3, Real> bottom_left = at(Real(-1.0), Real(-1.0));
  origin = Vec4(top_left);
  du = Vec4<Real>(top_right - top_left);
  dv = Vec4<Real>(bottom_left - top_left);
}

// FrameParams (hp:: or f32::) from the frame's parameters, in that
// instantiation's arithmetic.
template <class Params>
Params FrameParamsIn(const Frame& frame) {
  using Real = typename decltype(Params::lens)::value_type;
  using Vec3 = glm::vec<3, Real>;
  using Vec4 = glm::vec<4, Real>;
  const Real tan_y(frame.tan_half_fov_y);
  const Real tan_x = Real(frame.aspect) * tan_y;
  const Real far = frame.finite() ? Real(frame.far) : Real(0.0);
  const glm::dmat3& r = frame.rotation;
  const glm::dvec3& c = frame.camera_position;

  Params p;
  for (int col = 0; col < 3; ++col) {
    p.camera_world[col] = Vec4(Real(r[col][0]), Real(r[col][1]), Real(r[col][2]), Real(0.0));
  }
  p.camera_world[3] = Vec4(Real(c.x), Real(c.y), Real(c.z), Real(1.0));
  p.camera_position = Vec4(Real(c.x), Real(c.y), Real(c.z), far);
  // The view matrix: the transposed rotation, and -dot(axis, eye) per row.
  for (int axis = 0; axis < 3; ++axis) {
    for (int k = 0; k < 3; ++k) p.world_view[k][axis] = Real(r[axis][k]);
    p.world_view[3][axis] =
        -(Real(r[axis][0]) * Real(c.x) + Real(r[axis][1]) * Real(c.y) + Real(r[axis][2]) * Real(c.z));
    p.world_view[axis][3] = Real(0.0);
  }
  p.world_view[3][3] = Real(1.0);
  p.lens = Vec4(tan_x, tan_y, Real(1.0) / tan_x, Real(1.0) / tan_y);
  p.resolution =
      Vec4(Real(frame.width), Real(frame.height), Real(1.0) / Real(frame.width), Real(1.0) / Real(frame.height));

  // View-space point of the pixel ray at eye depth `depth`.
  auto view_at = [&](Real depth) {
    return [=](Real ndc_x, Real ndc_y) { return Vec3(ndc_x * tan_x * depth, ndc_y * tan_y * depth, -depth); };
  };
  // Pettineo 2009: far-plane corners rotated to world space.
  ScreenAttribute<Real>([&](Real x, Real y) { return Rotate(r, view_at(far)(x, y)); }, p.frustum_ray_origin,
                        p.frustum_ray_du, p.frustum_ray_dv);
  // Pettineo 2009, light volume: the surface's view-space position.
  ScreenAttribute<Real>(view_at(Real(frame.volume_depth)), p.volume_position_origin, p.volume_position_du,
                        p.volume_position_dv);
  // The eye-ray post 2011: the eye ray at w = 1 in view space and rotated to world space.
  ScreenAttribute<Real>(view_at(Real(1.0)), p.eye_ray_view_origin, p.eye_ray_view_du, p.eye_ray_view_dv);
  ScreenAttribute<Real>([&](Real x, Real y) { return Rotate(r, view_at(Real(1.0))(x, y)); }, p.eye_ray_world_origin,
                        p.eye_ray_world_du, p.eye_ray_world_dv);
  return p;
}

float Round(DD x) { return RoundToFloat(x); }
glm::vec4 Round(const hp::vec4& v) { return {Round(v.x), Round(v.y), Round(v.z), Round(v.w)}; }
glm::mat4 Round(const hp::mat4& m) { return glm::mat4(Round(m[0]), Round(m[1]), Round(m[2]), Round(m[3])); }

bool HasConstants(const Frame& frame, Convention convention) {
  // Conventions with a finite far plane have no constants on frames that
  // have none (infinite-only domains).
  return frame.finite() || (Info(convention).bits & f32::DB_CONVENTION_INFINITE) != 0u;
}

}  // namespace

hp::FrameParams BuildFrameParams(const Frame& frame) { return FrameParamsIn<hp::FrameParams>(frame); }

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
  // (ndc.x, ndc.y, ndc_z, 1) -> (ndc.x/H, ndc.y/V, -1, (ndc_z - A)/B), whose
  // columns are (1/H, 0, 0, 0), (0, 1/V, 0, 0), (0, 0, 0, P), (0, 0, -1, Q).
  // Both products below are written out over the sparse matrix's nonzero
  // entries, in the order glm's full product adds them (left to right, the
  // left matrix's entry first): adding a zero product is exact, so every
  // entry equals the full product's, at a fifth of the cost (this runs for
  // every frame and convention). tests/constants_test.cc holds them equal.
  const hp::mat4& cw = f.camera_world;
  d.inverse_view_projection[0] = cw[0] * f.lens.x;  // 1/H = tan_x
  d.inverse_view_projection[1] = cw[1] * f.lens.y;  // 1/V = tan_y
  d.inverse_view_projection[2] = cw[3] * d.coefficients.z;
  d.inverse_view_projection[3] = cw[2] * DD(-1.0) + cw[3] * d.coefficients.w;
  // The projection (EngineProjectionMatrix's layout: columns (H, 0, 0, 0),
  // (0, V, 0, 0), (0, 0, -A, -1), (0, 0, B, 0)) times the view.
  const DD minus_a = -a, minus_one(-1.0);
  for (int c = 0; c < 4; ++c) {
    const hp::vec4& v = f.world_view[c];
    d.view_projection[c] = hp::vec4(f.lens.z * v.x, f.lens.w * v.y, minus_a * v.z + b * v.w, minus_one * v.z);
  }
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
  o.world_view = Round(p.world_view);
  return o;
}

f32::DepthParams RoundToFloat(const hp::DepthParams& p) {
  f32::DepthParams o;
  o.inverse_view_projection = Round(p.inverse_view_projection);
  o.view_projection = Round(p.view_projection);
  o.coefficients = Round(p.coefficients);
  o.convention = p.convention;
  o.reserved0 = o.reserved1 = o.reserved2 = 0;
  return o;
}

glm::mat4 EngineViewMatrix(const Frame& frame) {
  // The inverse of the camera's rigid transform, as glm::lookAt builds it:
  // the transposed rotation and -dot(axis, eye) per row, in float32.
  const glm::mat3 r(frame.rotation);
  const glm::vec3 eye(frame.camera_position);
  glm::mat4 view(1.0f);
  for (int axis = 0; axis < 3; ++axis) {
    for (int k = 0; k < 3; ++k) view[k][axis] = r[axis][k];
    view[3][axis] = -glm::dot(r[axis], eye);
  }
  return view;
}

glm::mat4 EngineProjectionMatrix(const Frame& frame, Convention convention) {
  // glm::perspective's layout (right-handed, w = -view.z) with the depth
  // row of the convention: clip z = -A * view.z + B.
  const float tan_y = static_cast<float>(frame.tan_half_fov_y);
  const float tan_x = static_cast<float>(frame.aspect) * tan_y;
  const float far = frame.finite() ? static_cast<float>(frame.far) : 0.0f;
  const glm::vec2 ab = f32::ndc_depth_coefficients(static_cast<float>(frame.near), far, Info(convention).bits);
  glm::mat4 projection(0.0f);
  projection[0][0] = 1.0f / tan_x;
  projection[1][1] = 1.0f / tan_y;
  projection[2][2] = -ab.x;
  projection[2][3] = -1.0f;
  projection[3][2] = ab.y;
  return projection;
}

f32::FrameParams EngineFrameParams(const Frame& frame) {
  f32::FrameParams p = FrameParamsIn<f32::FrameParams>(frame);
  p.world_view = EngineViewMatrix(frame);
  return p;
}

f32::DepthParams EngineDepthParams(const Frame& frame, Convention convention) {
  const glm::mat4 projection = EngineProjectionMatrix(frame, convention);
  const float a = -projection[2][2], b = projection[3][2];
  f32::DepthParams d;
  d.view_projection = projection * EngineViewMatrix(frame);
  d.inverse_view_projection = glm::inverse(d.view_projection);
  d.coefficients = glm::vec4(a, b, 1.0f / b, -a / b);
  d.convention = Info(convention).bits;
  d.reserved0 = d.reserved1 = d.reserved2 = 0;
  return d;
}

void BuildShaderConstants(const Frame& frame, ConstantsModel model, f32::FrameParams& frame_params,
                          std::span<f32::DepthParams, kHardwareConventionCount> depth_params) {
  const bool exact = model == ConstantsModel::kExact;
  const hp::FrameParams exact_params = exact ? BuildFrameParams(frame) : hp::FrameParams{};
  frame_params = exact ? RoundToFloat(exact_params) : EngineFrameParams(frame);
  for (int c = 0; c < kHardwareConventionCount; ++c) {
    const auto convention = static_cast<Convention>(c);
    depth_params[c] = !HasConstants(frame, convention) ? f32::DepthParams{}
                      : exact                          ? RoundToFloat(BuildDepthParams(frame, exact_params, convention))
                                                       : EngineDepthParams(frame, convention);
  }
}

}  // namespace depthbench
