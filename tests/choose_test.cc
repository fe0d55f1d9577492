// choose on the example scenes gives answers a graphics engineer would
// agree with, and the precision fits on real bench data follow the theory.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "bench/backends/factory.h"
#include "bench/base/json_reader.h"
#include "bench/choose/choose.h"
#include "bench/choose/frame_cost.h"
#include "bench/speed/trade.h"
#include "bench/sweep/sweep.h"
#include "bench/fit/precision_fit.h"
#include "tests/command_runner.h"

namespace depthbench {
namespace {

const std::string kScenes = std::string(DEPTHBENCH_SOURCE_DIR) + "/bench/scenes/";

ChooseResult ChooseFor(const std::string& scene_file, const std::string& speed_file = "",
                       std::uint64_t samples = 40000) {
  auto scene = LoadScene(scene_file);
  EXPECT_TRUE(scene.ok()) << scene.status().message();
  auto backend = MakeBackend("cpu", {});
  CostSources costs;
  auto static_model = StaticCostLookup("");
  EXPECT_TRUE(static_model.ok()) << static_model.status().message();
  costs.static_model = *static_model;
  if (!speed_file.empty()) {
    FrameCostModel model;
    auto speed = SpeedFileFor((*backend)->device(), speed_file, Catalogue::BuiltIn(), model.source);
    EXPECT_TRUE(speed.ok()) << speed.status().message();
    model.speed = *speed;
    model.frame = scene->resolution.value_or(kCostFrame);
    model.stencil = scene->stencil;
    costs.measured = FrameCostLookup(model);
    costs.measured_from = speed_file;
  }
  ChooseOptions options;
  options.samples = samples;
  auto result = Choose(*scene, **backend, costs, options);
  EXPECT_TRUE(result.ok()) << result.status().message();
  return std::move(result).value();
}

// A scene file in `dir`: a fixed lens, the near and far planes given, and
// the rest of the TOML (the requirement, a depth range) as written.
std::string WriteScene(const std::string& dir, const std::string& name, const std::string& near, const std::string& far,
                       const std::string& rest) {
  const std::string path = dir + "/" + name + ".toml";
  std::ofstream(path) << "name = \"" << name << "\"\n[projection]\nnear = " << near << "\nfar = " << far
                      << "\nfov_degrees = 60\naspect = 1.5\n"
                      << rest;
  return path;
}
constexpr const char* kEasyRequirement = "[requirement]\nrelative_error = 0.05\n";

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

// The far end's figure is measured directly (the last tenth of depth before
// it, the scene's cameras); the model's prediction there is published only
// within 0.3 bit of it. An independent measurement of the same population
// (another seed) must agree with every published figure to that 0.3 bit,
// the sampling interval of a p99.9 from 1e5 samples being about 0.1 bit.
// Before, the spot-light shadow's inverse_vp/standard/x8_d24_unorm was
// predicted 2.5 bits low with the light 500 m out, and the flight sim's
// D24 candidates 0.7 bit low 200 km out.
void ExpectFarEndFiguresHold(const std::string& scene_file) {
  const ChooseResult r = ChooseFor(scene_file, "", 100000);
  ASSERT_FALSE(r.ranked.empty());
  auto scene = LoadScene(scene_file);
  ASSERT_TRUE(scene.ok());
  SweepOptions independent;
  independent.seed = 977;
  independent.samples = 100000;
  independent.domain = scene->domain;
  const double far = scene->domain.far->max;
  independent.domain.eye_depth = Range{far / 1.1, far};
  independent.cells = scene->Candidates();
  auto backend = MakeBackend("cpu", {});
  Backend* backends[] = {backend->get()};
  auto results = RunSweep(independent, backends);
  ASSERT_TRUE(results.ok()) << results.status().message();
  int published = 0;
  for (const CandidateVerdict& v : r.ranked) {
    const CellResult* c = results->Find(v.cell, "cpu");
    ASSERT_NE(c, nullptr) << v.cell.Name();
    const double direct = c->stats.All()[Metric::kAbsolute].AtLevel(Level::kP999, Metric::kAbsolute);
    EXPECT_NEAR(std::log2(v.far_end_measured / direct), 0.0, kPublishedPredictionBits)
        << v.cell.Name() << ": far end " << v.far_end_measured << ", independently " << direct;
    if (std::isfinite(v.predicted)) {
      ++published;
      EXPECT_NEAR(std::log2(v.predicted / direct), 0.0, kPublishedPredictionBits)
          << v.cell.Name() << ": predicted " << v.predicted << " (" << v.model << "), independently " << direct;
    }
  }
  ::testing::Test::RecordProperty("published_predictions", published);
}

TEST(ChooseTest, SpotShadowFarEndFiguresHoldOnAnIndependentMeasurement) {
  ExpectFarEndFiguresHold(kScenes + "spot_shadow.toml");
  // The 2.5-bit miss is withheld, not published.
  const ChooseResult r = ChooseFor(kScenes + "spot_shadow.toml", "", 100000);
  for (const CandidateVerdict& v : r.ranked) {
    if (v.cell.Name() == "inverse_vp/standard/x8_d24_unorm") {
      EXPECT_FALSE(std::isfinite(v.predicted)) << v.predicted;
      EXPECT_LT(v.prediction_off_bits, -1.0);
    }
  }
}

TEST(ChooseTest, FlightSimFarEndFiguresHoldOnAnIndependentMeasurement) {
  ExpectFarEndFiguresHold(kScenes + "flight_sim.toml");
}

// open_world's camera goes 20 km from the world origin: the camera's part
// of the far-end model is a few roundings of float32 world coordinates
// there (2^-9 apart, about 1.6 x 2^-24 x 20000), never 16 x 2^-24 x 20000.
TEST(ChooseTest, OpenWorldCameraTermIsAFewRoundingsOfItsWorldCoordinates) {
  const ChooseResult r = ChooseFor(kScenes + "open_world.toml", "", 100000);
  ASSERT_FALSE(r.ranked.empty());
  for (const CandidateVerdict& v : r.ranked) {
    EXPECT_GT(v.camera_term, 0.0) << v.cell.Name();
    EXPECT_LT(v.camera_term, 16.0 * std::ldexp(20000.0, -24)) << v.cell.Name();
    EXPECT_NE(v.model.find("+camera"), std::string::npos) << v.model;
  }
}

TEST(ChooseTest, SceneThatEveryCandidateMeetsGetsTheCheapest) {
  const std::string dir = testing::MakeTempDir("easy_scene");
  const std::string easy = WriteScene(dir, "easy", "1", "100", kEasyRequirement);
  const ChooseResult r = ChooseFor(easy);
  ASSERT_FALSE(r.ranked.empty());
  double cheapest = INFINITY;
  for (const CandidateVerdict& v : r.ranked) {
    EXPECT_TRUE(v.meets) << v.cell.Name() << ": " << v.reason;
    ASSERT_TRUE(v.cost.has_value());
    cheapest = std::min(cheapest, v.cost->value);
  }
  EXPECT_EQ(r.ranked.front().cost->value, cheapest);
  EXPECT_NE(r.ranked.front().reason.find("the cheapest that meets it"), std::string::npos) << r.ranked.front().reason;
  // The CI summary names the choice and shows the first ten candidates.
  const std::string summary = ChoiceSummaryMarkdown(r);
  EXPECT_EQ(summary.rfind("### depthbench choose: scene 'easy'", 0), 0u) << summary;
  EXPECT_NE(summary.find("Choice: **" + r.ranked.front().cell.Name() + "**"), std::string::npos) << summary;
  EXPECT_NE(summary.find("| " + r.ranked.front().cell.Name() + " |"), std::string::npos) << summary;
  if (r.ranked.size() > 10) {
    EXPECT_EQ(summary.find("| " + r.ranked[10].cell.Name() + " |"), std::string::npos) << summary;
    EXPECT_NE(summary.find("more candidates"), std::string::npos) << summary;
  }
  std::filesystem::remove_all(dir);
}

// The static model costs a variant the same in every convention and
// format: those candidates tie on cost, share a rank, and go in order of
// accuracy (the upper end of the interval).
TEST(ChooseTest, CostTiesShareARankInOrderOfAccuracy) {
  const std::string dir = testing::MakeTempDir("tie_scene");
  const std::string easy = WriteScene(dir, "easy", "1", "100", kEasyRequirement);
  const ChooseResult r = ChooseFor(easy);
  std::filesystem::remove_all(dir);
  ASSERT_TRUE(r.Met());
  EXPECT_EQ(r.cost_unit, kStaticCostUnit);
  int tied_first = 0;
  for (std::size_t k = 0; k < r.ranked.size(); ++k) {
    const CandidateVerdict& v = r.ranked[k];
    if (v.rank != 1) continue;
    ++tied_first;
    EXPECT_TRUE(v.meets) << v.cell.Name();
    EXPECT_EQ(v.cell.variant, r.ranked.front().cell.variant) << v.cell.Name();
    EXPECT_EQ(v.cost->value, r.ranked.front().cost->value) << v.cell.Name();
    if (k > 0) {
      EXPECT_GE(v.interval.high, r.ranked[k - 1].interval.high) << v.cell.Name();
    }
  }
  EXPECT_GE(tied_first, 2);
  EXPECT_TRUE(r.ranked.front().tied);
  EXPECT_NE(r.ranked.front().reason.find("tied for the cheapest"), std::string::npos) << r.ranked.front().reason;
  // A rank is 1 + the candidates ahead of it.
  for (std::size_t k = 1; k < r.ranked.size(); ++k) {
    if (r.ranked[k].rank != r.ranked[k - 1].rank) {
      EXPECT_EQ(r.ranked[k].rank, static_cast<int>(k) + 1);
    }
  }
}

// A speed file ranks by frame cost when it has every candidate; a file
// that lacks one is not mixed with the static model: the static model
// ranks every candidate, and the note says why.
TEST(ChooseTest, SpeedFileCostsAllCandidatesOrNone) {
  const std::string speed = std::string(DEPTHBENCH_SOURCE_DIR) + "/reports/speed/nvidia-h200.json";
  const ChooseResult measured = ChooseFor(kScenes + "cad_viewer.toml", speed);
  EXPECT_NE(measured.cost_unit.find("frame on NVIDIA H200"), std::string::npos) << measured.cost_unit;
  EXPECT_TRUE(measured.cost_note.empty()) << measured.cost_note;
  for (const CandidateVerdict& v : measured.ranked) {
    ASSERT_TRUE(v.cost.has_value()) << v.cell.Name();
    EXPECT_EQ(v.cost->unit, measured.cost_unit);
    EXPECT_GT(v.cost->bytes_per_pixel, 0u) << v.cell.Name();
  }

  // The same file without the ALU-bound timings of the first candidate.
  auto json = ReadJsonFile(speed);
  ASSERT_TRUE(json.ok()) << json.status().message();
  const std::string dropped = measured.ranked.front().cell.Name();
  auto& gpu = (*json)["gpu"];
  const std::size_t before = gpu.size();
  for (auto it = gpu.begin(); it != gpu.end();) {
    it = (*it)["cell"] == dropped && (*it)["regime"] == "alu" ? gpu.erase(it) : it + 1;
  }
  ASSERT_LT(gpu.size(), before);
  const std::string dir = testing::MakeTempDir("partial_speed");
  std::ofstream(dir + "/partial.json") << json->dump();
  const ChooseResult partial = ChooseFor(kScenes + "cad_viewer.toml", dir + "/partial.json");
  EXPECT_EQ(partial.cost_unit, kStaticCostUnit);
  EXPECT_NE(partial.cost_note.find("static cost model"), std::string::npos) << partial.cost_note;
  for (const CandidateVerdict& v : partial.ranked) EXPECT_EQ(v.cost->unit, kStaticCostUnit) << v.cell.Name();
  std::filesystem::remove_all(dir);
}

// choose gates a scene in CI: exit 1 when nothing meets the requirement,
// with the decision in --json.
// requirement.level = "bound": the proven bound decides. It is held
// against the limit (a limit just below the choice's bound turns it down),
// and it is a bound: no candidate's measured maximum exceeds it, and
// bounds in world units at a depth follow from the relative one.
TEST(ChooseTest, ProvenRequirementIsDecidedByTheBound) {
  const std::string dir = testing::MakeTempDir("proven_scene");
  const auto scene_with = [&](const std::string& name, double limit) {
    return WriteScene(dir, name, "0.5", "500",
                      fmt::format("resolution = [1280, 720]\n[engine]\nvariants = [\"divide\", \"frustum_ray\"]\n"
                                  "formats = [\"d32_sfloat\", \"r32_sfloat\"]\n[requirement]\nabsolute_error = {}\n"
                                  "at_depth = 400\nlevel = \"bound\"\n",
                                  limit));
  };
  const ChooseResult loose = ChooseFor(scene_with("loose", 0.05), "", 20000);
  ASSERT_TRUE(loose.proven);
  ASSERT_TRUE(loose.Met()) << loose.ranked.front().reason;
  for (const CandidateVerdict& v : loose.ranked) {
    ASSERT_FALSE(std::isnan(v.proven)) << v.cell.Name();
    if (!std::isfinite(v.proven)) {
      EXPECT_FALSE(v.unproven.empty()) << v.cell.Name();
      continue;
    }
    // A bound over every input of the population holds every sample of it.
    EXPECT_LE(v.measured_max, v.proven) << v.cell.Name();
    EXPECT_EQ(v.meets, v.proven <= 0.05) << v.cell.Name();
  }
  const CandidateVerdict& choice = loose.ranked.front();
  EXPECT_NE(choice.reason.find("on any conformant Vulkan device"), std::string::npos) << choice.reason;
  // Just below the choice's bound, the choice no longer meets the limit.
  const ChooseResult tight = ChooseFor(scene_with("tight", choice.proven * 0.99), "", 20000);
  bool seen = false;
  for (const CandidateVerdict& v : tight.ranked) {
    if (!(v.cell == choice.cell)) continue;
    seen = true;
    EXPECT_FALSE(v.meets) << v.reason;
  }
  EXPECT_TRUE(seen);
  std::filesystem::remove_all(dir);
}

TEST(ChooseTest, NothingMeetsExitsWithOne) {
  const std::string dir = testing::MakeTempDir("impossible_scene");
  const std::string impossible =
      WriteScene(dir, "impossible", "0.1", "100000", "[requirement]\nrelative_error = 1e-9\n");
  const auto r = testing::RunDepthbench(
      {"choose", "--scene", impossible, "--backend", "cpu", "--samples", "2e4", "--json", dir + "/choice.json",
       "--summary", dir + "/summary.md"});
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("nothing meets"), std::string::npos) << r.out;
  EXPECT_NE(testing::ReadText(dir + "/summary.md").find("\n\nNo candidate meets it.\n"), std::string::npos);
  auto json = ReadJsonFile(dir + "/choice.json");
  ASSERT_TRUE(json.ok()) << json.status().message();
  EXPECT_EQ((*json)["met"], false);
  EXPECT_TRUE((*json)["choice"].is_null());
  std::filesystem::remove_all(dir);
}

// A scene whose depths stop well short of an infinite far plane is not
// charged for what a texel at the far plane (infinity) reconstructs to.
TEST(ChooseTest, DepthRangeShortOfTheFarPlaneHasNoFarPlaneFindings) {
  const std::string dir = testing::MakeTempDir("short_scene");
  const std::string short_scene = WriteScene(dir, "short", "0.1", "\"inf\"",
                                             "[depth]\nrange = [0.1, 1000]\n[requirement]\nrelative_error = 1e-3\n");
  const ChooseResult r = ChooseFor(short_scene);
  ASSERT_FALSE(r.ranked.empty());
  for (const CandidateVerdict& v : r.ranked) EXPECT_EQ(v.nonfinite, 0u) << v.cell.Name() << ": " << v.reason;
  EXPECT_TRUE(r.Met());
  std::filesystem::remove_all(dir);
}

TEST(ChooseTest, CadViewerWantsReversedFloatDepth) {
  const ChooseResult r = ChooseFor(kScenes + "cad_viewer.toml");
  ASSERT_FALSE(r.ranked.empty());
  ASSERT_TRUE(r.ranked.front().meets) << r.ranked.front().reason;
  EXPECT_EQ(r.ranked.front().cell.format, Format::kD32Sfloat);
  EXPECT_EQ(Info(r.ranked.front().cell.convention).bits & 1u, 1u);  // reversed
}

// The literature's answer for a VR eye (reversed Z with a float buffer),
// and a variant that assumes a symmetric frustum is named as wrong for the
// eye rather than blamed on its arithmetic.
TEST(ChooseTest, VrEyeWantsReversedFloatDepthAndAFrustumAwareVariant) {
  const ChooseResult r = ChooseFor(kScenes + "vr_asymmetric.toml");
  ASSERT_TRUE(r.Met()) << r.ranked.front().reason;
  EXPECT_EQ(r.ranked.front().cell.format, Format::kD32Sfloat);
  EXPECT_EQ(r.ranked.front().cell.convention, Convention::kReversed);
  EXPECT_FALSE(r.ranked.front().cell.variant_info().assumes_symmetric_frustum);
  EXPECT_NE(r.api_recipe.find("glClipControl"), std::string::npos) << r.api_recipe;
  EXPECT_FALSE(r.lens.empty());
  bool saw_wrong_lens = false;
  for (const CandidateVerdict& v : r.ranked) {
    if (!v.cell.variant_info().assumes_symmetric_frustum) continue;
    saw_wrong_lens = true;
    EXPECT_TRUE(v.wrong_lens) << v.cell.Name();
    EXPECT_FALSE(v.meets) << v.cell.Name();
    EXPECT_NE(v.reason.find("symmetric frustum"), std::string::npos) << v.reason;
  }
  EXPECT_TRUE(saw_wrong_lens);
}

// When only symmetric-frustum formulas are allowed on an off-centre eye,
// the advice names the lens, not the depth buffer or the arithmetic.
TEST(ChooseTest, OnlySymmetricFormulasOnAnOffCentreEyeAreToldWhy) {
  const std::string dir = testing::MakeTempDir("symmetric_only");
  const std::string path = dir + "/eye.toml";
  std::ofstream(path) << "name = \"eye\"\n[projection]\neye_fov = [-52, 43, 47, -53]\nnear = 0.05\nfar = 1000\n"
                         "[engine]\nvariants = [\"divide\", \"pq\"]\nformats = [\"d32_sfloat\"]\n"
                         "[requirement]\nabsolute_error = 0.002\nat_depth = 10\n";
  const ChooseResult r = ChooseFor(path);
  ASSERT_FALSE(r.Met());
  ASSERT_GE(r.suggestions.size(), 2u);
  EXPECT_NE(r.suggestions[1].find("assumes a symmetric frustum"), std::string::npos) << r.suggestions[1];
}

TEST(ChooseTest, TaaJitterRulesOutTheSymmetricFormulas) {
  const ChooseResult r = ChooseFor(kScenes + "taa_jitter.toml");
  ASSERT_TRUE(r.Met());
  EXPECT_FALSE(r.ranked.front().cell.variant_info().assumes_symmetric_frustum);
  for (const CandidateVerdict& v : r.ranked) EXPECT_EQ(v.wrong_lens, v.cell.variant_info().assumes_symmetric_frustum);
}

// A directional light's cascade: orthographic, so its depth is linear and
// D16's step over 399 m (6.1 mm, half of it 3 mm) fails 1 mm anywhere,
// while 24 bits or a float pass; only orthographic cells are candidates,
// and the API advice says the projection is an orthographic one.
TEST(ChooseTest, OrthographicCascadeRulesOutD16AndRunsOnlyOrthographicCells) {
  const ChooseResult r = ChooseFor(kScenes + "shadow_ortho.toml");
  ASSERT_TRUE(r.Met()) << r.ranked.front().reason;
  EXPECT_NE(r.ranked.front().cell.format, Format::kD16Unorm);
  EXPECT_NE(r.api_recipe.find("an orthographic projection"), std::string::npos) << r.api_recipe;
  bool saw_d16 = false;
  for (const CandidateVerdict& v : r.ranked) {
    EXPECT_TRUE(Info(v.cell.convention).orthographic()) << v.cell.Name();
    if (v.cell.format != Format::kD16Unorm) continue;
    saw_d16 = true;
    EXPECT_FALSE(v.meets) << v.cell.Name();
  }
  EXPECT_TRUE(saw_d16);
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
      const bool d24 = c.format == Format::kX8D24Unorm &&
                       (c.convention == Convention::kStandard || c.convention == Convention::kReversed);
      const bool wanted = d24 || (c.convention == Convention::kReversed && c.format == Format::kD32Sfloat) ||
                          c.format == Format::kR32Sfloat;
      if (wanted) plan.cells.push_back(c);
    }
    plan_ = new FitPlan(plan);
    auto cpu = MakeBackend("cpu", {});
    Backend* backends[] = {cpu->get()};
    auto sweeps = RunFitSweeps(plan, backends);
    ASSERT_TRUE(sweeps.ok()) << sweeps.status().message();
    const Metric metrics[] = {Metric::kTotal};
    const Level levels[] = {Level::kP999};
    fits_ = new std::vector<PrecisionFit>(FitPrecision(*sweeps, plan, metrics, levels));
  }
  static void TearDownTestSuite() {
    delete fits_;
    delete plan_;
  }
  static std::vector<PrecisionFit>* fits_;
  static FitPlan* plan_;
};
std::vector<PrecisionFit>* RealFitTest::fits_ = nullptr;
FitPlan* RealFitTest::plan_ = nullptr;

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
    if (f.cell.convention == Convention::kStandard || f.cell.format == Format::kX8D24Unorm) continue;
    // No far/near term, or a slope within 0.1 bit of zero.
    const bool no_ratio_term = !Info(f.model.kind).uses_ratio;
    EXPECT_TRUE(no_ratio_term || std::fabs(f.slope) < 0.1)
        << f.cell.Name() << ": " << Info(f.model.kind).name << ", slope " << f.slope;
    EXPECT_LT(std::fabs(f.slope), 0.1) << f.cell.Name();
    ++checked;
  }
  EXPECT_EQ(checked, 7);  // 4 reversed D32F + 3 linear R32F
}

