#include "bench/pipeline/shader_constants.h"

#include <algorithm>
#include <array>

namespace depthbench {
namespace {

using DD = DoubleDouble;
using DD4 = DoubleDouble4;

// The formulas below are written once for a `Real` that is DoubleDouble
// (the exact constants: every conversion from double exact), DoubleDouble4
// (the same for four frames, one per lane: the arithmetic is branch-free, so
// each lane computes what DoubleDouble computes) or float (the engine's:
// every conversion rounds, every operation rounds).
template <class Params>
using RealOf = typename decltype(Params::lens)::value_type;

// The one list of those parameters: lift(get) is the Real that holds
// get(frame) of the frame, or of each lane's frame.
template <class Real, class Lift>
FrameValues<Real> LiftFrameValues(Lift lift) {
  FrameValues<Real> v;
  v.tan_half_fov_y = lift([](const Frame& f) { return f.tan_half_fov_y; });
  v.aspect = lift([](const Frame& f) { return f.aspect; });
  v.centre_x = lift([](const Frame& f) { return f.centre_x; });
  v.centre_y = lift([](const Frame& f) { return f.centre_y; });
  v.near = lift([](const Frame& f) { return f.near; });
  v.far = lift([](const Frame& f) { return f.finite() ? f.far : 0.0; });
  v.volume_depth = lift([](const Frame& f) { return f.volume_depth; });
  v.width = lift([](const Frame& f) { return f.width; });
  v.height = lift([](const Frame& f) { return f.height; });
  for (int k = 0; k < 3; ++k) v.camera_position[k] = lift([k](const Frame& f) { return f.camera_position[k]; });
  for (int col = 0; col < 3; ++col) {
    for (int row = 0; row < 3; ++row) {
      v.rotation[col][row] = lift([col, row](const Frame& f) { return f.rotation[col][row]; });
    }
  }
  return v;
}

template <class Real>
FrameValues<Real> ValuesOf(const Frame& frame) {
  return LiftFrameValues<Real>([&](auto get) { return Real(get(frame)); });
}

// Lane k holds *frames[k]; every conversion to double is exact. The zero
// added is the one DoubleDouble's constructor adds as it broadcasts: it
// turns a -0 (a camera coordinate at the origin) into +0, and each lane
// must hold what DoubleDouble(value) holds.
FrameValues<DD4> ValuesOf(const std::array<const Frame*, 4>& frames) {
  return LiftFrameValues<DD4>([&](auto get) {
    Double4 lanes;
    for (int k = 0; k < 4; ++k) lanes[k] = get(*frames[k]);
    return DD4::FromParts(lanes + 0.0, Double4{});
  });
}

template <class Real>
glm::vec<3, Real> Rotate(const glm::mat<3, 3, Real>& r, const glm::vec<3, Real>& v) {
  glm::vec<3, Real> out;
  for (int row = 0; row < 3; ++row) out[row] = r[0][row] * v.x + r[1][row] * v.y + r[2][row] * v.z;
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

// FrameParams (hp::, hp4:: or f32::) from the frame's parameters, in that
// instantiation's arithmetic.
template <class Params>
Params FrameParamsIn(const FrameValues<RealOf<Params>>& frame) {
  using Real = RealOf<Params>;
  using Vec3 = glm::vec<3, Real>;
  using Vec4 = glm::vec<4, Real>;
  const Real tan_y = frame.tan_half_fov_y;
  const Real tan_x = frame.aspect * tan_y;
  const Real far = frame.far;
  const glm::mat<3, 3, Real>& r = frame.rotation;
  const Vec3& c = frame.camera_position;

  Params p;
  for (int col = 0; col < 3; ++col) p.camera_world[col] = Vec4(r[col][0], r[col][1], r[col][2], Real(0.0));
  p.camera_world[3] = Vec4(c.x, c.y, c.z, Real(1.0));
  p.camera_position = Vec4(c.x, c.y, c.z, far);
  // The view matrix: the transposed rotation, and -dot(axis, eye) per row.
  for (int axis = 0; axis < 3; ++axis) {
    for (int k = 0; k < 3; ++k) p.world_view[k][axis] = r[axis][k];
    p.world_view[3][axis] = -(r[axis][0] * c.x + r[axis][1] * c.y + r[axis][2] * c.z);
    p.world_view[axis][3] = Real(0.0);
  }
  p.world_view[3][3] = Real(1.0);
  p.lens = Vec4(tan_x, tan_y, Real(1.0) / tan_x, Real(1.0) / tan_y);
  const Real cx = frame.centre_x, cy = frame.centre_y;
  p.lens_centre = Vec4(cx, cy, cx * p.lens.z, cy * p.lens.w);
  p.resolution = Vec4(frame.width, frame.height, Real(1.0) / frame.width, Real(1.0) / frame.height);
  p.clip_planes = Vec4(frame.near, far, Real(0.0), Real(0.0));

  // View-space point of the pixel ray at eye depth `depth` (a centred lens
  // adds zeros, which changes no bit).
  auto view_at = [&](Real depth) {
    return [=](Real ndc_x, Real ndc_y) {
      return Vec3((ndc_x * tan_x + cx) * depth, (ndc_y * tan_y + cy) * depth, -depth);
    };
  };
  // Pettineo 2009: far-plane corners rotated to world space.
  ScreenAttribute<Real>([&](Real x, Real y) { return Rotate(r, view_at(far)(x, y)); }, p.frustum_ray_origin,
                        p.frustum_ray_du, p.frustum_ray_dv);
  // Pettineo 2009, light volume: the surface's view-space position.
  ScreenAttribute<Real>(view_at(frame.volume_depth), p.volume_position_origin, p.volume_position_du,
                        p.volume_position_dv);
  // The eye-ray post 2011: the eye ray at w = 1 in view space and rotated to world space.
  ScreenAttribute<Real>(view_at(Real(1.0)), p.eye_ray_view_origin, p.eye_ray_view_du, p.eye_ray_view_dv);
  ScreenAttribute<Real>([&](Real x, Real y) { return Rotate(r, view_at(Real(1.0))(x, y)); }, p.eye_ray_world_origin,
                        p.eye_ray_world_du, p.eye_ray_world_dv);
  return p;
}

hp::vec2 NdcDepthCoefficients(DD near, DD far, std::uint32_t convention) {
  return hp::ndc_depth_coefficients(near, far, convention);
}
hp4::vec2 NdcDepthCoefficients(DD4 near, DD4 far, std::uint32_t convention) {
  return hp4::ndc_depth_coefficients(near, far, convention);
}
iv::vec2 NdcDepthCoefficients(Enclosure near, Enclosure far, std::uint32_t convention) {
  return iv::ndc_depth_coefficients(near, far, convention);
}

// DepthParams (hp:: or hp4::) of `convention` from the frame's near and far
// planes (far 0 when infinite) and its FrameParams, in that instantiation's
// arithmetic.
template <class DepthParams, class FrameParams>
DepthParams DepthParamsIn(RealOf<FrameParams> near, RealOf<FrameParams> far, const FrameParams& f,
                          std::uint32_t convention) {
  using Real = RealOf<FrameParams>;
  using Vec4 = glm::vec<4, Real>;
  const glm::vec<2, Real> ab = NdcDepthCoefficients(near, far, convention);
  const Real a = ab.x, b = ab.y;

  DepthParams d;
  d.coefficients = Vec4(a, b, Real(1.0) / b, -a / b);
  d.convention = convention;
  d.reserved0 = d.reserved1 = d.reserved2 = 0;

  // Inverse projection for view = (x/H + cx, y/V + cy, -1) * z and ndc_z =
  // A + B/z: (ndc.x, ndc.y, ndc_z, 1) -> (ndc.x/H + cx, ndc.y/V + cy, -1,
  // (ndc_z - A)/B), whose columns are (1/H, 0, 0, 0), (0, 1/V, 0, 0),
  // (0, 0, 0, P), (cx, cy, -1, Q).
  // Both products below are written out over the sparse matrix's nonzero
  // entries, in the order glm's full product adds them (left to right, the
  // left matrix's entry first): adding a zero product is exact, so every
  // entry equals the full product's, at a fifth of the cost (this runs for
  // every frame and convention). tests/constants_test.cc holds them equal.
  const glm::mat<4, 4, Real>& cw = f.camera_world;
  if ((convention & f32::DB_CONVENTION_ORTHOGRAPHIC) != 0u) {
    // view = (ndc.x * hw + cx, ndc.y * hh + cy, -(P * ndc_z + Q)) with the
    // half extents (hw, hh) in `lens` xy and w = 1: the inverse projection's
    // columns are (hw, 0, 0, 0), (0, hh, 0, 0), (0, 0, -P, 0), (cx, cy, -Q,
    // 1). The same sparse products as below.
    d.inverse_view_projection[0] = cw[0] * f.lens.x;
    d.inverse_view_projection[1] = cw[1] * f.lens.y;
    d.inverse_view_projection[2] = cw[2] * -d.coefficients.z;
    d.inverse_view_projection[3] =
        cw[0] * f.lens_centre.x + cw[1] * f.lens_centre.y + cw[2] * -d.coefficients.w + cw[3];
    // The projection: columns (H, 0, 0, 0), (0, V, 0, 0), (0, 0, -B, 0),
    // (-cx H, -cy V, A, 1), times the view.
    for (int c = 0; c < 4; ++c) {
      const Vec4& v = f.world_view[c];
      d.view_projection[c] = Vec4(f.lens.z * v.x - f.lens_centre.z * v.w, f.lens.w * v.y - f.lens_centre.w * v.w,
                                  -b * v.z + a * v.w, v.w);
    }
    return d;
  }
  d.inverse_view_projection[0] = cw[0] * f.lens.x;  // 1/H = tan_x
  d.inverse_view_projection[1] = cw[1] * f.lens.y;  // 1/V = tan_y
  d.inverse_view_projection[2] = cw[3] * d.coefficients.z;
  d.inverse_view_projection[3] =
      cw[0] * f.lens_centre.x + cw[1] * f.lens_centre.y + cw[2] * Real(-1.0) + cw[3] * d.coefficients.w;
  // The projection (EngineProjectionMatrix's layout: columns (H, 0, 0, 0),
  // (0, V, 0, 0), (cx H, cy V, -A, -1), (0, 0, B, 0)) times the view.
  const Real minus_a = -a, minus_one(-1.0);
  for (int c = 0; c < 4; ++c) {
    const Vec4& v = f.world_view[c];
    d.view_projection[c] = Vec4(f.lens.z * v.x + f.lens_centre.z * v.z, f.lens.w * v.y + f.lens_centre.w * v.z,
                                minus_a * v.z + b * v.w, minus_one * v.z);
  }
  return d;
}

// The members of FrameParams (of any instantiation) that hold reals:
// visit(member) for each, where member(params) is that member of `params`.
// One list for the rounding of one frame and of four.
template <class Visit>
void ForEachFrameParamsMember(Visit visit) {
  visit([](auto& p) -> auto& { return p.camera_world; });
  visit([](auto& p) -> auto& { return p.camera_position; });
  visit([](auto& p) -> auto& { return p.lens; });
  visit([](auto& p) -> auto& { return p.lens_centre; });
  visit([](auto& p) -> auto& { return p.resolution; });
  visit([](auto& p) -> auto& { return p.frustum_ray_origin; });
  visit([](auto& p) -> auto& { return p.frustum_ray_du; });
  visit([](auto& p) -> auto& { return p.frustum_ray_dv; });
  visit([](auto& p) -> auto& { return p.volume_position_origin; });
  visit([](auto& p) -> auto& { return p.volume_position_du; });
  visit([](auto& p) -> auto& { return p.volume_position_dv; });
  visit([](auto& p) -> auto& { return p.eye_ray_view_origin; });
  visit([](auto& p) -> auto& { return p.eye_ray_view_du; });
  visit([](auto& p) -> auto& { return p.eye_ray_view_dv; });
  visit([](auto& p) -> auto& { return p.eye_ray_world_origin; });
  visit([](auto& p) -> auto& { return p.eye_ray_world_du; });
  visit([](auto& p) -> auto& { return p.eye_ray_world_dv; });
  visit([](auto& p) -> auto& { return p.world_view; });
  visit([](auto& p) -> auto& { return p.clip_planes; });
}
// The same for DepthParams; its uints are copied.
template <class Visit>
void ForEachDepthParamsMember(Visit visit) {
  visit([](auto& p) -> auto& { return p.inverse_view_projection; });
  visit([](auto& p) -> auto& { return p.view_projection; });
  visit([](auto& p) -> auto& { return p.coefficients; });
}

float Round(DD x) { return RoundToFloat(x); }
glm::vec4 Round(const hp::vec4& v) { return {Round(v.x), Round(v.y), Round(v.z), Round(v.w)}; }
glm::mat4 Round(const hp::mat4& m) { return glm::mat4(Round(m[0]), Round(m[1]), Round(m[2]), Round(m[3])); }

// Four lanes rounded at once: out(k) receives lane k's float32 values.
template <class Out>
void RoundLanes(const hp4::vec4& v, Out out) {
  for (int i = 0; i < 4; ++i) {
    const Lanes<4>::Float f = RoundToFloat(v[i]);
    for (int k = 0; k < 4; ++k) out(k)[i] = f[k];
  }
}
template <class Out>
void RoundLanes(const hp4::mat4& m, Out out) {
  for (int c = 0; c < 4; ++c) RoundLanes(m[c], [&](int k) -> glm::vec4& { return out(k)[c]; });
}
template <class Out>
void RoundLanes(const hp4::FrameParams& p, Out out) {
  ForEachFrameParamsMember([&](auto member) {
    auto lane_member = [&](int k) -> auto& { return member(out(k)); };
    RoundLanes(member(p), lane_member);
  });
}
template <class Out>
void RoundLanes(const hp4::DepthParams& p, Out out) {
  ForEachDepthParamsMember([&](auto member) {
    auto lane_member = [&](int k) -> auto& { return member(out(k)); };
    RoundLanes(member(p), lane_member);
  });
  for (int k = 0; k < 4; ++k) {
    out(k).convention = p.convention;
    out(k).reserved0 = out(k).reserved1 = out(k).reserved2 = 0;
  }
}

// The convention bits of a frame's DepthParams slot: the perspective
// convention numbered `slot`, or its orthographic namesake in an
// orthographic frame.
std::uint32_t SlotBits(const Frame& frame, int slot) {
  return static_cast<std::uint32_t>(slot) | (frame.orthographic ? f32::DB_CONVENTION_ORTHOGRAPHIC : 0u);
}

bool HasConstants(const Frame& frame, std::uint32_t bits) {
  // Conventions with a finite far plane have no constants on frames that
  // have none (infinite-only domains); an orthographic frame has no
  // infinite far plane.
  const bool infinite = (bits & f32::DB_CONVENTION_INFINITE) != 0u;
  return frame.orthographic ? !infinite : frame.finite() || infinite;
}

// BuildShaderConstants under kExact for four frames at once, frames[k] in
// lane k: frame_params[k] and depth_params[k * kHardwareConventionCount +
// c] receive lane k's constants.
void BuildExactConstants4(const std::array<const Frame*, 4>& frames, f32::FrameParams* frame_params,
                          f32::DepthParams* depth_params) {
  const FrameValues<DD4> values = ValuesOf(frames);
  const hp4::FrameParams exact = FrameParamsIn<hp4::FrameParams>(values);
  RoundLanes(exact, [&](int k) -> f32::FrameParams& { return frame_params[k]; });
  for (int c = 0; c < kHardwareConventionCount; ++c) {
    // (The four frames are all perspective or all orthographic: the
    // caller checks.)
    const std::uint32_t bits = SlotBits(*frames[0], c);
    auto out = [&](int k) -> f32::DepthParams& { return depth_params[k * kHardwareConventionCount + c]; };
    // Lanes of frames without this convention's constants compute with far
    // 0, which no other lane sees, and are then zeroed as one frame's are.
    bool any = false;
    for (int k = 0; k < 4; ++k) any = any || HasConstants(*frames[k], bits);
    if (any) RoundLanes(DepthParamsIn<hp4::DepthParams>(values.near, values.far, exact, bits), out);
    for (int k = 0; k < 4; ++k) {
      if (!HasConstants(*frames[k], bits)) out(k) = f32::DepthParams{};
    }
  }
}

}  // namespace

hp::FrameParams BuildFrameParams(const Frame& frame) { return FrameParamsIn<hp::FrameParams>(ValuesOf<DD>(frame)); }

namespace {

// The far plane enters every constant monotonically, for fixed values of
// the other parameters: linearly in FrameParams (the frustum rays, the
// planes), through A, B, P and Q in DepthParams, each monotone in far
// (depth_mapping.h), and the inverse view-projection is linear in P and
// Q. So the enclosure over a range of far planes is the hull of the
// enclosures at its two ends, where evaluating the formulas over the range
// itself would not do: interval arithmetic takes the far in f / (f - n)
// as two independent ranges, and A would straddle 1 for any useful range.
template <class Params, class Each, class Make>
Params HullAtFarEnds(const FrameValues<Enclosure>& box, Each each_member, Make make) {
  FrameValues<Enclosure> at = box;
  at.far = Enclosure(box.far.lo);
  Params hull = make(at);
  at.far = Enclosure(box.far.hi);
  const Params high = make(at);
  each_member([&](auto member) {
    auto& h = member(hull);
    const auto& other = member(const_cast<Params&>(high));
    using Member = std::remove_cvref_t<decltype(h)>;
    if constexpr (std::is_same_v<Member, iv::mat4>) {
      for (int c = 0; c < 4; ++c) {
        for (int r = 0; r < 4; ++r) h[c][r] = Enclosure::Hull(h[c][r], other[c][r]);
      }
    } else {
      for (int k = 0; k < 4; ++k) h[k] = Enclosure::Hull(h[k], other[k]);
    }
  });
  return hull;
}

}  // namespace

namespace {

// `into` narrowed to what `also` encloses too (both enclose the same value).
void Narrow(Enclosure& into, const Enclosure& also) {
  const Enclosure both(std::max(into.lo, also.lo), std::min(into.hi, also.hi));
  if (both.lo <= both.hi) into = both;
}

// The world-space screen attributes are rotated view-space ones. Over a box
// of rotations, the steps FrameParamsIn takes as the difference of two
// rotated corners are enclosed far more loosely than the rotated
// view-space step (rotation is linear, so the two are equal), and a rotated
// component is never longer than the vector: both tighten each member.
void NarrowRotated(const FrameValues<Enclosure>& box, iv::FrameParams& p) {
  const iv::vec4* view[] = {&p.eye_ray_view_origin, &p.eye_ray_view_du, &p.eye_ray_view_dv};
  iv::vec4* eye_world[] = {&p.eye_ray_world_origin, &p.eye_ray_world_du, &p.eye_ray_world_dv};
  iv::vec4* frustum[] = {&p.frustum_ray_origin, &p.frustum_ray_du, &p.frustum_ray_dv};
  for (int k = 0; k < 3; ++k) {
    const glm::vec<3, Enclosure> v(view[k]->x, view[k]->y, view[k]->z);
    const glm::vec<3, Enclosure> world = Rotate(box.rotation, v);
    const double length = std::sqrt(Square(v.x).hi + Square(v.y).hi + Square(v.z).hi) * (1.0 + 0x1p-50);
    for (int c = 0; c < 3; ++c) {
      const Enclosure at_unit_depth(std::max(world[c].lo, -length), std::min(world[c].hi, length));
      Narrow((*eye_world[k])[c], at_unit_depth);
      // Pettineo's rays reach the far plane: the same at eye depth `far`.
      if (box.far.lo > 0.0) Narrow((*frustum[k])[c], at_unit_depth * box.far);
    }
  }
}

}  // namespace

iv::FrameParams EncloseFrameParams(const FrameValues<Enclosure>& box) {
  iv::FrameParams p = HullAtFarEnds<iv::FrameParams>(
      box, [](auto visit) { ForEachFrameParamsMember(visit); },
      [](const FrameValues<Enclosure>& at) { return FrameParamsIn<iv::FrameParams>(at); });
  NarrowRotated(box, p);
  return p;
}

iv::DepthParams EncloseDepthParams(const FrameValues<Enclosure>& box, Convention convention) {
  const std::uint32_t bits = Info(convention).bits;
  iv::DepthParams d = HullAtFarEnds<iv::DepthParams>(
      box, [](auto visit) { ForEachDepthParamsMember(visit); },
      [&](const FrameValues<Enclosure>& at) {
        return DepthParamsIn<iv::DepthParams>(at.near, at.far, FrameParamsIn<iv::FrameParams>(at), bits);
      });
  // The view-projection's entries mix A and B with opposite signs, which
  // need not be monotone in far: not enclosed (only the raster form reads it).
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) d.view_projection[c][r] = Enclosure::Whole();
  }
  return d;
}

