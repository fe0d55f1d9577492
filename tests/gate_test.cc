// The real gate, on edited copies of shaders/ and shared/ made in a
// temporary directory, against the committed lavapipe baseline.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/command_runner.h"

namespace depthbench {
namespace {

namespace fs = std::filesystem;
using testing::RunDepthbench;

const std::string kBaseline = std::string(DEPTHBENCH_SOURCE_DIR) + "/reports/baselines/lavapipe.json";

class GateTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = testing::MakeTempDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    testing::CopyShaderSources(root_);
  }
  void TearDown() override { fs::remove_all(root_); }

  // Replaces `from` by `to` in a copied file; the text must be there.
  void Edit(const std::string& relative, const std::string& from, const std::string& to) {
    ASSERT_TRUE(testing::ReplaceInFile(root_ + "/" + relative, from, to)) << "'" << from << "' not in " << relative;
  }

  testing::CommandResult Gate(const std::vector<std::string>& more = {}) {
    std::vector<std::string> args = {"gate", "--baseline", kBaseline, "--shaders", root_ + "/shaders"};
    args.insert(args.end(), more.begin(), more.end());
    return RunDepthbench(args);
  }

  // Runs the first reproducer the gate printed ("  reproduce: depthbench
  // run ...").
  static testing::CommandResult ReplayFirstReproducer(const testing::CommandResult& gate) {
    const std::string marker = "reproduce: depthbench ";
    const auto at = gate.out.find(marker);
    EXPECT_NE(at, std::string::npos) << gate.out;
    if (at == std::string::npos) return {};
    std::istringstream words(gate.out.substr(at + marker.size(), gate.out.find('\n', at) - at - marker.size()));
    std::vector<std::string> args;
    for (std::string w; words >> w;) args.push_back(w);
    auto replay = RunDepthbench(args);
    EXPECT_EQ(replay.exit_code, 0) << replay.err;
    return replay;
  }

  std::string root_;
};

TEST_F(GateTest, UnchangedCopyPasses) {
  const auto r = Gate({"--summary", root_ + "/summary.md"});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(r.out.rfind("PASS", 0), 0u) << r.out;  // the verdict comes first
  const std::string markdown = testing::ReadText(root_ + "/summary.md");
  EXPECT_EQ(markdown.rfind("### depthbench gate: PASS\n\nno cell got worse (", 0), 0u) << markdown;
  EXPECT_EQ(markdown.find("| worse cell"), std::string::npos) << markdown;
}

TEST_F(GateTest, RenamingAndReformattingWithoutNewArithmeticPasses) {
  Edit("shared/variants/divide.h", R"(  real a = depth.coefficients.x;
  real b = depth.coefficients.y;
  vec3 view = vec3(ndc.x / frame.lens.z, ndc.y / frame.lens.w, -1.0f);
  view = view / (ndc_z / b - a / b);
  return world_from_view(frame, view);)",
       R"(  // Same arithmetic, other names and layout.
  real coefficient_a = depth.coefficients.x;
  real coefficient_b = depth.coefficients.y;

  vec3 position_in_view = vec3(ndc.x / frame.lens.z,
                               ndc.y / frame.lens.w,
                               -1.0f);
  real one_over_eye_depth = ndc_z / coefficient_b - coefficient_a / coefficient_b;
  position_in_view = position_in_view / one_over_eye_depth;
  return world_from_view(frame, position_in_view);)");
  const auto r = Gate();
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
}

