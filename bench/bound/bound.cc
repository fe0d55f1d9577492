#include "bench/bound/bound.h"

#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <queue>

#include <fmt/format.h>

#include "bench/backends/vulkan/variant_program.h"
#include "bench/bound/spirv_eval.h"
#include "bench/pipeline/encode.h"
#include "bench/pipeline/shader_constants.h"

namespace depthbench::bound {

double BoundBits(double relative_error) {
  if (!(relative_error > 0.0)) return 0.0;
  return std::max(0.0, std::log2(relative_error) + 24.0);
}

namespace {

constexpr double kU = kUnitRoundoff;
constexpr double kPi = std::numbers::pi;

// The dimensions of a box. Lengths are in units of the near plane.
enum Dim : int {
  kLogRatio,   // log of far / near
  kDepth,      // t: the true eye depth is ratio^t (so 1 to far)
  kPixelX,     // pixel column, whole numbers
  kPixelY,     // pixel row
  kFov,        // vertical field of view, degrees
  kLogAspect,  // log of width / height
  kYaw,        // the camera's rotation as Z-Y-X Euler angles, radians
  kPitch,
  kRoll,
  kDistance,     // the camera's distance from the world origin, in near planes
  kVolumeDepth,  // t: the light volume's surface lies at eye depth ratio^t
  kDims,
};

struct Box {
  std::array<Enclosure, kDims> d;
  std::uint32_t width = 0, height = 0;  // the render target
  double shader = 0.0;                  // the box's figures (relative errors)
  double depth = 0.0;
  std::string why;             // why `shader` is infinite
  int last_split = kDims - 1;  // the dimension split to make this box
  // A box of the sweep's stored-value picks (sampler.h DepthPick): the
  // stored value is the format's edge, and the truth is what it denotes.
  DepthPick pick = DepthPick::kEyeDepth;
  double total() const { return shader + depth; }
  // What the refinement lowers: the shader part's bound, or the whole's.
  bool refine_total = false;
  double figure() const { return refine_total ? total() : shader; }
  friend bool operator<(const Box& a, const Box& b) { return a.figure() < b.figure(); }
};

Enclosure Exp(const Enclosure& x) { return Enclosure::Outward(std::exp(x.lo), std::exp(x.hi)); }

// cos over an interval of angles: the endpoints' values, and 1 or -1 where
// the interval holds a multiple of 2 pi or an odd multiple of pi.
Enclosure Cos(const Enclosure& a) {
  if (a.width() >= 2.0 * kPi) return {-1.0, 1.0};
  const double c0 = std::cos(a.lo), c1 = std::cos(a.hi);
  double lo = std::min(c0, c1), hi = std::max(c0, c1);
  auto holds = [&](double phase) { return phase + 2.0 * kPi * std::ceil((a.lo - phase) / (2.0 * kPi)) <= a.hi; };
  if (holds(0.0)) hi = 1.0;
  if (holds(kPi)) lo = -1.0;
  return {std::max(-1.0, lo - 1e-15), std::min(1.0, hi + 1e-15)};
}
Enclosure Sin(const Enclosure& a) { return Cos(a - Enclosure(kPi / 2.0)); }

// The camera's rotation (columns: its axes in world space) over the box's angles.
glm::mat<3, 3, Enclosure> Rotation(const Box& box) {
  const Enclosure cy = Cos(box.d[kYaw]), sy = Sin(box.d[kYaw]);
  const Enclosure cp = Cos(box.d[kPitch]), sp = Sin(box.d[kPitch]);
  const Enclosure cr = Cos(box.d[kRoll]), sr = Sin(box.d[kRoll]);
  auto clamp = [](const Enclosure& x) { return Enclosure(std::max(-1.0, x.lo), std::min(1.0, x.hi)); };
  glm::mat<3, 3, Enclosure> r;
  r[0][0] = clamp(cy * cp);
  r[1][0] = clamp(cy * sp * sr - sy * cr);
  r[2][0] = clamp(cy * sp * cr + sy * sr);
  r[0][1] = clamp(sy * cp);
  r[1][1] = clamp(sy * sp * sr + cy * cr);
  r[2][1] = clamp(sy * sp * cr - cy * sr);
  r[0][2] = clamp(-sp);
  r[1][2] = clamp(cp * sr);
  r[2][2] = clamp(cp * cr);
  return r;
}

// Scale. The analysis runs with the near plane at 1, and a bound found
// there must hold at every scale: rounding bounds relative to a value's
// magnitude do, but a value a float holds exactly at this scale need not
// be exact at another. So only values that do not scale are taken as
// exact: the program's literals, zero, whole numbers of pixels, the
// dimensionless A; a length (B, the far plane, near) never is, even where
// its normalized value is 1. A single sample's frame is analysed at its own
// scale (`at_scale`, ShaderBoundAt): there every float is known.

// The float32 values the points of `x` round to nearest: what the shader
// and the reference read of a constant computed exactly and rounded once
// (encode.h FrameMapping; a point when x is one a float holds).
Enclosure NearestFloats(const Enclosure& x) {
  return {NearestFloat32(x.lo), NearestFloat32(x.hi)};
}

// The same for a length: at a normalized scale, only that its float lies
// within 2^-24 of it.
Enclosure LengthFloat(const Enclosure& x, bool at_scale) {
  if (at_scale) return NearestFloats(x);
  const double w = kU * x.mag();
  return Enclosure::Outward(x.lo - w, x.hi + w);
}

// An input lane: the exact constant lies in `x` widened by `widen` u of
// its magnitude; the float32 value the shader receives is within `error` u
// of it (exactly 0 when it is 0, at any scale), and at the frame's own
// scale is x rounded.
Lane Input(const Enclosure& x, double widen, double error, bool at_scale) {
  if (x.lo == 0.0 && x.hi == 0.0) return Lane::Exact(x);
  const double w = widen * kU * x.mag();
  const Enclosure exact = Enclosure::Outward(x.lo - w, x.hi + w);
  // Point by point the float is within error u of x, which is within
  // widen u of the exact value: relative to the exact value where no
  // point is small enough to round as a denormal.
  const double relative = exact.mig() >= kLeastRelative ? Up(error * kU / (1.0 - widen * kU)) : INFINITY;
  return {exact, error * kU * x.mag() + kUnderflow, at_scale ? NearestFloats(x) : Enclosure::Whole(), relative};
}
Value Inputs(const iv::vec4& v, double widen, double error, bool at_scale, int exact_lanes = 0) {
  std::vector<Value> parts;
  for (int k = 0; k < 4; ++k)
    parts.push_back(Value::Float(k < exact_lanes ? Lane::Exact(v[k]) : Input(v[k], widen, error, at_scale)));
  return Value::Composite(std::move(parts));
}
// A matrix's columns; `transposed`: its rows, as a program that reads its
// buffers row-major holds it (SpirvProgram::RowMajorMatrices).
Value Inputs(const iv::mat4& m, double widen, double error, bool at_scale, bool transposed) {
  std::vector<Value> columns;
  for (int c = 0; c < 4; ++c) {
    iv::vec4 column = m[c];
    if (transposed) column = iv::vec4(m[0][c], m[1][c], m[2][c], m[3][c]);
    columns.push_back(Inputs(column, widen, error, at_scale));
  }
  return Value::Composite(std::move(columns));
}

// FrameParams as the shader receives them, members in declaration order
// (shared/params.h). Every constant is the exact one rounded once to float32
// (ConstantsModel::kExact), except where the reference itself reads a
// float32 value: the camera position (the sampler's is float32) and the
// far plane (the linear formats' reference decodes with the float far
// plane, so the frustum rays, which scale with the exact far plane, are a
// further ulp from what it denotes).
Value FrameInputs(const iv::FrameParams& f, bool at_scale, bool transposed) {
  std::vector<Value> m;
  Value camera_world = Inputs(f.camera_world, 0, 1, at_scale, transposed);
  camera_world.camera_to_world = !transposed;
  if (transposed) {
    for (int r = 0; r < 3; ++r)
      camera_world.parts.Mutable()[r].parts.Mutable()[3] = Value::Float(Lane::Exact(f.camera_world[3][r]));
  } else {
    camera_world.parts.Mutable()[3] = Inputs(f.camera_world[3], 0, 0, at_scale, 4);
  }
  m.push_back(std::move(camera_world));
  Value camera_position = Inputs(f.camera_position, 0, 0, at_scale, 3);
  camera_position.parts.Mutable()[3] = Value::Float(Lane::Exact(LengthFloat(f.camera_position.w, at_scale)));
  m.push_back(std::move(camera_position));
  m.push_back(Inputs(f.lens, 0, 1, at_scale));
  Value resolution = Inputs(f.resolution, 0, 1, at_scale, 2);  // whole numbers of pixels, then their reciprocals
  m.push_back(std::move(resolution));
  for (const iv::vec4* ray : {&f.frustum_ray_origin, &f.frustum_ray_du, &f.frustum_ray_dv})
    m.push_back(Inputs(*ray, 1, 2, at_scale));
  for (const iv::vec4* v :
       {&f.volume_position_origin, &f.volume_position_du, &f.volume_position_dv, &f.eye_ray_view_origin,
        &f.eye_ray_view_du, &f.eye_ray_view_dv, &f.eye_ray_world_origin, &f.eye_ray_world_du, &f.eye_ray_world_dv}) {
    m.push_back(Inputs(*v, 0, 1, at_scale));
  }
  m.push_back(Inputs(f.world_view, 0, 1, at_scale, transposed));
  m.push_back(Inputs(f.lens_centre, 0, 1, at_scale));
  Value clip_planes = Inputs(f.clip_planes, 0, 1, at_scale);
  clip_planes.parts.Mutable()[1] = Value::Float(Lane::Exact(LengthFloat(f.clip_planes.y, at_scale)));
  m.push_back(std::move(clip_planes));
  return Value::Composite(std::move(m));
}

// DepthParams as the shader receives them. The reference decodes with the
// float32 A and B (encode.h), so those arrive exactly; P = 1/B, Q = -A/B
// and the matrices are rounded from the exact frame's, up to two ulps from
// what the float A and B give, plus their own rounding.
Value DepthInputs(const iv::DepthParams* d, std::uint32_t convention, bool at_scale, bool transposed) {
  std::vector<Value> m;
  if (d != nullptr) {
    m.push_back(Inputs(d->inverse_view_projection, 2, 3, at_scale, transposed));
    m.push_back(Inputs(d->view_projection, 2, 3, at_scale, transposed));
    Value coefficients = Inputs(d->coefficients, 2, 3, at_scale);
    coefficients.parts.Mutable()[0] = Value::Float(Lane::Exact(NearestFloats(d->coefficients.x)));
    coefficients.parts.Mutable()[1] = Value::Float(Lane::Exact(LengthFloat(d->coefficients.y, at_scale)));
    m.push_back(std::move(coefficients));
  } else {
    // Not a projective convention: nothing here is the cell's to read.
    m.resize(3);
  }
  m.push_back(Value::Integer(convention));
  for (int k = 0; k < 3; ++k) m.push_back(Value::Integer(0));
  return Value::Composite(std::move(m));
}

// The stored values a box's true eye depths may produce, and the depth
// part's relative error bound.
struct Stored {
  Enclosure value;
  double depth = 0.0;
  std::string why;
};

// (1 + u)^n - 1 and (1 + u)^n / (1 - u) - 1: the relative error of n
// correctly rounded operations, without and with one in the denominator.
constexpr double Gamma(int n) { return n == 0 ? 0.0 : (1.0 + kU) * (Gamma(n - 1) + 1.0) - 1.0; }
constexpr double GammaOver(int n) { return (Gamma(n) + 1.0) / (1.0 - kU) - 1.0; }

// The format's rounding of a produced value v, then the fetch back to
// float32: within relative * |v| + absolute of it.
struct StorageError {
  double relative = 0.0, absolute = 0.0;
};
StorageError StorageOf(const FormatInfo& format) {
  switch (format.texel) {
    case TexelKind::kUnorm: return {kU, 0.5 / (std::ldexp(1.0, format.bits) - 1.0)};  // nearest code, fetched
    case TexelKind::kFloat16: return {0x1p-11, 0x1p-25};                              // float16's unit roundoff
    case TexelKind::kFloat32: return {};                                              // stored as produced
  }
  return {};
}

// Production as the host models it (encode.h, kFloat32), then the format's
// rounding and the fetch. The production's few operations are bounded in
// closed form, relative to each term, rather than by the lane rules:
// those would take the largest eye depth of the box over the smallest.
//   hardware: ndc = (A z~ (1 + d1) + B)(1 + d2) / z~ (1 + d3), z~ = z (1 + d0),
//             so |ndc - (A + B / z)| <= |A| gamma_3 + |B / z| gamma'_3;
//             GL-style clip depth then 0.5 ndc + 0.5, one rounding more;
//   linear:   z~ / far (1 + d1): within gamma_2 of z / far, relatively;
//   view z:   -z~: within u of it.
// `a`, `b` and `far` are the float32 values the reference decodes with.
// `linear` encloses z / far, tighter than the two ranges' quotient.
Stored StoredValues(Encoding encoding, const Enclosure& a, const Enclosure& b, const Enclosure& far, const Enclosure& z,
                    const Enclosure& linear) {
  const FormatInfo& format = Info(encoding.format);
  const StorageError storage = StorageOf(format);
  Stored out;
  switch (format.stores) {
    case DepthInput::kHardware: {
      const std::uint32_t bits = Info(encoding.convention).bits;
      const bool gl = (bits & 4u) != 0u;  // DB_CONVENTION_CLIP_MINUS_ONE
      const Enclosure b_over_z = b / z;
      Enclosure value = a + b_over_z;
      double produced = a.mag() * Gamma(3) + b_over_z.mag() * GammaOver(3) + kUnderflow;
      if (gl) {
        value = value * Enclosure(0.5) + Enclosure(0.5);
        produced = 0.5 * produced + kU * (value.mag() + 0.5 * produced) + kUnderflow;
      }
      const double delta = produced + storage.relative * value.mag() + storage.absolute;
      out.value = Enclosure(std::max(0.0, value.lo - delta), std::min(1.0, value.hi + delta));
      if ((bits & 2u) != 0u) {  // DB_CONVENTION_INFINITE
        // The stored value that denotes an infinite depth (A, as a window
        // depth 0 or 1) is not judged; the values next to it are a step of
        // the format away.
        const double step = format.texel == TexelKind::kUnorm ? 1.0 / (std::ldexp(1.0, format.bits) - 1.0)
                            : a.mid() > 0.0                   ? 0x1p-24
                                                              : 0x1p-149;
        if (a.mid() > 0.0) {
          out.value.hi = std::min(out.value.hi, 1.0 - step);
        } else {
          out.value.lo = std::max(out.value.lo, step);
        }
      }
      // The true value's NDC depth less A is B / z; the stored value's lies
      // within delta (2 delta in NDC for GL-style clip depth) of it, and no
      // nearer A than the stored values themselves.
      const double ndc_delta = (gl ? 2.0 : 1.0) * delta;
      const Enclosure ndc_stored = gl ? out.value * Enclosure(2.0) - Enclosure(1.0) : out.value;
      const double gap = std::max(b_over_z.mig() - ndc_delta, (ndc_stored - a).mig());
      if (!(gap > 0.0) || out.value.lo > out.value.hi) {
        out.why = "stored values that may denote an infinite depth";
        out.depth = INFINITY;
        return out;
      }
      out.depth = ndc_delta / gap;
      return out;
    }
    case DepthInput::kLinear: {
      const double relative = Gamma(2) + storage.relative * (1.0 + Gamma(2));
      const double delta = relative * linear.mag() + storage.absolute;
      out.value = Enclosure(std::max(0.0, linear.lo - delta), linear.hi + delta);
      out.depth = relative + storage.absolute / linear.mig();
      (void)far;
      return out;
    }
    case DepthInput::kViewZ: {
      const double delta = kU * z.mag() + kUnderflow;
      out.value = Enclosure(-z.hi - delta, -z.lo + delta);
      out.depth = kU + kUnderflow / z.lo;
      return out;
    }
  }
  return out;
}

// What a cell needs to evaluate its boxes.
struct CellProgram {
  const SpirvProgram* program = nullptr;
  std::uint32_t uv_function = 0;
  std::uint32_t reconstruct = 0;
};

class CellAnalysis {
 public:
  // `at_scale`: the frames given are samples' own, not normalized boxes.
  CellAnalysis(const Domain& domain, const Cell& cell, const CellProgram& program, bool at_scale = false)
      : domain_(domain), cell_(cell), program_(program), convention_(Info(cell.convention)), at_scale_(at_scale) {}