hp::DepthParams BuildDepthParams(const Frame& frame, const hp::FrameParams& f, Convention convention) {
  return DepthParamsIn<hp::DepthParams>(DD(frame.near), frame.finite() ? DD(frame.far) : DD(0.0), f,
                                        Info(convention).bits);
}

Convention SlotConvention(const Frame& frame, int slot) {
  const std::uint32_t bits = SlotBits(frame, slot);
  for (const ConventionInfo& c : AllConventions()) {
    if (c.hardware && c.bits == bits) return c.id;
  }
  return static_cast<Convention>(slot);  // an orthographic frame's infinite slots: never built
}

f32::FrameParams RoundToFloat(const hp::FrameParams& p) {
  f32::FrameParams o;
  ForEachFrameParamsMember([&](auto member) { member(o) = Round(member(p)); });
  return o;
}

f32::DepthParams RoundToFloat(const hp::DepthParams& p) {
  f32::DepthParams o;
  ForEachDepthParamsMember([&](auto member) { member(o) = Round(member(p)); });
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
  if (Info(convention).orthographic()) {
    // glm::ortho's layout with the convention's depth row: clip z = -B *
    // view.z + A, w = 1; tan_x and tan_y are the half extents.
    projection[3][0] = -static_cast<float>(frame.centre_x) * projection[0][0];
    projection[3][1] = -static_cast<float>(frame.centre_y) * projection[1][1];
    projection[2][2] = -ab.y;
    projection[3][2] = ab.x;
    projection[3][3] = 1.0f;
    return projection;
  }
  projection[2][0] = static_cast<float>(frame.centre_x) * projection[0][0];
  projection[2][1] = static_cast<float>(frame.centre_y) * projection[1][1];
  projection[2][2] = -ab.x;
  projection[2][3] = -1.0f;
  projection[3][2] = ab.y;
  return projection;
}

