// Off-centre frusta (a VR eye's field of view, TAA jitter): the variants
// that follow the frustum's own corners or matrix stay as exact as on a
// symmetric one, and those that assume a symmetric frustum (tan_aspect,
// and divide, reciprocal and pq as the engine notes write them) are caught
// making the error their assumption predicts. The same check on a
// symmetric frustum passes them, so it is the asymmetry it detects.
#include <cmath>

#include <gtest/gtest.h>

#include "bench/sweep/sweep.h"
#include "tests/cpu_sweep.h"

namespace depthbench {
namespace {

// p99.9 bits lost, over the natural samples, of each of `cells`.
std::vector<double> P999Bits(const Domain& domain, const std::vector<std::string>& cells) {
  std::vector<double> bits;
  for (const CellResult& c : testing_support::CpuSweep(domain, cells, 40).cells) {
    bits.push_back(BitsLost(Summarize(c.stats.All(), Metric::kTotal).p999));
  }
  return bits;
}

Domain EyeDomain(EyeFov fov) {
  Domain d;
  d.eye_fov = fov;
  d.ratio = {1e4, 1e4};
  d.infinite_far = false;
  d.camera_distance = {0.0, 0.0};
  return d;
}

const std::vector<std::string> kFollowTheFrustum = {"inverse_vp/reversed/d32f", "frustum_ray/linear/r32f",
                                                    "volume_ray/linear/r32f", "eye_ray/linear/viewz"};
const std::vector<std::string> kAssumeSymmetry = {"tan_aspect/linear/r32f", "divide/reversed/d32f",
                                                  "reciprocal/reversed/d32f", "pq/reversed/d32f"};

// A float32 reconstruction that follows the frustum loses about 2 bits at
// p99.9 here (the physics test's flat float32 figures); 4 leaves room.
constexpr double kExactEnough = 4.0;

TEST(LensTest, AnOffCentreEyeBreaksOnlyTheVariantsThatAssumeSymmetry) {
  // One eye of a headset: 5 degrees more to the nose side than outwards.
  const Domain eye = EyeDomain({-50.0, 45.0, 48.0, -52.0});
  for (double bits : P999Bits(eye, kFollowTheFrustum)) EXPECT_LT(bits, kExactEnough);
  // A symmetric-frustum variant puts NDC (0, 0) on the view axis, where
  // the frustum's centre is (tan 45 - tan 50) / 2 = -0.096 off it in x
  // (and 0.011 in y): about a tenth of the ray, 2^-3.3 relative, so 20.7
  // bits lost. 18 leaves room for where the ray is longest.
  for (double bits : P999Bits(eye, kAssumeSymmetry)) EXPECT_GT(bits, 18.0);
}

TEST(LensTest, TheSameCheckPassesEveryVariantOnASymmetricEye) {
  const Domain eye = EyeDomain({-45.0, 45.0, 40.0, -40.0});
  for (double bits : P999Bits(eye, kAssumeSymmetry)) EXPECT_LT(bits, kExactEnough);
}

TEST(LensTest, TaaJitterOfHalfAPixelCostsTheSymmetricVariantsAboutElevenBitsOfPosition) {
  Domain d;
  d.jitter = 0.5;
  d.ratio = {1e4, 1e4};
  d.infinite_far = false;
  d.camera_distance = {0.0, 0.0};
  d.resolutions = {{1920, 1080}};
  for (double bits : P999Bits(d, kFollowTheFrustum)) EXPECT_LT(bits, kExactEnough);
  // Half a pixel of 1920 is 2^-10.9 of the screen's half width: ignoring
  // it misplaces a point by up to that fraction of its ray, 24 - 10.9 =
  // 13.1 bits and a little more where the ray is short; at least 11.
  for (double bits : P999Bits(d, kAssumeSymmetry)) EXPECT_GT(bits, 11.0);
}

}  // namespace
}  // namespace depthbench