  // The box's shader and depth figures under `machine`.
  void Evaluate(Box& box, const Machine& machine) const {
    box.why.clear();
    const Enclosure ratio = Exp(box.d[kLogRatio]);
    // z = ratio^t and z / far = ratio^(t - 1), each from one product.
    const Enclosure z = Exp(box.d[kDepth] * box.d[kLogRatio]);
    const Enclosure linear = Exp((box.d[kDepth] - Enclosure(1.0)) * box.d[kLogRatio]);
    FrameValues<Enclosure> v;
    LensOf(box, v);
    v.near = Enclosure(1.0);
    v.far = domain_.finite_far ? ratio : Enclosure(0.0);
    v.volume_depth = Exp(box.d[kVolumeDepth] * box.d[kLogRatio]);
    v.width = Enclosure(box.width);
    v.height = Enclosure(box.height);
    const double reach = box.d[kDistance].hi;
    for (int k = 0; k < 3; ++k) v.camera_position[k] = Enclosure(-reach, reach);
    v.rotation = Rotation(box);
    const Inputs in = InputsOf(v);

    Stored stored;
    Enclosure truth = z;
    const Enclosure interest = Interest();
    if (box.pick == DepthPick::kEyeDepth) {
      // Only the eye depths of interest are drawn.
      if (!(z.hi >= interest.lo && z.lo <= interest.hi)) return NeverJudged(box);
      const Enclosure drawn(std::max(z.lo, interest.lo), std::min(z.hi, interest.hi));
      const Enclosure drawn_linear(std::max(linear.lo, (Enclosure(drawn.lo) / ratio).lo),
                                   std::min(linear.hi, (Enclosure(drawn.hi) / ratio).hi));
      truth = drawn;
      stored = StoredValues(cell_.encoding(), in.a, in.b, in.far, drawn, drawn_linear);
    } else {
      // A pick's truth is the depth it denotes, judged between the near
      // plane and the far one (none for an infinite far plane, reference.cc).
      // A denoted point float32 world coordinates cannot hold (infinity,
      // or past 2^64 from the camera at the domain's smallest scale) is
      // not judged either.
      stored.value = PickedValue(box.pick, ratio);
      truth = DenotedDepths(in, stored.value);
      const double slack = 0x1p-20;
      const bool infinite = (convention_.bits & 2u) != 0u;
      const bool holdable = truth.lo > 0.0 && truth.finite() && truth.lo * domain_.near.min < 0x1p64;
      const double nearest = std::max(1.0, interest.lo) * (1.0 - slack);
      const double farthest = std::min(infinite ? INFINITY : ratio.hi, interest.hi) * (1.0 + slack);
      if (!holdable || !(truth.hi >= nearest) || !(truth.lo <= farthest)) return NeverJudged(box);
      truth.lo = std::max(truth.lo, nearest);
    }
    box.depth = stored.depth;
    if (!stored.why.empty()) return Fail(box, stored.why);
    Expected<OutputError> error = ShaderError(in, box.d[kPixelX], box.d[kPixelY], stored.value, machine);
    if (!error.ok()) return Fail(box, error.status().message());
    // |true point - camera| = true eye depth * |the pixel's ray per unit eye depth|.
    box.shader = error->absolute / (truth.lo * RayLength(in, box.d[kPixelX], box.d[kPixelY]));
    // The point the stored value denotes is within the depth part of the
    // true one, relative to the true eye depth: 1 / (1 - depth) as far.
    if (stored.depth < 1.0) box.shader = std::min(box.shader, error->distance_relative / (1.0 - stored.depth));
  }