f32::FrameParams EngineFrameParams(const Frame& frame) {
  f32::FrameParams p = FrameParamsIn<f32::FrameParams>(ValuesOf<float>(frame));
  p.world_view = EngineViewMatrix(frame);
  return p;
}

f32::DepthParams EngineDepthParams(const Frame& frame, Convention convention) {
  const glm::mat4 projection = EngineProjectionMatrix(frame, convention);
  const bool orthographic = Info(convention).orthographic();
  const float a = orthographic ? projection[3][2] : -projection[2][2];
  const float b = orthographic ? -projection[2][2] : projection[3][2];
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
    const Convention convention = SlotConvention(frame, c);
    depth_params[c] = !HasConstants(frame, SlotBits(frame, c)) ? f32::DepthParams{}
                      : exact                          ? RoundToFloat(BuildDepthParams(frame, exact_params, convention))
                                                       : EngineDepthParams(frame, convention);
  }
}

void BuildShaderConstants(std::span<const Frame> frames, ConstantsModel model, std::span<f32::FrameParams> frame_params,
                          std::span<f32::DepthParams> depth_params) {
  constexpr std::size_t kLanes = kShaderConstantsLanes;
  for (std::size_t first = 0; first < frames.size(); first += kLanes) {
    const std::size_t lanes = std::min(kLanes, frames.size() - first);
    f32::FrameParams* frame_out = frame_params.data() + first;
    f32::DepthParams* depth_out = depth_params.data() + first * kHardwareConventionCount;
    // The four-lane arithmetic takes one convention per slot: the frames of
    // a group must be all perspective or all orthographic (a domain's are).
    const bool one_kind = std::all_of(frames.begin() + first, frames.begin() + first + lanes,
                                      [&](const Frame& f) { return f.orthographic == frames[first].orthographic; });
    if (model != ConstantsModel::kExact || !one_kind) {
      for (std::size_t k = 0; k < lanes; ++k) {
        BuildShaderConstants(frames[first + k], model, frame_out[k],
                             std::span<f32::DepthParams, kHardwareConventionCount>(
                                 depth_out + k * kHardwareConventionCount, kHardwareConventionCount));
      }
    } else if (lanes == kLanes) {
      BuildExactConstants4({&frames[first], &frames[first + 1], &frames[first + 2], &frames[first + 3]}, frame_out,
                           depth_out);
    } else {
      // A short last group: its last frame again in the spare lanes, whose
      // results are dropped.
      std::array<const Frame*, kLanes> group;
      for (std::size_t k = 0; k < kLanes; ++k) group[k] = &frames[first + std::min(k, lanes - 1)];
      std::array<f32::FrameParams, kLanes> frame_lanes;
      std::array<f32::DepthParams, kLanes * kHardwareConventionCount> depth_lanes;
      BuildExactConstants4(group, frame_lanes.data(), depth_lanes.data());
      std::copy_n(frame_lanes.begin(), lanes, frame_out);
      std::copy_n(depth_lanes.begin(), lanes * kHardwareConventionCount, depth_out);
    }
  }
}

}  // namespace depthbench
