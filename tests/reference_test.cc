// The reference against independent high-precision evaluations (MPFR), and
// every variant's formula, evaluated in double-double with exact constants,
// against the reference.
#include <bit>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "bench/numerics/formulas.h"
#include "bench/numerics/formulas_mpfr.h"
#include "bench/pipeline/encode.h"
#include "bench/pipeline/reference.h"
#include "bench/pipeline/sampler.h"
#include "bench/pipeline/shader_constants.h"

namespace depthbench {
namespace {

using DD = DoubleDouble;

double RelativeDifference(DD a, const mp::real& b) {
  return std::fabs((((mp::real(a.hi()) + mp::real(a.lo())) - b) / b).ToDouble());
}

// The textbook decode z = B / (d - A) with the textbook coefficients, in
// MPFR at 400 bits: an independent formulation of what the stored value
// denotes (at that precision its cancellation costs nothing).
mp::real TextbookDecode(Convention c, double near, double far, const mp::real& d) {
  const mp::real n(near), f(far);
  mp::real a, b;
  const std::uint32_t bits = Info(c).bits;
  const bool reversed = bits & 1u, infinite = bits & 2u;
  if (bits & 8u) {  // orthographic: d = (z - n) / (f - n), or (f - z) / (f - n) reversed
    return reversed ? f - d * (f - n) : n + d * (f - n);
  }
  if (infinite) {
    a = reversed ? mp::real(0.0) : mp::real(1.0);
    b = reversed ? n : -n;
  } else {
    a = reversed ? -n / (f - n) : f / (f - n);
    b = reversed ? n * f / (f - n) : -(n * f) / (f - n);
  }
  return b / (d - a);
}

TEST(ReferenceTest, DecodeIsFarBelowFloatRounding) {
  // Random codes of every hardware encoding at far/near up to 1e12,
  // with half of them in the last 2^-20 before the far plane, where the
  // textbook decode cancels catastrophically.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double worst = 0.0;
  for (const Encoding& e : AllEncodings()) {
    if (!Info(e.convention).hardware) continue;
    const std::uint32_t max_code =
        Info(e.format).texel == TexelKind::kUnorm ? (1u << Info(e.format).bits) - 1 : 0x3f800000u;
    for (int k = 0; k < 2000; ++k) {
      const double near = std::exp(std::log(1e-6) + unit(rng) * std::log(1e7));
      const double far = near * std::exp(std::log(10.0) + unit(rng) * std::log(1e11));
      Frame frame;
      frame.near = near;
      frame.far = (Info(e.convention).bits & 2u) ? INFINITY : far;
      std::uint32_t code = static_cast<std::uint32_t>(unit(rng) * max_code);
      if (k % 2 == 0) code = max_code - static_cast<std::uint32_t>(unit(rng) * std::min(max_code, 1u << 12));
      const StoredDepth stored{code, FetchTexel(e.format, code)};
      const DD z = DecodeEyeDepth(e, ProductionModel::kExact, frame, stored.fetched);
      if (!std::isfinite(z.hi()) || z.hi() <= 0.0) continue;
      // The fetched value (what the shader reads), exactly.
      mp::real d = mp::real(stored.fetched);
      const mp::real exact = TextbookDecode(e.convention, near, far, d);
      worst = std::max(worst, RelativeDifference(z, exact));
    }
  }
  // 2^-96: a handful of double-double operations (2^-103 each) and room to
  // spare, 72 bits below float32's 2^-24.
  EXPECT_LT(worst, std::ldexp(1.0, -96));
}

TEST(ReferenceTest, DoubleDoubleArithmeticMatchesMpfr) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  auto to_mp = [](DD x) { return mp::real(x.hi()) + mp::real(x.lo()); };
  double worst = 0.0;
  for (int k = 0; k < 20000; ++k) {
    DD a = DD(std::ldexp(unit(rng), k % 40 - 20)) / DD(3.0), b = DD(std::ldexp(unit(rng), k % 17 - 8)) * DD(7.0);
    for (auto [dd, exact] : {std::pair{a + b, to_mp(a) + to_mp(b)}, std::pair{a * b, to_mp(a) * to_mp(b)},
                             std::pair{a / b, to_mp(a) / to_mp(b)}}) {
      worst = std::max(worst, std::fabs(((to_mp(dd) - exact) / exact).ToDouble()));
    }
  }
  EXPECT_LT(worst, std::ldexp(1.0, -100));  // double-double's ~106 bits, less a few roundings
}

// NextFloat steps through the bits instead of calling std::nextafter: the
// same answer at zero of either sign, across the subnormal and normal
// boundary, at the largest float (to infinity) and for random floats.
// RoundToFloat relies on it to tell a tie between two floats.
TEST(ReferenceTest, NextFloatIsNextafter) {
  std::vector<float> values = {0.0f,
                               -0.0f,
                               std::numeric_limits<float>::denorm_min(),
                               -std::numeric_limits<float>::denorm_min(),
                               std::numeric_limits<float>::min(),
                               -std::numeric_limits<float>::min(),
                               std::numeric_limits<float>::max(),
                               -std::numeric_limits<float>::max(),
                               1.0f,
                               -1.0f,
                               0x1p-126f * 0.5f};
  std::mt19937 rng(5);
  for (int k = 0; k < 100000; ++k) {
    const float f = std::bit_cast<float>(static_cast<std::uint32_t>(rng()));
    if (std::isfinite(f)) values.push_back(f);
  }
  for (float f : values) {
    for (bool up : {false, true}) {
      const float expected = std::nextafter(f, up ? INFINITY : -INFINITY);
      ASSERT_EQ(std::bit_cast<std::uint32_t>(NextFloat(f, up)), std::bit_cast<std::uint32_t>(expected))
          << f << (up ? " up" : " down");
    }
  }
  // A tie between 1 and the next float: the low part decides.
  const double tie = (1.0 + static_cast<double>(NextFloat(1.0f, true))) / 2.0;
  EXPECT_EQ(RoundToFloat(DD::FromParts(tie, 0x1p-80)), NextFloat(1.0f, true));
  EXPECT_EQ(RoundToFloat(DD::FromParts(tie, -0x1p-80)), 1.0f);
  EXPECT_EQ(RoundToFloat(DD::FromParts(-tie, 0x1p-80)), -1.0f);
}

TEST(ReferenceTest, NaiveDoubleDecodeIsNotEnoughAtHighRatios) {
  // Why the reference does not use B / (d - A) in double: at far/near = 1e9
  // a stored value one D24 step below 1 decodes with an error far above
  // float32's rounding.
  const double near = 1.0, far = 1e9;
  const double a = far / (far - near), b = -near * far / (far - near);
  const std::uint32_t code = (1u << 24) - 2;
  const double d = code / (std::ldexp(1.0, 24) - 1.0);
  const double naive = b / (d - a);
  const mp::real exact =
      TextbookDecode(Convention::kStandard, near, far, mp::real(code) / mp::real(std::ldexp(1.0, 24) - 1.0));
  EXPECT_GT(std::fabs(((mp::real(naive) - exact) / exact).ToDouble()), std::ldexp(1.0, -30));
  Frame frame;
  frame.near = near;
  frame.far = far;
  const mp::real exact_fetched =
      TextbookDecode(Convention::kStandard, near, far, mp::real(FetchTexel(Format::kX8D24Unorm, code)));
  EXPECT_LT(RelativeDifference(DecodeEyeDepth({Convention::kStandard, Format::kX8D24Unorm}, ProductionModel::kExact,
                                              frame, FetchTexel(Format::kX8D24Unorm, code)),
                               exact_fetched),
            std::ldexp(1.0, -96));
}

// Every variant's formula, instantiated in double-double with the exact
// constants, must land on the point the stored value denotes: this checks
// the algebra of each restated seed independently of float rounding.
TEST(ReferenceTest, EveryVariantFormulaIsExactInHighPrecision) {
  Domain perspective;
  perspective.camera_distance = {0.0, 1e3};
  // An off-centre view volume, as a shadow map fitted to a view's frustum
  // has.
  Domain orthographic = perspective;
  orthographic.orthographic = ViewVolume{-40.0, 60.0, -20.0, 35.0};
  orthographic.infinite_far = false;
  const Sampler perspective_sampler(5, perspective), orthographic_sampler(5, orthographic);
  for (const Cell& cell : AllCells()) {
    const Sampler& sampler = Info(cell.convention).orthographic() ? orthographic_sampler : perspective_sampler;
    hp::WorldPositionFn formula = nullptr;
    switch (cell.variant) {
      case Variant::kFrustumRay: formula = hp::frustum_ray_world_position; break;
      case Variant::kVolumeRay: formula = hp::volume_ray_world_position; break;
      case Variant::kTanAspect: formula = hp::tan_aspect_world_position; break;
      case Variant::kEyeRay: formula = hp::eye_ray_world_position; break;
      case Variant::kInverseVp: formula = hp::inverse_vp_world_position; break;
      case Variant::kDivide: formula = hp::divide_world_position; break;
      case Variant::kReciprocal: formula = hp::reciprocal_world_position; break;
      case Variant::kPq: formula = hp::pq_world_position; break;
      case Variant::kOrthoLerp: formula = hp::ortho_lerp_world_position; break;
    }
    double worst = 0.0;
    for (std::uint64_t f = 0; f < 40; ++f) {
      const Frame frame = sampler.FrameAt(f);
      const hp::FrameParams params = BuildFrameParams(frame);
      const hp::DepthParams depth =
          Info(cell.convention).hardware ? BuildDepthParams(frame, params, cell.convention) : hp::DepthParams{};
      for (std::uint64_t i = f * kSamplesPerFrame; i < f * kSamplesPerFrame + 8; ++i) {
        const PixelSample sample = sampler.SampleAt(i, frame);
        if (sample.pick != DepthPick::kEyeDepth) continue;
        const StoredDepth stored = EncodeEyeDepth(cell.encoding(), ProductionModel::kExact, frame, sample.eye_depth);
        const double z = DecodeEyeDepth(cell.encoding(), ProductionModel::kExact, frame, stored.fetched).hi();
        if (!std::isfinite(z) || z <= 0.0) continue;
        // The fetched value, as the formula reads it.
        const DD value(static_cast<double>(stored.fetched));
        hp::vec2 uv = hp::uv_from_pixel(DD(sample.x), DD(sample.y), params.resolution);
        hp::vec3 p = formula(params, depth, uv, value);
        const glm::dvec3 ray = PixelRay(frame, sample.x, sample.y);
        const glm::dvec3 offset = PixelOffset(frame, sample.x, sample.y);
        const double distance = glm::length(offset + z * ray);
        for (int k = 0; k < 3; ++k) {
          // Camera-relative, so that world magnitudes do not enter.
          const double relative = (p[k] - DD(frame.camera_position[k])).ToDouble();
          worst = std::max(worst, std::fabs(relative - offset[k] - z * ray[k]) / distance);
        }
      }
    }
    // The expected point is the double ray times the long double depth,
    // good to a few 2^-53; double-double formulas, even those that cancel 27
    // bits at far/near 1e8, stay below 2^-70. A wrong formula is off by far
    // more than 2^-45.
    EXPECT_LT(worst, std::ldexp(1.0, -45)) << cell.Name();
  }
}

}  // namespace
}  // namespace depthbench