// "p99.9 at the far plane at f/n R" means what a run at R reports for the
// samples nearest the far plane: the fitted prediction at 1e4 against the
// deepest decade of a direct run there, drawn with another seed, for
// standard D24 (losing a bit per doubling), reversed D24 and reversed D32F.
// 0.3 bit: the p99.9 of ~60000 samples in a decade is known to about a
// tenth of a bit, the quarter-octave bins interpolate within a quarter, and
// the model's residual at one of its own ratios is a tenth or two.
TEST_F(RealFitTest, FarPlanePredictionsMatchADirectRun) {
  SweepOptions options;
  options.seed = 4242;
  options.samples = 240000;
  options.domain = plan_->domain;
  options.domain.ratio = {1e4, 1e4};
  options.domain.infinite_far = false;
  options.cells = {*ParseCell("reciprocal/standard/d24"), *ParseCell("reciprocal/reversed/d24"),
                   *ParseCell("reciprocal/reversed/d32f")};
  auto cpu = MakeBackend("cpu", {});
  Backend* backends[] = {cpu->get()};
  auto direct = RunSweep(options, backends);
  ASSERT_TRUE(direct.ok()) << direct.status().message();
  int checked = 0;
  for (const CellResult& c : direct->cells) {
    const BandStats deepest = c.stats.ForDepth(3);  // z/n in [1e3, 1e4]
    ASSERT_GT(deepest.finite, 40000u) << c.cell.Name();
    const double measured = BitsLost(Summarize(deepest, Metric::kTotal).p999);
    for (const PrecisionFit& f : *fits_) {
      if (!(f.cell == c.cell)) continue;
      ASSERT_TRUE(f.predicted.contains("1e4")) << c.cell.Name();
      EXPECT_NEAR(f.predicted.at("1e4"), measured, 0.3) << c.cell.Name() << ": model " << Info(f.model.kind).name;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 3);
}

}  // namespace
}  // namespace depthbench
