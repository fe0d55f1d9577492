// Scene files: what they describe, and the errors bad ones get (file, line,
// field, what is allowed).
#include <cctype>

#include <gtest/gtest.h>

#include "bench/choose/scene.h"

namespace depthbench {
namespace {

const std::string kScenes = std::string(DEPTHBENCH_SOURCE_DIR) + "/bench/scenes/";

constexpr const char* kValid = R"(name = "test"
[projection]
near = 0.5
far = 50000
fov_degrees = [50, 90]
aspect = 1.78
resolution = [1920, 1080]
[camera]
distance_from_origin = [0, 20000]
[engine]
conventions = ["standard", "reversed"]
formats = ["d24", "d32_sfloat"]
[requirement]
absolute_error = 0.01
at_depth = 5000
)";

TEST(SceneTest, ParsesEveryFieldIntoTheDomain) {
  auto scene = ParseScene(kValid, "valid.toml");
  ASSERT_TRUE(scene.ok()) << scene.status().message();
  EXPECT_EQ(scene->name, "test");
  EXPECT_EQ(scene->domain.near, (Range{0.5, 0.5}));
  EXPECT_EQ(scene->domain.far, (Range{50000, 50000}));
  EXPECT_TRUE(scene->domain.finite_far);
  EXPECT_FALSE(scene->domain.infinite_far);
  EXPECT_EQ(scene->domain.fov_degrees, (Range{50, 90}));
  EXPECT_EQ(scene->domain.aspect, (Range{1.78, 1.78}));
  EXPECT_EQ(scene->domain.camera_distance, (Range{0, 20000}));
  EXPECT_EQ(scene->domain.resolutions.size(), 1u);
  EXPECT_EQ(scene->requirement.kind, Requirement::Kind::kAbsolute);
  EXPECT_EQ(scene->requirement.at_depth, 5000.0);
  EXPECT_DOUBLE_EQ(scene->requirement.RelativeLimit(), 0.01 / 5000);
  // Standard and reversed, finite far, hardware formats only: 4 variants x 2 x 2.
  EXPECT_EQ(scene->Candidates().size(), 16u);
}

TEST(SceneTest, ExampleScenesLoad) {
  for (const char* name : {"indoor_shooter", "open_world", "space_game", "cad_viewer", "spot_shadow", "flight_sim",
                           "engine_matrix", "vr_asymmetric", "taa_jitter", "shadow_ortho"}) {
    auto scene = LoadScene(kScenes + name + ".toml");
    EXPECT_TRUE(scene.ok()) << name << ": " << scene.status().message();
  }
  auto space = LoadScene(kScenes + "space_game.toml");
  ASSERT_TRUE(space.ok());
  EXPECT_FALSE(space->domain.finite_far);  // far = "inf"
  for (const Cell& c : space->Candidates()) EXPECT_NE(Info(c.format).stores, DepthInput::kLinear) << c.Name();
}

TEST(SceneTest, EngineMatrixFixesPlanesLensAndConvention) {
  auto scene = LoadScene(kScenes + "engine_matrix.toml");
  ASSERT_TRUE(scene.ok()) << scene.status().message();
  const Domain& d = scene->domain;
  EXPECT_EQ(d.near, (Range{0.1, 0.1}));
  EXPECT_FALSE(d.finite_far);  // reversed infinite
  ASSERT_TRUE(d.depth_convention.has_value());
  EXPECT_EQ(*d.depth_convention, Convention::kReversedInf);
  ASSERT_TRUE(d.eye_fov.has_value());
  // The 60-degree lens: the baked jitter (2e-4 of the ray) changes the
  // angle it spans only in the second order, by about 1e-6 degree.
  EXPECT_NEAR(d.eye_fov->up - d.eye_fov->down, 60.0, 1e-5);
  EXPECT_TRUE(d.OffCentre());                                  // the jitter baked into the matrix, and jitter = 0.5
  EXPECT_EQ(d.jitter, 0.5);
  EXPECT_EQ(scene->api, GraphicsApi::kVulkan);
  // Only the matrix's convention among the projective ones.
  for (const Cell& c : scene->Candidates()) {
    if (Info(c.convention).hardware) {
      EXPECT_EQ(c.convention, Convention::kReversedInf) << c.Name();
    }
  }
}

TEST(SceneTest, EyeFovAndJitterAreTheDomainsLens) {
  auto scene = LoadScene(kScenes + "vr_asymmetric.toml");
  ASSERT_TRUE(scene.ok()) << scene.status().message();
  ASSERT_TRUE(scene->domain.eye_fov.has_value());
  EXPECT_EQ(*scene->domain.eye_fov, (EyeFov{-52, 43, 47, -53}));
  EXPECT_TRUE(scene->domain.OffCentre());
  auto taa = LoadScene(kScenes + "taa_jitter.toml");
  ASSERT_TRUE(taa.ok()) << taa.status().message();
  EXPECT_EQ(taa->domain.jitter, 0.5);
  EXPECT_TRUE(taa->domain.OffCentre());
  auto plain = LoadScene(kScenes + "indoor_shooter.toml");
  ASSERT_TRUE(plain.ok());
  EXPECT_FALSE(plain->domain.OffCentre());
}

struct BadScene {
  std::string from, to;  // an edit of kValid
  std::string message;   // part of the error
};

// A readable test name: the field the message is about, as in
// "projection_near_3".
std::string TestNameOf(const std::string& message, size_t index) {
  std::string field = message.substr(message.find(": ") == std::string::npos ? 0 : message.find(": ") + 2);
  field = field.substr(0, field.find(':'));
  std::string name;
  for (char c : field) name += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return name + "_" + std::to_string(index);
}

// What ctest shows for a case (gtest_discover_tests prints the parameter).
void PrintTo(const BadScene& bad, std::ostream* os) { *os << TestNameOf(bad.message, 0); }

class BadSceneTest : public ::testing::TestWithParam<BadScene> {};

TEST_P(BadSceneTest, NamesFileLineFieldAndWhatIsAllowed) {
  std::string text = kValid;
  const BadScene& bad = GetParam();
  const auto at = text.find(bad.from);
  ASSERT_NE(at, std::string::npos) << bad.from;
  text.replace(at, bad.from.size(), bad.to);
  auto scene = ParseScene(text, "bad.toml");
  ASSERT_FALSE(scene.ok()) << text;
  EXPECT_NE(scene.status().message().find(bad.message), std::string::npos) << scene.status().message();
}

INSTANTIATE_TEST_SUITE_P(
    Errors, BadSceneTest,
    ::testing::Values(
        BadScene{"near = 0.5\n", "", "bad.toml: projection.near: missing"},
        BadScene{"near = 0.5", "near = -1", "bad.toml:3:8: projection.near: must be greater than 0 (got -1)"},
        BadScene{"near = 0.5", "near = \"close\"", "bad.toml:3:8: projection.near: expected a number"},
        BadScene{"far = 50000", "far = 0.2", "bad.toml:4:7: projection.far: must be greater than near (0.5); got 0.2"},
        BadScene{"far = 50000", "far = \"forever\"", "bad.toml:4:7: projection.far: expected a number or \"inf\""},
        BadScene{"fov_degrees = [50, 90]", "fov_degrees = [50, 190]",
                 "bad.toml:5:15: projection.fov_degrees: 50:190 is out of range; allowed (0, 180) degrees"},
        BadScene{"aspect = 1.78", "aspect = [1, 2, 3]",
                 "bad.toml:6:10: projection.aspect: expected a number or [min, max]"},
        BadScene{"formats = [\"d24\", \"d32_sfloat\"]", "formats = [\"d24\", \"d48\"]",
                 "bad.toml:12:19: engine.formats: unknown format 'd48'; allowed: d16_unorm (d16)"},
        BadScene{"conventions = [\"standard\", \"reversed\"]", "conventions = [\"sideways\"]",
                 "engine.conventions: unknown convention 'sideways'; allowed: standard, reversed"},
        BadScene{"at_depth = 5000\n", "", "requirement.at_depth: an absolute error needs the eye depth it applies at"},
        BadScene{"absolute_error = 0.01", "absolute_error = 0.01\nrelative_error = 1e-4",
                 "[requirement]: needs exactly one of absolute_error (world units), relative_error, bits_lost"},
        BadScene{"at_depth = 5000", "at_depth = 90000",
                 "requirement.at_depth: must lie in the scene's eye-depth range [0.5, 50000]; got 90000"},
        BadScene{"[camera]", "[cameras]", "bad.toml:8:1: cameras: unknown field; allowed here: name, projection"},
        BadScene{"resolution = [1920, 1080]", "resolution = [1920]",
                 "projection.resolution: expected [width, height] in pixels"},
        BadScene{"[requirement]", "[requirement]\nlevel = \"p42\"", "requirement.level: allowed: \"p99.9\", \"max\", \"bound\""},
        BadScene{"name = \"test\"", "name = \"test\"\nbroken = = 1", "bad.toml:2:"},
        BadScene{"aspect = 1.78", "aspect = 1.78\neye_fov = [-40, 40, 30, -30]",
                 "eye_fov sets the lens; give one or the other"},
        BadScene{"aspect = 1.78", "aspect = 1.78\northo = [-40, 40, -30, 30]",
                 "projection.fov_degrees: ortho sets the lens; give one or the other"},
        BadScene{"fov_degrees = [50, 90]\naspect = 1.78", "ortho = [-40, 40, 30, -30]",
                 "projection.ortho: ortho: -40,40,30,-30 has no area"},
        BadScene{"fov_degrees = [50, 90]\naspect = 1.78", "eye_fov = [40, -40, 30, -30]",
                 "projection.eye_fov: eye_fov: 40,-40,30,-30 has no area"},
        BadScene{"aspect = 1.78", "aspect = 1.78\njitter = 9", "projection.jitter: allowed [0, 4] pixels"},
        BadScene{"near = 0.5\nfar = 50000\nfov_degrees = [50, 90]\naspect = 1.78",
                 "matrix = [1, 0, 0.5, 0, 0, 1, 0, 0, 0, 0, -1, -1, 0, 0, -0.2, 0]\napi = \"vulkan\"\n"
                 "layout = \"column-major\"",
                 "projection.matrix: projection matrix: an oblique near plane"},
        BadScene{"near = 0.5\nfar = 50000\nfov_degrees = [50, 90]\naspect = 1.78",
                 "matrix = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, -1, 0, 0, -0.2, 0]\napi = \"dx12\"\n"
                 "layout = \"column-major\"",
                 "projection.api: API 'dx12' is not one of d3d, vulkan"},
        BadScene{"near = 0.5\nfar = 50000", "near = 0.5\nfar = 50000\napi = \"vulkan\"",
                 "projection.api: describes projection.matrix, which is not given"},
        BadScene{"near = 0.5\nfar = 50000\nfov_degrees = [50, 90]\naspect = 1.78",
                 "matrix = [1, 0, 0]\napi = \"vulkan\"\nlayout = \"column-major\"",
                 "projection.matrix: expected 16 numbers"}),
    [](const ::testing::TestParamInfo<BadScene>& info) { return TestNameOf(info.param.message, info.index); });

}  // namespace
}  // namespace depthbench