  // What the shader receives for the frames of `v`.
  struct Inputs {
    FrameValues<Enclosure> values;
    iv::FrameParams frame;
    Value frame_value, depth_value;
    Enclosure a, b;  // the depth mapping's A and B, as the reference reads them
    Enclosure far;   // the far plane, as the linear formats' reference reads it
  };
  Inputs InputsOf(const FrameValues<Enclosure>& v) const {
    Inputs in;
    in.values = v;
    in.frame = EncloseFrameParams(v);
    iv::DepthParams depth{};
    const bool hardware = convention_.hardware;
    if (hardware) depth = EncloseDepthParams(v, cell_.convention);
    const bool transposed = program_.program->RowMajorMatrices();
    in.frame_value = FrameInputs(in.frame, at_scale_, transposed);
    in.depth_value = DepthInputs(hardware ? &depth : nullptr, convention_.bits, at_scale_, transposed);
    in.a = NearestFloats(depth.coefficients.x);
    in.b = LengthFloat(depth.coefficients.y, at_scale_);
    in.far = LengthFloat(in.frame.camera_position.w, at_scale_);
    return in;
  }

  // The bound on the output's distance from the point exact arithmetic
  // gives, for the pixels and stored values given.
  struct OutputError {
    double absolute = 0.0;  // the error vector's length
    // Its length over the exact output's distance from the camera, point
    // by point (a camera-to-world product's, Lane::distance_relative), or
    // infinity.
    double distance_relative = INFINITY;
  };
  Expected<OutputError> ShaderError(const Inputs& in, const Enclosure& pixel_x, const Enclosure& pixel_y,
                                    const Enclosure& stored, const Machine& machine) const {
    const Value pixel[3] = {Value::Float(Lane::Exact(pixel_x)), Value::Float(Lane::Exact(pixel_y)),
                            in.frame_value.parts[3]};
    DB_ASSIGN_OR_RETURN(const Value uv, program_.program->Evaluate(program_.uv_function, pixel, machine));
    const Value arguments[4] = {in.frame_value, in.depth_value, uv, Value::Float(Lane::Exact(stored))};
    DB_ASSIGN_OR_RETURN(const Value p, program_.program->Evaluate(program_.reconstruct, arguments, machine));
    if (p.kind != Value::Kind::kComposite || p.parts.size() != 3)
      return InvalidArgument("an output that is not a vec3");
    double sum = 0.0;
    for (const Value& lane : p.parts) {
      if (lane.kind != Value::Kind::kFloat) return InvalidArgument("an output lane with no known float value");
      sum += lane.lane.error * lane.lane.error;
    }
    OutputError out{std::sqrt(sum) * (1.0 + 1e-12)};
    const Lane& first = p.parts[0].lane;
    bool product = first.vector != 0;
    for (int k = 0; k < 3; ++k)
      product = product && p.parts[k].lane.vector == first.vector && p.parts[k].lane.component == k;
    if (product) out.distance_relative = first.distance_relative;
    return out;
  }

