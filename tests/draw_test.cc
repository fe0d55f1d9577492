// shared/draw.h, the sampler's float64 draw that a device repeats bit for
// bit (tests/device_judge_test.cc holds the device's draws equal to these):
// here, that it is close enough to exact for what it defines, and that it
// draws what the sampler promises.
#include <cmath>
#include <cstdint>

#include <gtest/gtest.h>

#include "bench/pipeline/draw.h"
#include "bench/pipeline/reference.h"
#include "bench/pipeline/sampler.h"

namespace depthbench {
namespace {

// Units in the last place of a double near x.
double Ulps(double value, long double exact) {
  const double ulp = std::nextafter(static_cast<double>(exact), INFINITY) - static_cast<double>(exact);
  return static_cast<double>(std::fabs(static_cast<long double>(value) - exact)) / ulp;
}

// 2^x against long double's exp2 (64-bit significand, so its own error is
// below 2^-11 of a double's ulp). The bound: e^t's seventeen Horner steps
// keep every partial sum in [1, 2), each rounded once (half an ulp), and
// the rounding of t = frac(x) ln 2 moves e^t by at most 0.7 ulp: about
// two ulps in all, doubled for slack. Four ulps is 2^-50 relative, 26
// bits below float32's rounding.
TEST(DrawTest, Exp2IsWithinFourUlpsOfTheExactPower) {
  double worst = 0.0;
  for (int k = 0; k <= 200000; ++k) {
    const double x = -1.0 + 65.0 * k / 200000.0;
    worst = std::max(worst, Ulps(draw::draw_exp2(x), std::exp2(static_cast<long double>(x))));
  }
  EXPECT_LE(worst, 4.0);
  EXPECT_GT(worst, 0.0);  // (a polynomial, not a library call)
}

// Whole powers are exact (t = 0 leaves the polynomial at 1), so a draw at
// the unit's ends lands on the range's ends: lo * 2^0 = lo.
TEST(DrawTest, Exp2OfAnIntegerIsExact) {
  for (int k = -60; k <= 60; ++k) EXPECT_EQ(draw::draw_exp2(k), std::ldexp(1.0, k)) << k;
}

// The float64 ray against the same formula in long double, component by
// component, over the frames and pixels the wide domain draws. With S =
// tan_x + tan_y + 1: the NDC coordinate is within 3 * 2^-53 of exact (the
// rounded division, the doubling, the subtraction), so the view vector's
// components within 4 * 2^-53 tan (the product rounds once more); the
// rotation's two products and two sums round four times more, each within
// 2^-53 S (rotation entries are at most 1): 8 * 2^-53 S bounds the sum,
// and |ray| >= 1. That is below 2^-48 for every field of view the domains
// draw, about 25 bits below float32's rounding.
TEST(DrawTest, TheRayIsWithinAFewUlpsOfTheExactRay) {
  const Sampler sampler(11, WideDomain());
  double worst = 0.0;  // in units of 2^-53 S
  for (std::uint64_t f = 0; f < 2000; ++f) {
    const Frame frame = sampler.FrameAt(f);
    const long double tan_x = static_cast<long double>(frame.aspect) * frame.tan_half_fov_y;
    for (std::uint64_t i = f * kSamplesPerFrame; i < f * kSamplesPerFrame + 16; ++i) {
      const PixelSample sample = sampler.SampleAt(i, frame);
      const glm::dvec3 ray = PixelRay(frame, sample.x, sample.y);
      const long double ndc_x = (sample.x + 0.5L) / frame.width * 2 - 1;
      const long double ndc_y = 1 - (sample.y + 0.5L) / frame.height * 2;
      const long double view[3] = {ndc_x * tan_x, ndc_y * static_cast<long double>(frame.tan_half_fov_y), -1.0L};
      const long double norm = tan_x + frame.tan_half_fov_y + 1.0L;
      for (int row = 0; row < 3; ++row) {
        long double exact = 0.0L;
        for (int column = 0; column < 3; ++column) exact += frame.rotation[column][row] * view[column];
        worst = std::max(worst, static_cast<double>(std::fabs(ray[row] - exact) / (norm * 0x1p-53L)));
      }
    }
  }
  EXPECT_LE(worst, 8.0);
}

// The draw keeps the sampler's promises: eye depths within the frame's
// range, the depth picks and coverage kinds in their shares (5% stored
// values, 10% each doubling, 75% natural), pixels within the target.
TEST(DrawTest, DrawsWithinTheFrameInTheSamplersShares) {
  const Sampler sampler(3, WideDomain());
  int stored = 0, near = 0, far = 0, natural = 0;
  const int frames = 4000;
  for (std::uint64_t f = 0; f < frames; ++f) {
    const Frame frame = sampler.FrameAt(f);
    for (std::uint64_t i = f * kSamplesPerFrame; i < (f + 1) * kSamplesPerFrame; ++i) {
      const PixelSample s = sampler.SampleAt(i, frame);
      ASSERT_LT(s.x, frame.width);
      ASSERT_LT(s.y, frame.height);
      if (s.pick != DepthPick::kEyeDepth) {
        ++stored;
        continue;
      }
      ASSERT_GE(s.eye_depth, frame.eye_depth_min);
      ASSERT_LE(s.eye_depth, frame.eye_depth_max);
      near += s.coverage == Coverage::kNearDoubling ? 1 : 0;
      far += s.coverage == Coverage::kFarDoubling ? 1 : 0;
      natural += s.coverage == Coverage::kNatural ? 1 : 0;
      if (s.coverage == Coverage::kNearDoubling) {
        ASSERT_LE(s.eye_depth, 2 * frame.eye_depth_min);
      }
      if (s.coverage == Coverage::kFarDoubling) {
        ASSERT_GE(s.eye_depth, frame.eye_depth_max / 2);
      }
    }
  }
  // 256000 samples: a share p is within 5 standard deviations
  // (sqrt(p (1 - p) / n), under 0.0009) of its expectation.
  const double n = frames * kSamplesPerFrame;
  EXPECT_NEAR(stored / n, 0.05, 0.005);
  EXPECT_NEAR(near / n, 0.10, 0.005);
  EXPECT_NEAR(far / n, 0.10, 0.005);
  EXPECT_NEAR(natural / n, 0.75 * 0.92, 0.01);  // 8% of pixels are corners and edges
}

}  // namespace
}  // namespace depthbench
