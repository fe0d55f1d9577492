// choose on the example scenes gives answers a graphics engineer would
// agree with, and the precision fits on real bench data follow the theory.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "bench/backends/factory.h"
#include "bench/choose/choose.h"
#include "bench/fit/precision_fit.h"
#include "tests/command_runner.h"

namespace depthbench {
namespace {

const std::string kScenes = std::string(DEPTHBENCH_SOURCE_DIR) + "/bench/scenes/";

ChooseResult ChooseFor(const std::string& scene_file) {
  auto scene = LoadScene(scene_file);
  EXPECT_TRUE(scene.ok()) << scene.status().message();
  auto backend = MakeBackend("cpu", {});
  auto costs = StaticCostLookup("");
  EXPECT_TRUE(costs.ok()) << costs.status().message();
  ChooseOptions options;
  options.samples = 40000;
  auto result = Choose(*scene, **backend, *costs, options);
  EXPECT_TRUE(result.ok()) << result.status().message();
  return std::move(result).value();
}

TEST(ChooseTest, OpenWorldIsNotGivenStandardZ) {
  const ChooseResult r = ChooseFor(kScenes + "open_world.toml");
  ASSERT_FALSE(r.ranked.empty());
  // Whether or not anything meets 1 cm at 50 km, the first answer must not
  // be standard Z: at f/n = 1e5 it has lost ~17 bits at the far end.
  const Convention top = r.ranked.front().cell.convention;
  EXPECT_NE(top, Convention::kStandard);
  EXPECT_NE(top, Convention::kStandardGl);
  for (const CandidateVerdict& v : r.ranked) {
    if (v.cell.convention == Convention::kStandard || v.cell.convention == Convention::kStandardGl) {
      EXPECT_FALSE(v.meets) << v.cell.Name();
    }
  }
  if (!r.ranked.front().meets) {
    EXPECT_FALSE(r.suggestions.empty());  // says what would have to change
  }
}

TEST(ChooseTest, SceneThatEveryCandidateMeetsGetsTheCheapest) {
  const std::string dir = testing::MakeTempDir("easy_scene");
  std::ofstream(dir + "/easy.toml") << R"(name = "easy"
[projection]
near = 1
far = 100
fov_degrees = 60
aspect = 1.5
[requirement]
relative_error = 0.05
)";
  const ChooseResult r = ChooseFor(dir + "/easy.toml");
  ASSERT_FALSE(r.ranked.empty());
  double cheapest = INFINITY;
  for (const CandidateVerdict& v : r.ranked) {
    EXPECT_TRUE(v.meets) << v.cell.Name() << ": " << v.reason;
    ASSERT_TRUE(v.cost.has_value());
    cheapest = std::min(cheapest, v.cost->value);
  }
  EXPECT_EQ(r.ranked.front().cost->value, cheapest);
  EXPECT_NE(r.ranked.front().reason.find("the cheapest that meets it"), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(ChooseTest, CadViewerWantsReversedFloatDepth) {
  const ChooseResult r = ChooseFor(kScenes + "cad_viewer.toml");
  ASSERT_FALSE(r.ranked.empty());
  ASSERT_TRUE(r.ranked.front().meets) << r.ranked.front().reason;
  EXPECT_EQ(r.ranked.front().cell.format, Format::kD32Sfloat);
  EXPECT_EQ(Info(r.ranked.front().cell.convention).bits & 1u, 1u);  // reversed
}

TEST(ChooseTest, BadSceneFileExitsWithTwo) {
  const auto r = testing::RunDepthbench({"choose", "--scene", kScenes + "missing.toml"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("missing.toml' does not exist"), std::string::npos) << r.err;
}

// The fits on real bench data.
class RealFitTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    FitPlan plan;
    plan.samples_per_ratio = 60000;
    plan.domain.fov_degrees = {60, 60};
    plan.domain.aspect = {16.0 / 9.0, 16.0 / 9.0};
    for (const Cell& c : AllCells()) {
      const bool wanted = (c.convention == Convention::kStandard && c.format == Format::kX8D24Unorm) ||
                          (c.convention == Convention::kReversed && c.format == Format::kD32Sfloat) ||
                          c.format == Format::kR32Sfloat;
      if (wanted) plan.cells.push_back(c);
    }
    auto cpu = MakeBackend("cpu", {});
    Backend* backends[] = {cpu->get()};
    auto sweeps = RunFitSweeps(plan, backends);
    ASSERT_TRUE(sweeps.ok()) << sweeps.status().message();
    const Metric metrics[] = {Metric::kTotal};
    const Level levels[] = {Level::kP999};
    fits_ = new std::vector<PrecisionFit>(FitPrecision(*sweeps, plan, metrics, levels));
  }
  static void TearDownTestSuite() { delete fits_; }
  static std::vector<PrecisionFit>* fits_;
};
std::vector<PrecisionFit>* RealFitTest::fits_ = nullptr;

TEST_F(RealFitTest, StandardZWith24BitUnormLosesAboutOneBitPerDoubling) {
  int checked = 0;
  for (const PrecisionFit& f : *fits_) {
    if (f.cell.convention != Convention::kStandard) continue;
    EXPECT_GE(f.slope, 0.85) << f.cell.Name();
    EXPECT_LE(f.slope, 1.1) << f.cell.Name();
    ++checked;
  }
  EXPECT_EQ(checked, 4);
}

TEST_F(RealFitTest, ReversedFloatAndLinearFloatAreFlat) {
  int checked = 0;
  for (const PrecisionFit& f : *fits_) {
    if (f.cell.convention == Convention::kStandard) continue;
    // No far/near term, or a slope within 0.1 bit of zero.
    const bool no_ratio_term = !Info(f.model.kind).uses_ratio;
    EXPECT_TRUE(no_ratio_term || std::fabs(f.slope) < 0.1)
        << f.cell.Name() << ": " << Info(f.model.kind).name << ", slope " << f.slope;
    EXPECT_LT(std::fabs(f.slope), 0.1) << f.cell.Name();
    ++checked;
  }
  EXPECT_EQ(checked, 7);  // 4 reversed D32F + 3 linear R32F
}

}  // namespace
}  // namespace depthbench