  // The stored value a pick takes (the fetched float, encode.h EncodeEdge);
  // a view-z format's far end follows the frame's far plane.
  Enclosure PickedValue(DepthPick pick, const Enclosure& ratio) const {
    if (Info(cell_.format).stores == DepthInput::kViewZ) {
      switch (pick) {
        case DepthPick::kStoredOne:
        case DepthPick::kStoredBeforeOne: return -ratio * Enclosure(1.0 - 0x1p-23, 1.0);
        case DepthPick::kStoredAfterZero: return Enclosure(-0x1p-149);
        default: return Enclosure(0.0);
      }
    }
    return Enclosure(EncodeEdge(cell_.encoding(), Frame{}, pick).fetched);
  }

  // The eye depths stored values denote, as the reference decodes them.
  Enclosure DenotedDepths(const Inputs& in, const Enclosure& stored) const {
    switch (Info(cell_.format).stores) {
      case DepthInput::kHardware: {
        const bool gl = (convention_.bits & 4u) != 0u;  // DB_CONVENTION_CLIP_MINUS_ONE
        return in.b / ((gl ? stored * Enclosure(2.0) - Enclosure(1.0) : stored) - in.a);
      }
      case DepthInput::kLinear: return stored * in.far;
      case DepthInput::kViewZ: return -stored;
    }
    return Enclosure::Whole();
  }