TEST_F(GateTest, ReciprocalRewrittenAsMultiplyAddFailsOnStandardZ) {
  Edit("shared/variants/reciprocal.h", "real inverse_w = depth.coefficients.y / (ndc_z - depth.coefficients.x);",
       "real inverse_w = 1.0f / (ndc_z * depth.coefficients.z + depth.coefficients.w);");
  // The Markdown summary goes to --summary, and is added to a GitHub
  // Actions job's summary file after what earlier steps wrote there.
  const std::string summary = root_ + "/summary.md", job = root_ + "/job-summary.md";
  { std::ofstream(job) << "earlier step\n"; }
  const char* before = std::getenv("GITHUB_STEP_SUMMARY");
  const std::string kept = before != nullptr ? before : "";
  ::setenv("GITHUB_STEP_SUMMARY", job.c_str(), 1);
  const auto r = Gate({"--summary", summary});
  if (before != nullptr) {
    ::setenv("GITHUB_STEP_SUMMARY", kept.c_str(), 1);
  } else {
    ::unsetenv("GITHUB_STEP_SUMMARY");
  }
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_EQ(r.out.rfind("FAIL", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("worse: reciprocal/standard/"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("worse: divide/"), std::string::npos) << "only the edited variant may change";
  // The replay is a sample where the edit shows: the shader part's worst,
  // with that part's figure before and after (not a sample that storage
  // dominates alike before and after).
  EXPECT_NE(r.out.find("the worst sample of the shader's part: its band maximum"), std::string::npos) << r.out;

  const std::string markdown = testing::ReadText(summary);
  EXPECT_EQ(markdown.rfind("### depthbench gate: FAIL\n", 0), 0u) << markdown;
  EXPECT_NE(markdown.find("| reciprocal/standard/"), std::string::npos) << markdown;
  EXPECT_EQ(markdown.find("| divide/"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("`depthbench run --seed"), std::string::npos) << "a row replays its sample: " << markdown;
  EXPECT_EQ(testing::ReadText(job), "earlier step\n" + markdown + "\n");
}

// With a machine table format the gate's table of worse cells is all that
// standard output carries; the verdict goes to standard error.
TEST_F(GateTest, TableFormatMarkdownPrintsTheWorseCells) {
  Edit("shared/variants/reciprocal.h", "real inverse_w = depth.coefficients.y / (ndc_z - depth.coefficients.x);",
       "real inverse_w = 1.0f / (ndc_z * depth.coefficients.z + depth.coefficients.w);");
  const auto r = RunDepthbench(
      {"--table-format", "markdown", "gate", "--baseline", kBaseline, "--shaders", root_ + "/shaders"});
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_EQ(r.out.rfind("| worse cell | backend | band that changed most |", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("| reciprocal/standard/"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("\nFAIL: "), std::string::npos) << r.err;
}

TEST_F(GateTest, SixteenBitIntermediateFails) {
  // The NDC depth squeezed through a 16-bit float, as a careless half-
  // precision optimisation would.
  Edit("shared/variants/divide.h", "  real ndc_z = ndc_depth_from_window_depth(depth, stored);",
       "  real ndc_z = unpackHalf2x16(packHalf2x16(vec2(ndc_depth_from_window_depth(depth, stored), 0.0f))).x;");
  const auto r = Gate();
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("worse: divide/"), std::string::npos) << r.out;
}

TEST_F(GateTest, SyntaxErrorExitsWithTwoNamingFileAndLine) {
  Edit("shared/variants/pq.h", "  real ndc_z = ndc_depth_from_window_depth(depth, stored);",
       "  real ndc_z = ndc_depth_from_window_depth(depth, stored) +;");
  const auto r = Gate();
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("shared/variants/pq.h:9: error:"), std::string::npos) << r.err;
}

TEST_F(GateTest, PlantedNanFailsAndItsReproducerReproducesIt) {
  // NaN for stored depths in one range only.
  Edit("shared/variants/pq.h", "  real inverse_w = 1.0f / (ndc_z * depth.coefficients.z + depth.coefficients.w);",
       "  real inverse_w = 1.0f / (ndc_z * depth.coefficients.z + depth.coefficients.w);\n"
       "  if (stored > 0.25f && stored < 0.5f) inverse_w = inverse_w * (stored - stored) / (stored - stored);");
  const auto r = Gate();
  ASSERT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("NaN appeared"), std::string::npos) << r.out;
  const auto replay = ReplayFirstReproducer(r);
  EXPECT_NE(replay.out.find("vulkan:"), std::string::npos) << replay.out;
  EXPECT_NE(replay.out.find("NaN"), std::string::npos) << replay.out;
}

TEST_F(GateTest, PlantedInfFailsAndItsReproducerShowsTheInf) {
  // pq returns +inf for stored depths in one range: Inf appears where there
  // was none (and no NaN), and the reproducer must replay a sample that
  // gives Inf (not the worst finite one).
  Edit("shared/variants/pq.h", "  return world_from_view(frame, view);",
       "  vec3 p = world_from_view(frame, view);\n"
       "  if (stored > 0.25f && stored < 0.5f) p = vec3(uintBitsToFloat(0x7f800000u));\n"
       "  return p;");
  const auto r = Gate();
  ASSERT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("Inf appeared"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("NaN appeared"), std::string::npos) << r.out;
  const auto replay = ReplayFirstReproducer(r);
  // The line of the GPU's output: "     vulkan: (inf, inf, inf)  Inf (a finding: ...)".
  const auto at = replay.out.find("vulkan: (");
  ASSERT_NE(at, std::string::npos) << replay.out;
  const std::string line = replay.out.substr(at, replay.out.find('\n', at) - at);
  EXPECT_NE(line.find("(inf, inf, inf)  Inf (a finding"), std::string::npos) << replay.out;
}

TEST_F(GateTest, AllNanCellsAreWorseOnceWithoutABitsFigure) {
  // pq returns NaN for every sample: its cells have no finite output. They
  // were listed as worse (NaN appeared) and better (bits lost "fell" to 0.0)
  // at once; now they are worse, once, for having no finite output.
  Edit("shared/variants/pq.h", "  return world_from_view(frame, view);",
       "  return vec3(uintBitsToFloat(0x7fc00000u));");
  const auto r = Gate();
  ASSERT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("\nworse: pq/"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("all: no finite output ("), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("better: pq/"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("-> 0.00 bits"), std::string::npos) << r.out;
}

TEST(GateInputTest, ForeignOrBrokenBaselinesCannotBeJudged) {
  const std::string dir = testing::MakeTempDir("gate_inputs");
  std::ofstream(dir + "/broken.json") << "{ \"schema\": \"depthbench.baseline\", ";
  auto r = RunDepthbench({"gate", "--baseline", dir + "/broken.json"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("the baseline does not parse: " + dir + "/broken.json:1:"), std::string::npos) << r.err;
  r = RunDepthbench({"gate", "--baseline", dir + "/none.json"});
  EXPECT_EQ(r.exit_code, 2);
  // Named with the baselines beside it (a typo shows at once).
  EXPECT_NE(r.err.find("does not exist (baselines found: " + dir + "/broken.json); make one with"), std::string::npos)
      << r.err;
  // A baseline made with another sample plan.
  std::ifstream in(kBaseline);
  std::stringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  s.replace(s.find("\"seed\": 1122"), 12, "\"seed\": 1123");
  std::ofstream(dir + "/other_plan.json") << s;
  r = RunDepthbench({"gate", "--baseline", dir + "/other_plan.json"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("another sample plan"), std::string::npos) << r.err;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace depthbench

namespace depthbench {
namespace {

// Every band the gate compares can move: a half-bit-scale loss in the
// shader's arithmetic (its result scaled by 1 + 2^-20, a rounding a
// shader edit could introduce) shows in the camera-distance band too, not
// only in the ratio and depth bands (the distance bands once kept no
// arithmetic figures, so that check compared 0 with 0).
TEST(GateBandTest, AnArithmeticLossShowsInTheDistanceBand) {
  const std::string root = testing::MakeTempDir("gate_distance_band");
  testing::CopyShaderSources(root);
  ASSERT_TRUE(testing::ReplaceInFile(root + "/shared/variants/reciprocal.h", "  return world_from_view(frame, view);",
                                     "  return world_from_view(frame, view * (1.0f + 9.5367431640625e-07f));"));
  const std::string json = root + "/gate.json";
  const auto r = RunDepthbench({"gate", "--baseline", kBaseline, "--shaders", root + "/shaders", "--json", json});
  ASSERT_EQ(r.exit_code, 1) << r.out << r.err;
  const nlohmann::json verdict = nlohmann::json::parse(testing::ReadText(json));
  bool distance_band_worse = false;
  for (const auto& cell : verdict["backends"][0]["cells"]) {
    for (const auto& band : cell["worse"]) {
      if (band["band"].get<std::string>().rfind("distance ", 0) != 0) continue;
      for (const auto& reason : band["reasons"]) {
        distance_band_worse |= reason.get<std::string>().rfind("arith p99.9", 0) == 0;
      }
    }
  }
  EXPECT_TRUE(distance_band_worse) << r.out;
  fs::remove_all(root);
}

// --shaders with baselines that run no shader compares nothing an edit
// changes: refused, saying why.
TEST(GateBandTest, ShadersWithOnlyACpuBaselineAreRefused) {
  const auto r =
      RunDepthbench({"gate", "--baseline", std::string(DEPTHBENCH_SOURCE_DIR) + "/reports/baselines/cpu.json",
                     "--shaders", "/no/such/dir"});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("none of the baselines is for the vulkan backend"), std::string::npos) << r.err;
}

// A regression of half a bit at the float32 floor is caught: two more ulps
// of relative error on every divide output (the result scaled by 1 + 2^-23)
// lift reversed D32F's p99.9 from about 2 bits by about half a bit, above
// the 0.25-bit tolerance and the band's sampling interval.
TEST(GateBandTest, HalfABitAtTheFloorIsCaught) {
  const std::string root = testing::MakeTempDir("gate_half_bit");
  testing::CopyShaderSources(root);
  ASSERT_TRUE(testing::ReplaceInFile(root + "/shared/variants/divide.h", "  return world_from_view(frame, view);",
                                     "  return world_from_view(frame, view * (1.0f + 1.1920928955078125e-07f));"));
  const auto r = RunDepthbench({"gate", "--baseline", kBaseline, "--shaders", root + "/shaders"});
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("worse: divide/reversed/d32_sfloat"), std::string::npos) << r.out;
  fs::remove_all(root);
}

}  // namespace
}  // namespace depthbench
