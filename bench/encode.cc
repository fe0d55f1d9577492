#include "bench/encode.h"

#include <atomic>
#include <bit>
#include <cmath>
#include <limits>

#include "bench/double_double.h"
#include "bench/formulas.h"
#include "bench/formulas_mpfr.h"

namespace depthbench {
namespace {

using DD = DoubleDouble;

// Relative error bounds of the step-2 evaluations: a handful of correctly
// rounded operations, each below 2^-64 (long double) or 2^-104
// (double-double); the bounds leave a wide margin.
constexpr long double kLongDoubleError = 0x1p-59L;
constexpr double kDoubleDoubleError = 0x1p-96;

std::atomic<std::uint64_t> double_double_fallbacks{0};
std::atomic<std::uint64_t> mpfr_fallbacks{0};

// Whether some value within `relative_error` of x rounds to a different
// float than x: i.e. x is that close to a midpoint between two floats.
template <class T, class ToFloat>
bool NearFloatBoundary(T x, T relative_error, ToFloat to_float) {
  float f = to_float(x);
  if (!std::isfinite(f)) return false;
  T tolerance = (x < T(0.0) ? -x : x) * relative_error + T(0x1p-1074);
  for (float neighbour : {std::nextafter(f, -INFINITY), std::nextafter(f, INFINITY)}) {
    T midpoint = (T(static_cast<double>(f)) + T(static_cast<double>(neighbour))) * T(0.5);  // exact
    T distance = midpoint - x;
    if ((distance < T(0.0) ? -distance : distance) <= tolerance) return true;
  }
  return false;
}

// The float nearest to an exact value, evaluated as cheaply as the value
// allows: long double first, double-double and MPFR only near a tie.
template <class Fast, class Precise, class Exact>
float RoundExactly(Fast fast, Precise precise, Exact exact) {
  long double x = fast();
  auto ld_to_float = [](long double v) { return static_cast<float>(v); };
  if (!NearFloatBoundary(x, kLongDoubleError, ld_to_float)) return static_cast<float>(x);
  double_double_fallbacks.fetch_add(1, std::memory_order_relaxed);
  DD y = precise();
  if (!NearFloatBoundary(y, DD(kDoubleDoubleError), [](DD v) { return RoundToFloat(v); })) {
    return RoundToFloat(y);
  }
  mpfr_fallbacks.fetch_add(1, std::memory_order_relaxed);
  return exact().ToFloat();
}

double FarOrZero(const Frame& frame) { return frame.finite() ? frame.far : 0.0; }
constexpr double UnormScale(int bits) { return static_cast<double>((std::uint64_t{1} << bits) - 1); }

// Step 2 for hardware depth: the float32 window depth.
float WindowDepthAsFloat(Convention convention, const Frame& frame, double z) {
  const std::uint32_t bits = Info(convention).bits;
  const double n = frame.near, f = FarOrZero(frame);
  auto fast = [&] { return ld::window_depth_from_eye_depth(n, f, bits, z); };
  auto precise = [&] { return hp::window_depth_from_eye_depth(DD(n), DD(f), bits, DD(z)); };
  auto exact = [&] { return mp::window_depth_from_eye_depth(n, f, bits, z); };
  if ((bits & f32::DB_CONVENTION_CLIP_MINUS_ONE) == 0u) return RoundExactly(fast, precise, exact);
  // GL-style: the rasterizer's float32 is NDC depth, then the viewport
  // transform maps it back to [0, 1] in float32 (exact in double, one rounding).
  float ndc = RoundExactly([&] { return fast() * 2.0L - 1.0L; }, [&] { return precise() * DD(2.0) - DD(1.0); },
                           [&] { return exact() * mp::real(2.0) - mp::real(1.0); });
  return static_cast<float>(0.5 * static_cast<double>(ndc) + 0.5);
}

}  // namespace

EncodeFallbacks EncodeFallbackCounts() { return {double_double_fallbacks.load(), mpfr_fallbacks.load()}; }

float PipelineFloat(Encoding encoding, const Frame& frame, double eye_depth) {
  switch (Info(encoding.format).stores) {
    case DepthInput::kHardware:
      return WindowDepthAsFloat(encoding.convention, frame, eye_depth);
    case DepthInput::kLinear:
      return RoundExactly([&] { return static_cast<long double>(eye_depth) / frame.far; },
                          [&] { return DD(eye_depth) / DD(frame.far); },
                          [&] { return mp::real(eye_depth) / mp::real(frame.far); });
    case DepthInput::kViewZ:
      return static_cast<float>(-eye_depth);
  }
  return 0.0f;
}

std::uint32_t FloatToUnorm(float value, int bits) {
  double clamped = std::fmin(1.0, std::fmax(0.0, static_cast<double>(value)));
  // value * (2^b - 1) is exact in double (24 + 24 bits); nearbyint rounds
  // half to even in the default rounding mode.
  return static_cast<std::uint32_t>(std::nearbyint(clamped * UnormScale(bits)));
}

std::uint16_t FloatToHalf(float value) {
  std::uint16_t sign = std::signbit(value) ? 0x8000 : 0;
  double v = std::fabs(static_cast<double>(value));
  if (std::isnan(value)) return 0x7e00;
  if (v >= 65520.0) return sign | 0x7c00;  // rounds to infinity
  if (v < 0x1p-14) {                        // subnormal half: multiples of 2^-24
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
    case TexelKind::kFloat32:
      return std::bit_cast<float>(code);
    case TexelKind::kFloat16:
      return HalfToFloat(static_cast<std::uint16_t>(code));
    case TexelKind::kUnorm:
      break;
  }
  // code / (2^b - 1) rounded to double and then to float is correctly
  // rounded for b <= 24: the exact quotient's binary expansion repeats with
  // period b, so it never lies within the double's 29 extra bits of a float
  // midpoint unless it is exactly representable. tests/encode_test.cc
  // checks every 16- and 24-bit code against an exact rounding.
  return static_cast<float>(static_cast<double>(code) / UnormScale(info.bits));
}

StoredDepth StoreFloat(Format format, float value) {
  const FormatInfo& info = Info(format);
  std::uint32_t code = 0;
  switch (info.texel) {
    case TexelKind::kUnorm: code = FloatToUnorm(value, info.bits); break;
    case TexelKind::kFloat16: code = FloatToHalf(value); break;
    case TexelKind::kFloat32: code = std::bit_cast<std::uint32_t>(value); break;
  }
  return {code, FetchTexel(format, code)};
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

long double DecodeEyeDepth(Encoding encoding, const Frame& frame, std::uint32_t code) {
  const FormatInfo& info = Info(encoding.format);
  // The code's exact value v and 1 - v, each rounded once.
  long double value, complement;
  if (info.texel == TexelKind::kUnorm) {
    const long double scale = UnormScale(info.bits);
    value = static_cast<long double>(code) / scale;
    complement = static_cast<long double>(scale - code) / scale;
  } else {
    value = FetchTexel(encoding.format, code);  // exact for float formats
    complement = 1.0L - value;                  // exact unless value < 2^-40, then harmless
  }
  switch (info.stores) {
    case DepthInput::kHardware:
      return ld::eye_depth_from_window_depth(frame.near, FarOrZero(frame), Info(encoding.convention).bits, value,
                                             complement);
    case DepthInput::kLinear:
      return value * frame.far;
    case DepthInput::kViewZ:
      return -value;
  }
  return NAN;
}

}  // namespace depthbench