  // The least length of the pixels' rays per unit eye depth.
  static double RayLength(const Inputs& in, const Enclosure& pixel_x, const Enclosure& pixel_y) {
    const Enclosure ndc_x = (pixel_x + Enclosure(0.5)) * Enclosure(2.0) / in.values.width - Enclosure(1.0);
    const Enclosure ndc_y = Enclosure(1.0) - (pixel_y + Enclosure(0.5)) * Enclosure(2.0) / in.values.height;
    const Enclosure ray_sq = Enclosure(1.0) + Square(ndc_x * in.frame.lens.x + in.frame.lens_centre.x) +
                             Square(ndc_y * in.frame.lens.y + in.frame.lens_centre.y);
    return std::sqrt(ray_sq.lo) * (1.0 - 1e-12);
  }

  // The whole domain's boxes: one per render target.
  std::vector<Box> Roots() const {
    std::vector<Box> roots;
    for (const Resolution& r : domain_.resolutions) {
      Box box;
      const Range ratio = Ratios();
      box.d[kLogRatio] = Enclosure(std::log(ratio.min), std::log(ratio.max));
      box.d[kDepth] = Enclosure(0.0, 1.0);
      box.d[kPixelX] = Enclosure(0.0, r.width - 1.0);
      box.d[kPixelY] = Enclosure(0.0, r.height - 1.0);
      box.d[kFov] = Enclosure(domain_.fov_degrees.min, domain_.fov_degrees.max);
      box.d[kLogAspect] = Enclosure(std::log(domain_.aspect.min), std::log(domain_.aspect.max));
      box.d[kYaw] = Enclosure(-kPi, kPi);
      box.d[kPitch] = Enclosure(-kPi / 2.0, kPi / 2.0);
      box.d[kRoll] = Enclosure(-kPi, kPi);
      box.d[kDistance] = Enclosure(0.0, domain_.camera_distance.max / domain_.near.min);
      box.d[kVolumeDepth] = Enclosure(0.0, 1.0);
      box.width = r.width;
      box.height = r.height;
      roots.push_back(box);
      // The sweep's stored-value picks, over every frame and pixel.
      for (DepthPick pick :
           {DepthPick::kStoredZero, DepthPick::kStoredOne, DepthPick::kStoredAfterZero, DepthPick::kStoredBeforeOne}) {
        Box edge = box;
        edge.pick = pick;
        edge.d[kDepth] = Enclosure(0.0);
        roots.push_back(edge);
      }
    }
    return roots;
  }

