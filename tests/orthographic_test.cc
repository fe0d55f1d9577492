// Orthographic projections (a directional light's shadow map, a CAD view):
// their depth is linear in eye depth, so the figures follow from the
// format's step over the whole depth range, not from a near plane; the
// perspective variants do not run on them, nor the orthographic ones on a
// perspective frame.
#include <cmath>

#include <gtest/gtest.h>

#include "bench/sweep/sweep.h"
#include "tests/cpu_sweep.h"

namespace depthbench {
namespace {

constexpr double kNear = 1.0, kFar = 400.0;

// A shadow cascade's volume, off the view axis in y, camera at the origin.
Domain Cascade(double far = kFar) {
  Domain d;
  d.orthographic = ViewVolume{-40.0, 40.0, -25.0, 35.0};
  d.near = {kNear, kNear};
  d.far = Range{far, far};
  d.infinite_far = false;
  d.camera_distance = {0.0, 0.0};
  d.resolutions = {{2048, 2048}};
  return d;
}

Results Sweep(const Domain& domain, const std::vector<std::string>& cells) {
  return testing_support::CpuSweep(domain, cells, 41);
}

TEST(OrthographicTest, D16LosesHalfAStepOfTheWholeDepthRangeAnywhere) {
  const Results r = Sweep(Cascade(), {"ortho_lerp/ortho-standard/d16", "inverse_vp/ortho-reversed/d16"});
  ASSERT_EQ(r.cells.size(), 2u);
  // Round to nearest of (z - n) / (f - n) in 16 bits misplaces a point by
  // up to half a step, (f - n) / 65535 / 2 = 3.04e-3 world units, at every
  // depth alike. Over 1e5 uniform roundings the largest comes within 1%
  // of it. The float32 arithmetic around it (the depth's production, the
  // shader's multiply-add and its view-to-world transform, each a few
  // roundings of values up to 400) adds at most a few times 2^-24 * 400 =
  // 2.4e-5; four of them is the slack.
  const double half_step = (kFar - kNear) / 65535.0 / 2.0;
  const double float32_slack = 4.0 * std::ldexp(kFar, -24);
  for (const CellResult& c : r.cells) {
    const double largest = Summarize(c.stats.All(), Metric::kAbsolute).max;
    EXPECT_GT(largest, 0.99 * half_step) << c.cell.Name();
    EXPECT_LT(largest, half_step + float32_slack) << c.cell.Name();
  }
}

TEST(OrthographicTest, ReversedZGainsNothingWithAFloatBuffer) {
  // Perspective reversed Z with D32F pairs float's fine steps near 0 with
  // the far plane, where 1/z crowds depths. Linear depth has no crowding:
  // reversed puts the near plane at 1, where float32's step is 2^-24 of
  // the whole range, (f - n) / n = 2^13.3 times the step a point at the
  // near plane needs; standard puts it at 0, where steps are finest.
  const Results r = Sweep(Cascade(1e4), {"ortho_lerp/ortho-standard/d32f", "ortho_lerp/ortho-reversed/d32f"});
  ASSERT_EQ(r.cells.size(), 2u);
  const double standard = BitsLost(Summarize(r.cells[0].stats.All(), Metric::kTotal).p999);
  const double reversed = BitsLost(Summarize(r.cells[1].stats.All(), Metric::kTotal).p999);
  // Standard stays within float32's own few bits (4 as lens_test allows);
  // reversed loses several more over the depths near the near plane.
  EXPECT_LT(standard, 4.0);
  EXPECT_GT(reversed, standard + 2.0);
}

TEST(OrthographicTest, EachDomainRunsItsOwnProjectionsCells) {
  const std::vector<Cell> orthographic = CellsForDomain(AllCells(), Cascade());
  ASSERT_FALSE(orthographic.empty());
  for (const Cell& c : orthographic) {
    EXPECT_TRUE(Info(c.convention).orthographic()) << c.Name();
    EXPECT_NE(c.variant_info().projections, Projections::kPerspective) << c.Name();
  }
  for (const Cell& c : CellsForDomain(AllCells(), Domain{})) {
    EXPECT_FALSE(Info(c.convention).orthographic()) << c.Name();
    EXPECT_NE(c.variant_info().projections, Projections::kOrthographic) << c.Name();
  }
}

}  // namespace
}  // namespace depthbench
