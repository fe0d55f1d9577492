#include "bench/pipeline/encode.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

#include "bench/numerics/double_double.h"
#include "bench/numerics/formulas.h"
#include "bench/numerics/formulas_mpfr.h"

namespace depthbench {
namespace {

using DD = DoubleDouble;

// Relative error bound of the double-double evaluations of step 2: a
// handful of operations, each below 2^-103.
constexpr double kDoubleDoubleError = 0x1p-96;

std::atomic<std::uint64_t> tie_fallbacks{0};
std::atomic<std::uint64_t> mpfr_fallbacks{0};

double FarOrZero(const Frame& frame) { return frame.finite() ? frame.far : 0.0; }
constexpr double UnormScale(int bits) { return static_cast<double>((std::uint64_t{1} << bits) - 1); }

using Float4 = float __attribute__((vector_size(16)));
using Bits4 = std::uint64_t __attribute__((vector_size(32)));

// The float nearest to the exact value x that `v` approximates (relative
// error below kDoubleDoubleError), four lanes at a time. float(hi) is right
// unless hi lies exactly halfway between two floats: then the low 29 of its
// 52 fraction bits read 1000...0 (in the normal range of floats). Those
// lanes, and float subnormals and non-finite values, go through `scalar`,
// which is given the lane's index. Only the first `lanes` lanes are real.
template <class Scalar>
Float4 RoundToFloat4(DoubleDouble4 v, int lanes, Scalar scalar) {
  const Double4 hi = v.hi();
  Float4 f = __builtin_convertvector(hi, Float4);
  const Bits4 bits = reinterpret_cast<Bits4>(hi);
  const Double4 magnitude = reinterpret_cast<Double4>(bits & 0x7fffffffffffffffull);
  const auto midpoint = (bits & 0x1fffffffull) == 0x10000000ull;
  const auto ordinary = magnitude >= 0x1p-126 && magnitude < 0x1p127;
  const auto special = midpoint | !ordinary;
  for (int k = 0; k < lanes; ++k) {
    if (special[k]) f[k] = scalar(k, DoubleDouble::FromParts(hi[k], v.lo()[k]));
  }
  return f;
}

// A lane RoundToFloat4 could not settle: outside the normal range of
// floats, or on a midpoint between two floats, where the low part decides
// unless it is within the error bound (then MPFR does).
template <class Exact>
float SettleLane(DoubleDouble x, Exact exact) {
  const double hi = x.hi();
  const float f = static_cast<float>(hi);
  if (!std::isfinite(f) || static_cast<double>(f) == hi) return f;
  const float g = NextFloat(f, hi > static_cast<double>(f));
  if (hi != (static_cast<double>(f) + static_cast<double>(g)) * 0.5) return f;  // not a tie
  tie_fallbacks.fetch_add(1, std::memory_order_relaxed);
  if (std::fabs(x.lo()) > std::fabs(hi) * kDoubleDoubleError) return RoundToFloat(x);
  mpfr_fallbacks.fetch_add(1, std::memory_order_relaxed);
  return exact().ToFloat();
}

// Steps 1 and 2 for four samples under kExact: the exact value in
// double-double, then correctly rounded to float32 (GL-style clip depth:
// NDC depth, then the viewport transform in float32, exact in double with
// one rounding).
Float4 ExactPipelineFloat4(Encoding encoding, const double* near, const double* far, const double* z, int lanes) {
  const std::uint32_t bits = Info(encoding.convention).bits;
  Double4 n, f, depth;
  for (int k = 0; k < 4; ++k) {
    n[k] = near[k];
    f[k] = far[k];
    depth[k] = z[k];
  }
  const auto wide = [](Double4 x) { return DoubleDouble4::FromParts(x, Double4{}); };
  auto exact_window = [&](int k) { return mp::window_depth_from_eye_depth(near[k], far[k], bits, z[k]); };
  switch (Info(encoding.format).stores) {
    case DepthInput::kHardware: {
      const DoubleDouble4 window = hp4::window_depth_from_eye_depth(wide(n), wide(f), bits, wide(depth));
      if ((bits & f32::DB_CONVENTION_CLIP_MINUS_ONE) == 0u) {
        return RoundToFloat4(window, lanes,
                             [&](int k, DoubleDouble x) { return SettleLane(x, [&] { return exact_window(k); }); });
      }
      const Float4 ndc =
          RoundToFloat4(window * DoubleDouble4(2.0) - DoubleDouble4(1.0), lanes, [&](int k, DoubleDouble x) {
            return SettleLane(x, [&] { return exact_window(k) * mp::real(2.0) - mp::real(1.0); });
          });
      return __builtin_convertvector(0.5 * __builtin_convertvector(ndc, Double4) + 0.5, Float4);
    }
    case DepthInput::kLinear:
      return RoundToFloat4(wide(depth) / wide(f), lanes, [&](int k, DoubleDouble x) {
        return SettleLane(x, [&] { return mp::real(z[k]) / mp::real(far[k]); });
      });
    case DepthInput::kViewZ: return __builtin_convertvector(-depth, Float4);
  }
  return Float4{};
}

// Steps 1 and 2 under kFloat32 for n samples: every operation in float32,
// on the view-space depth an engine holds and the mapping's float32
// constants. The switch stands outside the loops, which the compiler then
// runs in SIMD lanes (-ffp-contract=off keeps a multiply and an add from
// fusing).
void Float32PipelineFloats(Encoding encoding, const double* a, const double* b, const double* z, std::size_t n,
                           float* out) {
  const auto f = [](double x) { return static_cast<float>(x); };
  switch (Info(encoding.format).stores) {
    case DepthInput::kHardware: {
      const std::uint32_t bits = Info(encoding.convention).bits;
      const bool gl = (bits & f32::DB_CONVENTION_CLIP_MINUS_ONE) != 0u;
      if ((bits & f32::DB_CONVENTION_ORTHOGRAPHIC) != 0u) {
        // glm::ortho's clip z, -B * view.z + A with view.z = -z (the sign
        // flips exactly), and w = 1: no divide.
        if (!gl) {
          for (std::size_t i = 0; i < n; ++i) out[i] = f(b[i]) * f(z[i]) + f(a[i]);
        } else {
          for (std::size_t i = 0; i < n; ++i) out[i] = (f(b[i]) * f(z[i]) + f(a[i])) * 0.5f + 0.5f;
        }
      } else if (!gl) {
        for (std::size_t i = 0; i < n; ++i) out[i] = (f(a[i]) * f(z[i]) + f(b[i])) / f(z[i]);
      } else {
        for (std::size_t i = 0; i < n; ++i) out[i] = (f(a[i]) * f(z[i]) + f(b[i])) / f(z[i]) * 0.5f + 0.5f;
      }
      return;
    }
    case DepthInput::kLinear:
      for (std::size_t i = 0; i < n; ++i) out[i] = f(z[i]) / f(a[i]);
      return;
    case DepthInput::kViewZ:
      for (std::size_t i = 0; i < n; ++i) out[i] = -f(z[i]);
      return;
  }
}

}  // namespace

EncodeFallbacks EncodeFallbackCounts() { return {tie_fallbacks.load(), mpfr_fallbacks.load()}; }

void FrameMapping(Encoding encoding, const Frame& frame, double& a, double& b) {
  // What shader_constants.cc rounds for the shaders: the exact coefficients
  // (and the far plane) rounded once to float32.
  a = b = 0.0;
  switch (Info(encoding.format).stores) {
    case DepthInput::kHardware: {
      const hp::vec2 ab =
          hp::ndc_depth_coefficients(DD(frame.near), DD(FarOrZero(frame)), Info(encoding.convention).bits);
      a = RoundToFloat(ab.x);
      b = RoundToFloat(ab.y);
      return;
    }
    case DepthInput::kLinear: a = static_cast<float>(FarOrZero(frame)); return;
    case DepthInput::kViewZ: return;
  }
}

void PipelineFloats(Encoding encoding, ProductionModel model, const DepthMappings& mapping, const double* eye_depth,
                    std::size_t n, float* out) {
  if (model == ProductionModel::kFloat32) {
    Float32PipelineFloats(encoding, mapping.a, mapping.b, eye_depth, n, out);
    return;
  }
  for (std::size_t i = 0; i < n; i += 4) {
    double lanes[3][4];
    for (std::size_t k = 0; k < 4; ++k) {
      const std::size_t at = i + k < n ? i + k : n - 1;  // pad the tail
      lanes[0][k] = mapping.near[at];
      lanes[1][k] = mapping.far[at];
      lanes[2][k] = eye_depth[at];
    }
    const Float4 f = ExactPipelineFloat4(encoding, lanes[0], lanes[1], lanes[2],
                                         static_cast<int>(std::min<std::size_t>(4, n - i)));
    for (std::size_t k = 0; k < 4 && i + k < n; ++k) out[i + k] = f[k];
  }
}

namespace {

// The mapping of one frame and encoding, as one-element arrays.
struct OneMapping {
  double near, far, a, b;
  OneMapping(Encoding encoding, const Frame& frame) : near(frame.near), far(FarOrZero(frame)) {
    FrameMapping(encoding, frame, a, b);
  }
  DepthMappings Arrays() const { return {&near, &far, &a, &b}; }
};

}  // namespace

float PipelineFloat(Encoding encoding, ProductionModel model, const Frame& frame, double eye_depth) {
  const OneMapping mapping(encoding, frame);
  float out;
  PipelineFloats(encoding, model, mapping.Arrays(), &eye_depth, 1, &out);
  return out;
}

std::uint32_t FloatToUnorm(float value, int bits) {
  const Format format = bits == 16 ? Format::kD16Unorm : Format::kX8D24Unorm;
  return StoreFloat(format, value).code;
}

std::uint16_t FloatToHalf(float value) {
  std::uint16_t sign = std::signbit(value) ? 0x8000 : 0;
  double v = std::fabs(static_cast<double>(value));
  if (std::isnan(value)) return 0x7e00;
  if (v >= 65520.0) return sign | 0x7c00;  // rounds to infinity
  if (v < 0x1p-14) {                       // subnormal half: multiples of 2^-24
    return sign | static_cast<std::uint16_t>(std::nearbyint(v * 0x1p24));
  }
  int exponent;
  double mantissa = std::frexp(v, &exponent);  // v = mantissa * 2^exponent, mantissa in [0.5, 1)
  // Significand in [1024, 2048]: ten fraction bits, rounded half to even;
  // a carry to 2048 lands on the next binade, which the packing absorbs.
  auto significand = static_cast<std::uint32_t>(std::nearbyint(mantissa * 2048.0));
  std::uint32_t biased = static_cast<std::uint32_t>(exponent - 1 + 15);
  return static_cast<std::uint16_t>(sign | ((biased << 10) + (significand - 1024)));
}

float HalfToFloat(std::uint16_t half) {
  const bool negative = (half & 0x8000) != 0;
  const int exponent = (half >> 10) & 0x1f;
  const int fraction = half & 0x3ff;
  double magnitude;
  if (exponent == 0) {
    magnitude = std::ldexp(static_cast<double>(fraction), -24);
  } else if (exponent == 31) {
    magnitude = fraction == 0 ? INFINITY : NAN;
  } else {
    magnitude = std::ldexp(1024.0 + fraction, exponent - 25);
  }
  return static_cast<float>(negative ? -magnitude : magnitude);
}

float FetchTexel(Format format, std::uint32_t code) {
  const FormatInfo& info = Info(format);
  switch (info.texel) {
    case TexelKind::kFloat32: return std::bit_cast<float>(code);
    case TexelKind::kFloat16: return HalfToFloat(static_cast<std::uint16_t>(code));
    case TexelKind::kUnorm: break;
  }
  // code / (2^b - 1) rounded to double and then to float is correctly
  // rounded for b <= 24: the exact quotient's binary expansion repeats with
  // period b, so it never lies within the double's 29 extra bits of a float
  // midpoint unless it is exactly representable. tests/encode_test.cc
  // checks every 16- and 24-bit code against an exact rounding.
  // (The product with the rounded reciprocal is within 2^-52 of the
  // quotient: still 28 bits of room.)
  return static_cast<float>(static_cast<double>(code) * (1.0 / UnormScale(info.bits)));
}

std::uint32_t CodeSignBit(Format format) {
  switch (Info(format).texel) {
    case TexelKind::kUnorm: return 0;
    case TexelKind::kFloat32: return 1u << 31;
    case TexelKind::kFloat16: return 1u << 15;
  }
  return 0;
}

std::uint32_t CodeDistance(Format format, std::uint32_t a, std::uint32_t b) {
  const std::uint32_t sign = CodeSignBit(format);
  const std::int64_t x = CodeOnLine(a, sign), y = CodeOnLine(b, sign);
  const std::int64_t distance = x > y ? x - y : y - x;
  return static_cast<std::uint32_t>(std::min<std::int64_t>(distance, std::numeric_limits<std::uint32_t>::max()));
}

void StoreFloats(Format format, const float* values, std::size_t n, std::uint32_t* codes, float* fetched) {
  const FormatInfo& info = Info(format);
  switch (info.texel) {
    case TexelKind::kUnorm: {
      // value * (2^b - 1) is exact in double (24 + 24 bits) and rounded to
      // the nearest integer, ties to even: adding and taking away 2^52 does
      // that in the default rounding mode for values below 2^52, four at a
      // time. NaN clamps to 0. The fetch: see FetchTexel.
      const double scale = UnormScale(info.bits), inverse = 1.0 / scale;
      const auto encode = [&](auto v) {
        using D = decltype(v);
        const D zero{}, one = zero + 1.0;
        const D clamped = v > 0.0 ? (v < 1.0 ? v : one) : zero;
        return (clamped * scale + 0x1p52) - 0x1p52;
      };
      std::size_t i = 0;
      for (; i + 4 <= n; i += 4) {
        Float4 f;
        std::memcpy(&f, values + i, sizeof(f));
        const Double4 code = encode(__builtin_convertvector(f, Double4));
        const auto c = __builtin_convertvector(code, std::int32_t __attribute__((vector_size(16))));
        const Float4 fetch = __builtin_convertvector(code * inverse, Float4);
        std::memcpy(codes + i, &c, sizeof(c));
        std::memcpy(fetched + i, &fetch, sizeof(fetch));
      }
      for (; i < n; ++i) {
        const double code = encode(static_cast<double>(values[i]));
        codes[i] = static_cast<std::uint32_t>(code);
        fetched[i] = static_cast<float>(code * inverse);
      }
      return;
    }
    case TexelKind::kFloat16:
      for (std::size_t i = 0; i < n; ++i) {
        codes[i] = FloatToHalf(values[i]);
        fetched[i] = HalfToFloat(static_cast<std::uint16_t>(codes[i]));
      }
      return;
    case TexelKind::kFloat32:
      for (std::size_t i = 0; i < n; ++i) {
        codes[i] = std::bit_cast<std::uint32_t>(values[i]);
        fetched[i] = values[i];
      }
      return;
  }
}

StoredDepth StoreFloat(Format format, float value) {
  StoredDepth stored;
  StoreFloats(format, &value, 1, &stored.code, &stored.fetched);
  return stored;
}

StoredDepth EncodeEdge(Encoding encoding, const Frame& frame, DepthPick pick) {
  const Format format = encoding.format;
  const FormatInfo& info = Info(format);
  if (info.stores == DepthInput::kViewZ) {
    // View z runs from 0 (the camera) to -far: the edges of that range.
    float far_z = static_cast<float>(-frame.depth_limit);
    float value = 0.0f;
    switch (pick) {
      case DepthPick::kStoredZero: value = -0.0f; break;
      case DepthPick::kStoredOne: value = far_z; break;
      case DepthPick::kStoredAfterZero: value = -std::numeric_limits<float>::denorm_min(); break;
      case DepthPick::kStoredBeforeOne: value = std::nextafter(far_z, 0.0f); break;
      case DepthPick::kEyeDepth: break;
    }
    return StoreFloat(format, value);
  }
  std::uint32_t one = 0;
  switch (info.texel) {
    case TexelKind::kUnorm: one = static_cast<std::uint32_t>(UnormScale(info.bits)); break;
    case TexelKind::kFloat16: one = 0x3c00; break;
    case TexelKind::kFloat32: one = std::bit_cast<std::uint32_t>(1.0f); break;
  }
  // For every format the codes of [0, 1] are consecutive integers, so the
  // steps next to the ends are one code away.
  std::uint32_t code = 0;
  switch (pick) {
    case DepthPick::kStoredZero: code = 0; break;
    case DepthPick::kStoredOne: code = one; break;
    case DepthPick::kStoredAfterZero: code = 1; break;
    case DepthPick::kStoredBeforeOne: code = one - 1; break;
    case DepthPick::kEyeDepth: break;
  }
  return {code, FetchTexel(format, code)};
}

namespace {

// The eye depth four float values denote (each exact as a double).
[[gnu::always_inline]] inline DoubleDouble4 DecodeValue(Encoding encoding, ProductionModel model, Double4 near,
                                                        Double4 far, Double4 a, Double4 b, Double4 value) {
  using DD = DoubleDouble4;
  const auto wide = [](Double4 x) { return DD::FromParts(x, Double4{}); };
  const std::uint32_t bits = Info(encoding.convention).bits;
  switch (Info(encoding.format).stores) {
    case DepthInput::kHardware: {
      if (model == ProductionModel::kExact) {
        // 1 - value is exact in double-double, and the decode needs no
        // difference of nearly equal numbers.
        return hp4::eye_depth_from_window_depth(wide(near), wide(far), bits, wide(value), DD(1.0) - wide(value));
      }
      const DD ndc = (bits & f32::DB_CONVENTION_CLIP_MINUS_ONE) == 0u ? wide(value) : wide(value) * DD(2.0) - DD(1.0);
      // (The difference of two floats is exact in double-double.)
      if ((bits & f32::DB_CONVENTION_ORTHOGRAPHIC) != 0u) return (ndc - wide(a)) / wide(b);
      return wide(b) / (ndc - wide(a));
    }
    case DepthInput::kLinear: return wide(value) * wide(model == ProductionModel::kExact ? far : a);
    case DepthInput::kViewZ: return -wide(value);
  }
  return DD(NAN);
}

[[gnu::always_inline]] inline void DecodeEyeDepthsBody(Encoding encoding, ProductionModel model,
                                                       const DepthMappings& mapping, const float* values, std::size_t n,
                                                       double* hi, double* lo) {
  // Two groups of four per step: their dependency chains interleave.
  constexpr std::size_t kStep = 8;
  const auto decode = [&](const Double4(&in)[5][2]) __attribute__((always_inline)) {
    std::array<DoubleDouble4, 2> z;
    for (int g = 0; g < 2; ++g) z[g] = DecodeValue(encoding, model, in[0][g], in[1][g], in[2][g], in[3][g], in[4][g]);
    return z;
  };
  const double* arrays[4] = {mapping.near, mapping.far, mapping.a, mapping.b};
  std::size_t i = 0;
  for (; i + kStep <= n; i += kStep) {  // whole steps: lanes loaded and stored whole
    Double4 in[5][2];
    for (int g = 0; g < 2; ++g) {
      const std::size_t at = i + 4 * g;
      for (int p = 0; p < 4; ++p) std::memcpy(&in[p][g], arrays[p] + at, sizeof(Double4));
      Float4 f;
      std::memcpy(&f, values + at, sizeof(f));
      in[4][g] = __builtin_convertvector(f, Double4);
    }
    const std::array<DoubleDouble4, 2> z = decode(in);
    for (int g = 0; g < 2; ++g) {
      const Double4 h = z[g].hi(), l = z[g].lo();
      std::memcpy(hi + i + 4 * g, &h, sizeof(h));
      if (lo != nullptr) std::memcpy(lo + i + 4 * g, &l, sizeof(l));
    }
  }
  if (i < n) {  // the tail, padded with its last sample
    Double4 in[5][2];
    for (std::size_t k = 0; k < kStep; ++k) {
      const std::size_t at = i + k < n ? i + k : n - 1;
      for (int p = 0; p < 4; ++p) in[p][k / 4][k % 4] = arrays[p][at];
      in[4][k / 4][k % 4] = static_cast<double>(values[at]);
    }
    const std::array<DoubleDouble4, 2> z = decode(in);
    for (std::size_t k = 0; i + k < n; ++k) {
      hi[i + k] = z[k / 4].hi()[k % 4];
      if (lo != nullptr) lo[i + k] = z[k / 4].lo()[k % 4];
    }
  }
}

}  // namespace

void DecodeEyeDepths(Encoding encoding, ProductionModel model, const DepthMappings& mapping, const float* values,
                     std::size_t n, double* hi, double* lo, Isa isa) {
  RunWith(
      isa, [&](auto)
               __attribute__((always_inline)) { DecodeEyeDepthsBody(encoding, model, mapping, values, n, hi, lo); });
}

DoubleDouble DecodeEyeDepth(Encoding encoding, ProductionModel model, const Frame& frame, float value) {
  const OneMapping mapping(encoding, frame);
  double hi, lo;
  DecodeEyeDepths(encoding, model, mapping.Arrays(), &value, 1, &hi, &lo);
  return DoubleDouble::FromParts(hi, lo);
}

}  // namespace depthbench