 private:
  // The far/near ratios of the domain's frames: an absolute far plane's
  // over every near plane it may meet. Infinite-far frames reach
  // kInfiniteDepthSpan.
  Range Ratios() const {
    if (!domain_.finite_far) return {Domain::kInfiniteDepthSpan, Domain::kInfiniteDepthSpan};
    if (!domain_.far) return domain_.ratio;
    return {domain_.far->min / domain_.near.max, domain_.far->max / domain_.near.min};
  }
  // The eye depths of interest in near planes (reference.cc judges only
  // those): an absolute range over every near plane it may meet.
  Enclosure Interest() const {
    if (!domain_.eye_depth) return {0.0, INFINITY};
    return Enclosure::Outward(domain_.eye_depth->min / domain_.near.max, domain_.eye_depth->max / domain_.near.min);
  }
  static void NeverJudged(Box& box) { box.shader = box.depth = 0.0; }
  static void Fail(Box& box, std::string why) {
    box.shader = INFINITY;
    box.why = std::move(why);
  }

  // tan(fov/2), aspect and the lens centre of the box's frames.
  void LensOf(const Box& box, FrameValues<Enclosure>& v) const {
    if (domain_.eye_fov) {
      const EyeFov& e = *domain_.eye_fov;
      v.tan_half_fov_y = Enclosure((e.TanUp() - e.TanDown()) / 2.0);
      v.aspect = Enclosure((e.TanRight() - e.TanLeft()) / 2.0) / v.tan_half_fov_y;
      v.centre_x = Enclosure((e.TanRight() + e.TanLeft()) / 2.0);
      v.centre_y = Enclosure((e.TanUp() + e.TanDown()) / 2.0);
    } else {
      const double to_half_radians = kPi / 360.0;
      v.tan_half_fov_y =
          Enclosure::Outward(std::tan(box.d[kFov].lo * to_half_radians), std::tan(box.d[kFov].hi * to_half_radians));
      v.aspect = Exp(box.d[kLogAspect]);
      v.centre_x = v.centre_y = Enclosure(0.0);
    }
    if (domain_.jitter > 0.0) {
      // Up to `jitter` pixels: 2 jitter / width of the half width tan_x.
      const Enclosure j(-domain_.jitter, domain_.jitter);
      v.centre_x = v.centre_x + j * Enclosure(2.0) / Enclosure(box.width) * (v.aspect * v.tan_half_fov_y);
      v.centre_y = v.centre_y + j * Enclosure(2.0) / Enclosure(box.height) * v.tan_half_fov_y;
    }
  }

