#include "bench/encode.h"

#include <atomic>
#include <bit>
#include <cmath>

#include "bench/formulas.h"
#include "bench/formulas_mpfr.h"

namespace depthbench {
namespace {

using DD = DoubleDouble;

// Bound on the relative error of the double-double depth formulas (a few
// operations of error below 2^-102 each; tests/reference_test.cc measures
// it against MPFR). Values closer than this to a float rounding boundary are
// rounded from an MPFR evaluation instead.
constexpr double kDoubleDoubleError = 0x1p-96;

std::atomic<std::uint64_t> mpfr_fallbacks{0};

bool NearFloatRoundingBoundary(DD x) {
  float f = RoundToFloat(x);
  if (!std::isfinite(f)) return false;
  double tolerance = std::fabs(x.hi()) * kDoubleDoubleError + 0x1p-1074;
  for (float neighbour : {std::nextafter(f, -INFINITY), std::nextafter(f, INFINITY)}) {
    double midpoint = (static_cast<double>(f) + static_cast<double>(neighbour)) * 0.5;
    if (std::fabs((DD(midpoint) - x).hi()) <= tolerance) return true;
  }
  return false;
}

// The float nearest to the exact value that `approx` approximates; `exact`
// evaluates it in MPFR and is called only for near-ties.
template <class ExactFn>
float RoundExactly(DD approx, ExactFn exact) {
  if (!NearFloatRoundingBoundary(approx)) return RoundToFloat(approx);
  mpfr_fallbacks.fetch_add(1, std::memory_order_relaxed);
  return exact().ToFloat();
}

mp::real Mp(double x) { return mp::real(x); }

double FarOrZero(const Frame& frame) { return frame.finite() ? frame.far : 0.0; }

// Steps 1 and 2 of the pipeline for hardware depth: the float32 window depth.
float WindowDepthAsFloat(Convention convention, const Frame& frame, double z) {
  const std::uint32_t bits = Info(convention).bits;
  const double far = FarOrZero(frame);
  DD window = hp::window_depth_from_eye_depth(DD(frame.near), DD(far), bits, DD(z));
  auto exact_window = [&] { return mp::window_depth_from_eye_depth(Mp(frame.near), Mp(far), bits, Mp(z)); };
  if ((bits & f32::DB_CONVENTION_CLIP_MINUS_ONE) == 0u) return RoundExactly(window, exact_window);
  // GL-style: the rasterizer's float32 is NDC depth, then the viewport
  // transform maps it back to [0, 1] in float32 (exact in double, one rounding).
  float ndc = RoundExactly(window * DD(2.0) - DD(1.0),
                           [&] { return exact_window() * Mp(2.0) - Mp(1.0); });
  return static_cast<float>(0.5 * static_cast<double>(ndc) + 0.5);
}

// Step 3: the format's conversion of a float32 value.
std::uint32_t ConvertFloat(Format format, float value) {
  const FormatInfo& info = Info(format);
  switch (info.texel) {
    case TexelKind::kUnorm:
      return FloatToUnorm(value, info.bits);
    case TexelKind::kFloat16:
      return FloatToHalf(value);
    case TexelKind::kFloat32:
      return std::bit_cast<std::uint32_t>(value);
  }
  return 0;
}

StoredDepth Stored(Format format, std::uint32_t code) { return {code, FetchTexel(format, code)}; }

double UnormScale(int bits) { return std::ldexp(1.0, bits) - 1.0; }

}  // namespace

std::uint64_t MpfrFallbackCount() { return mpfr_fallbacks.load(); }

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
  // Significand in [1024, 2048): ten fraction bits, rounded half to even;
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

DD TexelValue(Format format, std::uint32_t code) {
  const FormatInfo& info = Info(format);
  switch (info.texel) {
    case TexelKind::kUnorm:
      return DD(static_cast<double>(code)) / DD(UnormScale(info.bits));
    case TexelKind::kFloat16:
      return DD(HalfToFloat(static_cast<std::uint16_t>(code)));
    case TexelKind::kFloat32:
      return DD(std::bit_cast<float>(code));
  }
  return DD(NAN);
}

float FetchTexel(Format format, std::uint32_t code) {
  const FormatInfo& info = Info(format);
  if (info.texel != TexelKind::kUnorm) return static_cast<float>(TexelValue(format, code).hi());
  // code / (2^b - 1) correctly rounded: |g * (2^b - 1) - code| is exact in
  // double for any float g, so the nearest float can be picked exactly.
  const double scale = UnormScale(info.bits);
  const double c = code;
  float best = static_cast<float>(c / scale);
  auto error = [&](float g) { return std::fabs(static_cast<double>(g) * scale - c); };
  for (float g : {std::nextafter(best, -INFINITY), std::nextafter(best, INFINITY)}) {
    bool even = (std::bit_cast<std::uint32_t>(g) & 1u) == 0u;
    if (error(g) < error(best) || (error(g) == error(best) && even)) best = g;
  }
  return best;
}

StoredDepth EncodeEyeDepth(Encoding encoding, const Frame& frame, double eye_depth) {
  const Format format = encoding.format;
  float value = 0.0f;
  switch (Info(format).stores) {
    case DepthInput::kHardware:
      value = WindowDepthAsFloat(encoding.convention, frame, eye_depth);
      break;
    case DepthInput::kLinear:
      value = RoundExactly(DD(eye_depth) / DD(frame.far),
                           [&] { return Mp(eye_depth) / Mp(frame.far); });
      break;
    case DepthInput::kViewZ:
      value = static_cast<float>(-eye_depth);
      break;
  }
  return Stored(format, ConvertFloat(format, value));
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
    return Stored(format, std::bit_cast<std::uint32_t>(value));
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
  return Stored(format, code);
}

DD DecodeEyeDepth(Encoding encoding, const Frame& frame, std::uint32_t code) {
  DD value = TexelValue(encoding.format, code);
  switch (Info(encoding.format).stores) {
    case DepthInput::kHardware:
      return hp::eye_depth_from_window_depth(DD(frame.near), DD(FarOrZero(frame)),
                                             Info(encoding.convention).bits, value);
    case DepthInput::kLinear:
      return value * DD(frame.far);
    case DepthInput::kViewZ:
      return -value;
  }
  return DD(NAN);
}

}  // namespace depthbench