  const Domain& domain_;
  const Cell& cell_;
  const CellProgram& program_;
  const ConventionInfo& convention_;
  bool at_scale_;
};

// The two halves of `box` along `dim` (pixels split between whole numbers).
std::optional<std::pair<Box, Box>> Halves(const Box& box, int dim) {
  const Enclosure& x = box.d[dim];
  double cut = x.mid();
  std::pair<Box, Box> halves{box, box};
  if (dim == kPixelX || dim == kPixelY) {
    if (x.hi - x.lo < 1.0) return std::nullopt;
    cut = std::floor(cut);
    halves.first.d[dim] = Enclosure(x.lo, cut);
    halves.second.d[dim] = Enclosure(cut + 1.0, x.hi);
    return halves;
  }
  if (!(x.width() > 0.0)) return std::nullopt;
  halves.first.d[dim] = Enclosure(x.lo, cut);
  halves.second.d[dim] = Enclosure(cut, x.hi);
  return halves;
}

struct Outcome {
  double shader = 0.0, depth = 0.0, total = 0.0;
  std::uint64_t boxes = 0;
  std::string why;
};

// Branch and bound: split the worst box along the dimension whose halves'
// worse figure is lowest, `splits` times; the figure is the shader part's
// bound, or with `refine_total` the whole error's.
Outcome Refine(const CellAnalysis& analysis, const Machine& machine, int splits, bool refine_total) {
  std::priority_queue<Box> queue;
  for (Box box : analysis.Roots()) {
    box.refine_total = refine_total;
    analysis.Evaluate(box, machine);
    queue.push(std::move(box));
  }
  for (int s = 0; s < splits && !queue.empty(); ++s) {
    const Box& worst = queue.top();
    std::optional<std::pair<Box, Box>> best;
    double best_figure = INFINITY;
    // Dimensions in turn from the one after the box's last split, so that
    // where every split leaves a half unbounded (a divisor range that
    // holds 0 until the box is narrow in several dimensions), each
    // dimension is split in turn.
    for (int k = 0; k < kDims; ++k) {
      const int dim = (worst.last_split + 1 + k) % kDims;
      std::optional<std::pair<Box, Box>> halves = Halves(worst, dim);
      if (!halves) continue;
      analysis.Evaluate(halves->first, machine);
      analysis.Evaluate(halves->second, machine);
      const double figure = std::log(halves->first.figure()) + std::log(halves->second.figure());
      if (!best || figure < best_figure) {
        best_figure = figure;
        halves->first.last_split = halves->second.last_split = dim;
        best = std::move(halves);
      }
    }
    if (!best) break;  // a point: nothing left to split
    queue.pop();
    queue.push(std::move(best->first));
    queue.push(std::move(best->second));
  }
  // The boxes cover the domain, so the worst of each figure over them
  // bounds it everywhere.
  Outcome out;
  out.boxes = queue.size();
  for (; !queue.empty(); queue.pop()) {
    const Box& box = queue.top();
    if (box.shader > out.shader && !box.why.empty()) out.why = box.why;
    out.shader = std::max(out.shader, box.shader);
    out.depth = std::max(out.depth, box.depth);
    out.total = std::max(out.total, box.total());
  }
  return out;
}

// Each variant's program, compiled and parsed once.
using Programs = std::map<Variant, Expected<SpirvProgram>>;

Expected<CellProgram> ProgramOf(const Cell& cell, const std::filesystem::path& shader_dir, Programs& programs) {
  auto found = programs.find(cell.variant);
  if (found == programs.end()) {
    Expected<std::vector<std::uint32_t>> words =
        CompileVariant(cell.variant_info(), VariantPass::kAccuracy, shader_dir);
    Expected<SpirvProgram> program = words.ok() ? SpirvProgram::Parse(*words) : Expected<SpirvProgram>(words.status());
    found = programs.emplace(cell.variant, std::move(program)).first;
  }
  if (!found->second.ok()) return found->second.status();
  CellProgram program{&*found->second};
  DB_ASSIGN_OR_RETURN(program.uv_function, program.program->Function("uv_from_pixel"));
  DB_ASSIGN_OR_RETURN(program.reconstruct, program.program->Function(ReconstructFunctionName(cell.variant_info())));
  return program;
}

Status CheckCovered(const Domain& domain) {
  if (domain.orthographic) return InvalidArgument("bounds cover perspective domains only (this one is orthographic)");
  if (domain.capture) return InvalidArgument("bounds cover drawn domains only (this one is a captured frame)");
  if (domain.constants != ConstantsModel::kExact) {
    return InvalidArgument("bounds cover exact shader constants only (this domain computes them in float32)");
  }
  if (domain.production != ProductionModel::kFloat32) {
    return InvalidArgument(
        "bounds cover the compute form's float32 production only (--production float32): the raster form's depths "
        "come from the device's rasterizer, which the specification gives no tolerance for, and exact production "
        "decodes with the exact frame");
  }
  return Status::Ok();
}

}  // namespace

Expected<std::vector<CellBound>> BoundCells(const Domain& domain, std::span<const Cell> cells,
                                            const std::filesystem::path& shader_dir, const BoundOptions& options,
                                            const std::function<void(std::size_t, std::size_t)>& progress) {
  DB_RETURN_IF_ERROR(CheckCovered(domain));
  std::vector<CellBound> bounds;
  Programs programs;
  for (const Cell& cell : cells) {
    CellBound bound;
    bound.cell = cell;
    const VariantInfo& variant = cell.variant_info();
    DB_ASSIGN_OR_RETURN(const CellProgram program, ProgramOf(cell, shader_dir, programs));
    if (variant.assumes_symmetric_frustum && domain.OffCentre()) {
      bound.device_shader = bound.exact_shader = bound.total = INFINITY;
      bound.unbounded = "its formula assumes a symmetric frustum, and this domain's is off-centre";
    } else {
      const CellAnalysis analysis(domain, cell, program);
      const Outcome device = Refine(analysis, kVulkanDevice, options.splits, false);
      const Outcome exact = Refine(analysis, kExactlyRounded, options.splits, false);
      const Outcome whole = Refine(analysis, kVulkanDevice, options.splits, true);
      bound.device_shader = device.shader;
      // An exactly rounded machine follows the Vulkan rules too, so the
      // device's bound holds for it; the two refinements split differently.
      bound.exact_shader = std::min(exact.shader, device.shader);
      bound.depth = whole.depth;
      bound.total = whole.total;
      bound.boxes = device.boxes;
      bound.unbounded = !device.why.empty() ? device.why : whole.why;
    }
    bounds.push_back(std::move(bound));
    if (progress) progress(bounds.size(), cells.size());
  }
  return bounds;
}

double LongestRay(const Domain& domain) {
  double tan_x = 0.0, tan_y = 0.0;
  if (domain.eye_fov) {
    const EyeFov& e = *domain.eye_fov;
    tan_x = std::max(std::fabs(e.TanLeft()), std::fabs(e.TanRight()));
    tan_y = std::max(std::fabs(e.TanUp()), std::fabs(e.TanDown()));
  } else {
    tan_y = std::tan(domain.fov_degrees.max * kPi / 360.0);
    tan_x = tan_y * domain.aspect.max;
  }
  if (domain.jitter > 0.0) {
    // A shift of `jitter` pixels moves the lens by 2 jitter / size of its
    // half extent, at most (CellAnalysis::LensOf).
    std::uint32_t width = UINT32_MAX, height = UINT32_MAX;
    for (const Resolution& r : domain.resolutions) {
      width = std::min(width, r.width);
      height = std::min(height, r.height);
    }
    tan_x *= 1.0 + 2.0 * domain.jitter / width;
    tan_y *= 1.0 + 2.0 * domain.jitter / height;
  }
  return std::sqrt(1.0 + tan_x * tan_x + tan_y * tan_y) * (1.0 + 1e-12);
}

struct SampleBounds::State {
  Programs programs;
  std::vector<Cell> cells;
  std::vector<Expected<CellProgram>> cell_programs;
};

Expected<SampleBounds> SampleBounds::Make(std::span<const Cell> cells, const std::filesystem::path& shader_dir) {
  SampleBounds bounds;
  bounds.state_ = std::make_shared<State>();
  State& state = *bounds.state_;
  state.cells.assign(cells.begin(), cells.end());
  for (const Cell& cell : state.cells) state.cell_programs.push_back(ProgramOf(cell, shader_dir, state.programs));
  return bounds;
}

Expected<double> SampleBounds::At(const Cell& cell, const Frame& frame, std::uint32_t pixel_x,
                                  std::uint32_t pixel_y, const Enclosure& stored, const Machine& machine) const {
  const auto found = std::find(state_->cells.begin(), state_->cells.end(), cell);
  if (found == state_->cells.end()) return InvalidArgument(fmt::format("{} was not given to bound", cell.Name()));
  const Expected<CellProgram>& program = state_->cell_programs[found - state_->cells.begin()];
  if (!program.ok()) return program.status();
  // A formula that is wrong in exact arithmetic here has no bound.
  if (cell.variant_info().assumes_symmetric_frustum && (frame.centre_x != 0.0 || frame.centre_y != 0.0))
    return INFINITY;
  const Domain domain;
  const CellAnalysis analysis(domain, cell, *program, true);
  FrameValues<Enclosure> v;
  v.tan_half_fov_y = Enclosure(frame.tan_half_fov_y);
  v.aspect = Enclosure(frame.aspect);
  v.centre_x = Enclosure(frame.centre_x);
  v.centre_y = Enclosure(frame.centre_y);
  v.near = Enclosure(frame.near);
  v.far = Enclosure(frame.finite() ? frame.far : 0.0);
  v.volume_depth = Enclosure(frame.volume_depth);
  v.width = Enclosure(frame.width);
  v.height = Enclosure(frame.height);
  for (int k = 0; k < 3; ++k) v.camera_position[k] = Enclosure(frame.camera_position[k]);
  for (int col = 0; col < 3; ++col) {
    for (int r = 0; r < 3; ++r) v.rotation[col][r] = Enclosure(frame.rotation[col][r]);
  }
  const auto in = analysis.InputsOf(v);
  const Enclosure px(pixel_x), py(pixel_y);
  DB_ASSIGN_OR_RETURN(const auto error, analysis.ShaderError(in, px, py, stored, AtScale(machine)));
  const Enclosure depth = analysis.DenotedDepths(in, stored);
  if (!(depth.lo > 0.0)) return InvalidArgument("stored values that denote no depth in front of the camera");
  return std::min(error.absolute / (depth.lo * CellAnalysis::RayLength(in, px, py)), error.distance_relative);
}

Expected<double> ShaderBoundAt(const Cell& cell, const Frame& frame, std::uint32_t pixel_x, std::uint32_t pixel_y,
                               const Enclosure& stored, const Machine& machine,
                               const std::filesystem::path& shader_dir) {
  DB_ASSIGN_OR_RETURN(const SampleBounds bounds, SampleBounds::Make(std::span<const Cell>(&cell, 1), shader_dir));
  return bounds.At(cell, frame, pixel_x, pixel_y, stored, machine);
}

}  // namespace depthbench::bound
