// Variants from the user's own shader files (--variant-file) on lavapipe:
// the two examples of bench/examples/ and the contract's declarations
// (uv origin, view handedness, the input kinds). A user's function that
// restates a built-in formula must give that formula's positions, which
// the CPU backend computes: the contract's constants, the HLSL matrix
// layout and the generated programs are right only then.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bench/backends/factory.h"
#include "bench/backends/vulkan/variant_program.h"
#include "bench/base/thread_pool.h"
#include "bench/pipeline/batch.h"
#include "bench/pipeline/stats.h"
#include "bench/pipeline/user_variant.h"
#include "bench/sweep/sweep.h"

namespace depthbench {
namespace {

namespace fs = std::filesystem;

const fs::path kExamples = fs::path(DEPTHBENCH_SOURCE_DIR) / "bench" / "examples";

// The same formula on lavapipe and in GLM differs only in the order of a
// sum GLSL leaves open (tests/vulkan_backend_test.cc derives this bound:
// two chained matrix-vector products reassociated, 6 units of 2^-24 of the
// distance, 8 with a margin). A user's function that computes uv from the
// bottom-left corner adds one rounding of 1 - v (one unit of the
// coordinate), inside the margin.
constexpr double kToleranceUnits = 8.0;

class VariantFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto vulkan = MakeBackend("vulkan", BackendOptions{});
    ASSERT_TRUE(vulkan.ok()) << vulkan.status().message();
    vulkan_ = std::move(vulkan).value();
    auto cpu = MakeBackend("cpu", BackendOptions{});
    ASSERT_TRUE(cpu.ok()) << cpu.status().message();
    cpu_ = std::move(cpu).value();
  }
  // The variant of the shader file at `path`, in a catalogue of that file
  // alone that the test keeps (it replaces the one before).
  Expected<Variant> AddFile(const std::string& path) {
    DB_ASSIGN_OR_RETURN(catalogue_, MakeCatalogue({path}));
    return catalogue_->variants().back().id;
  }

  // A shader file written for the test.
  std::string WriteShader(const std::string& name, const std::string& text) {
    const fs::path path = fs::path(::testing::TempDir()) / name;
    std::ofstream(path) << text;
    return path.string();
  }

  // The user's variant on Vulkan against built-in `same` on the CPU, on
  // every cell of `same`, camera at the origin and moderate far/near.
  void ExpectSamePositions(Variant user, Variant same) {
    std::vector<Cell> user_cells, same_cells;
    for (const Cell& cell : AllCells()) {
      if (cell.variant != same) continue;
      same_cells.push_back(cell);
      user_cells.push_back(catalogue_->MakeCell(user, cell.convention, cell.format));
    }
    ASSERT_FALSE(same_cells.empty());
    const RunLayout same_layout = MakeRunLayout(same_cells);
    const RunLayout user_layout = MakeRunLayout(user_cells);
    ASSERT_EQ(same_layout.encodings, user_layout.encodings);
    Domain domain;
    domain.camera_distance = {0.0, 0.0};
    domain.ratio = {10.0, 1000.0};
    const Sampler sampler(7, domain);
    const BatchBuilder builder(sampler, same_layout.encodings);
    ThreadPool pool;
    Batch batch;
    builder.Build(0, 4096, batch, pool);
    ASSERT_TRUE(cpu_->Prepare(same_layout.cells).ok());
    Status prepared = vulkan_->Prepare(user_layout.cells);
    ASSERT_TRUE(prepared.ok()) << prepared.message();
    std::vector<std::uint32_t> which(same_cells.size());
    std::iota(which.begin(), which.end(), 0u);
    std::vector<float> cpu_scratch, vulkan_scratch;
    auto want = cpu_->Run(batch, which, cpu_scratch);
    auto got = vulkan_->Run(batch, which, vulkan_scratch);
    ASSERT_TRUE(want.ok() && got.ok());
    std::size_t compared = 0;
    const std::size_t n = batch.count;
    for (std::size_t k = 0; k < which.size(); ++k) {
      for (std::size_t i = 0; i < n; ++i) {
        const float* w = want->data() + k * n * 3 + i;
        const float* g = got->data() + k * n * 3 + i;
        if (!std::isfinite(w[0]) || !std::isfinite(w[n]) || !std::isfinite(w[2 * n])) continue;
        const double distance = std::hypot(w[0], w[n], w[2 * n]);
        const double error = std::hypot(g[0] - w[0], g[n] - w[n], g[2 * n] - w[2 * n]);
        ASSERT_LE(error, kToleranceUnits * std::ldexp(distance, -24))
            << user_cells[k].Name() << " sample " << i << ": " << same_cells[k].Name() << " (" << w[0] << ", " << w[n]
            << ", " << w[2 * n] << "), user's (" << g[0] << ", " << g[n] << ", " << g[2 * n] << ")";
        ++compared;
      }
    }
    EXPECT_GT(compared, which.size() * n / 2);
  }

  std::unique_ptr<Backend> vulkan_, cpu_;
  std::unique_ptr<const Catalogue> catalogue_;
};

TEST_F(VariantFileTest, UnityStyleHlslExampleIsInverseViewProjection) {
  auto unity = AddFile((kExamples / "unity_world_position.hlsl").string());
  ASSERT_TRUE(unity.ok()) << unity.status().message();
  EXPECT_EQ(catalogue_->Info(*unity).name, "unity_world_position");
  ExpectSamePositions(*unity, Variant::kInverseVp);
}

TEST_F(VariantFileTest, LeftHandedBottomLeftGlslIsDivide) {
  // divide restated in a left-handed view space (the camera looks down +z)
  // with uv from the bottom-left corner: wrong declarations or constants
  // mirror the position.
  const std::string path =
      WriteShader("left_handed.glsl", R"(// depthbench: input=hardware uv=bottom-left view=left-handed
vec3 reconstruct(vec2 uv, float depth) {
  vec2 ndc = vec2(uv.x * 2.0 - 1.0, uv.y * 2.0 - 1.0);
  float ndc_z = depth;
  if ((db_Convention & DB_CONVENTION_CLIP_MINUS_ONE) != 0u) ndc_z = -1.0 + depth * 2.0;
  vec3 view = vec3(ndc.x / db_Lens.z, ndc.y / db_Lens.w, 1.0) / (ndc_z / db_DepthCoefficients.y - db_DepthCoefficients.x / db_DepthCoefficients.y);
  return (db_ViewToWorld * vec4(view, 1.0)).xyz;
}
)");
  auto variant = AddFile(path);
  ASSERT_TRUE(variant.ok()) << variant.status().message();
  ExpectSamePositions(*variant, Variant::kDivide);
}

TEST_F(VariantFileTest, LinearDepthHlslIsFrustumRay) {
  const std::string path = WriteShader("ray.hlsl", R"(// depthbench: input=linear entry=FromRay
float3 FromRay(float2 uv, float linearDepth) { return db_CameraPosition + db_FrustumRay * linearDepth; }
)");
  auto variant = AddFile(path);
  ASSERT_TRUE(variant.ok()) << variant.status().message();
  ExpectSamePositions(*variant, Variant::kFrustumRay);
}

// The GLSL example subtracts before it divides: near the far plane of a
// standard-Z projection the shader's own part of the error, p99.9 13.5
// bits for divide at far/near 1e4, falls to 1.7 (float32's floor for a
// chain of roundings); the production part, the same for both, stays.
TEST_F(VariantFileTest, SubtractFirstExampleBeatsDivideNearTheFarPlane) {
  auto edit = AddFile((kExamples / "divide_subtract_first.glsl").string());
  ASSERT_TRUE(edit.ok()) << edit.status().message();
  SweepOptions options;
  options.seed = 3;
  options.samples = 100'000;
  options.domain.camera_distance = {0.0, 0.0};
  options.domain.ratio = {1e4, 1e4};
  options.cells = {{Variant::kDivide, Convention::kStandard, Format::kD32Sfloat},
                   catalogue_->MakeCell(*edit, Convention::kStandard, Format::kD32Sfloat)};
  Backend* backends[] = {vulkan_.get()};
  auto results = RunSweep(options, backends);
  ASSERT_TRUE(results.ok()) << results.status().message();
  auto bits = [&](const Cell& cell, Metric metric) {
    const CellResult* found = results->Find(cell, "vulkan");
    EXPECT_NE(found, nullptr);
    return found == nullptr ? 0.0 : BitsLost(Summarize(found->stats.All(), metric).p999);
  };
  const double divide_shader = bits(options.cells[0], Metric::kArith);
  const double edit_shader = bits(options.cells[1], Metric::kArith);
  // Eight bits: far more than the p99.9's sampling interval (a tenth of a
  // bit at 1e5 samples) and far less than the 12-bit gap measured.
  EXPECT_GT(divide_shader, 12.0);
  EXPECT_LT(edit_shader, divide_shader - 8.0);
  EXPECT_LE(bits(options.cells[1], Metric::kTotal), bits(options.cells[0], Metric::kTotal));
}

TEST_F(VariantFileTest, CompileErrorsNameTheUsersLineAndNothingGenerated) {
  // A missing ';' on line 2 makes glslang stumble again in the generated
  // lines after the user's file; that follow-on message is left out.
  const std::string path = WriteShader(
      "broken.hlsl",
      "// depthbench: input=hardware\nfloat3 reconstruct(float2 uv, float depth) { return float3(uv, depth) }\n");
  auto variant = AddFile(path);
  ASSERT_TRUE(variant.ok()) << variant.status().message();
  auto compiled =
      CompileVariant(catalogue_->Info(*variant), VariantPass::kAccuracy, fs::path(DEPTHBENCH_SOURCE_DIR) / "shaders");
  ASSERT_FALSE(compiled.ok());
  const std::string& message = compiled.status().message();
  EXPECT_NE(message.find("broken.hlsl:2: error:"), std::string::npos) << message;
  EXPECT_EQ(message.find("program>"), std::string::npos) << message;
}

// The device judge's fused program holds a GLSL function as the accuracy
// pass does; an HLSL one it refuses, so that `--judge-fusion auto` keeps
// the separate passes (device_judge.h's JudgeFusion).
TEST_F(VariantFileTest, OnlyAGlslFunctionCompilesIntoTheFusedJudge) {
  const fs::path shaders = fs::path(DEPTHBENCH_SOURCE_DIR) / "shaders";
  auto glsl = AddFile((kExamples / "divide_subtract_first.glsl").string());
  ASSERT_TRUE(glsl.ok()) << glsl.status().message();
  auto fused = CompileVariant(catalogue_->Info(*glsl), VariantPass::kJudged, shaders);
  ASSERT_TRUE(fused.ok()) << fused.status().message();
  auto alone = CompileVariant(catalogue_->Info(*glsl), VariantPass::kAccuracy, shaders);
  ASSERT_TRUE(alone.ok()) << alone.status().message();
  EXPECT_GT(fused->size(), alone->size() + 1000);  // the judge's rows come with the function
  auto unity = AddFile((kExamples / "unity_world_position.hlsl").string());
  ASSERT_TRUE(unity.ok()) << unity.status().message();
  auto refused = CompileVariant(catalogue_->Info(*unity), VariantPass::kJudged, shaders);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), StatusCode::kUnavailable);
  EXPECT_NE(refused.status().message().find("HLSL"), std::string::npos) << refused.status().message();
}

// Fused, a user's GLSL function gets a program of its own beside the one
// of the built-in variants (its contract cannot be defined twice), and the
// cells of both record what the host judge records.
TEST_F(VariantFileTest, AUsersFunctionIsJudgedFusedAsOnTheHost) {
  SweepOptions options;
  options.batch_size = 3000;  // several batches, each ending inside a frame
  options.samples = 20'000;
  auto edit = AddFile((kExamples / "divide_subtract_first.glsl").string());
  ASSERT_TRUE(edit.ok()) << edit.status().message();
  options.cells = {{Variant::kDivide, Convention::kStandard, Format::kD32Sfloat},
                   {Variant::kPq, Convention::kReversed, Format::kX8D24Unorm},
                   catalogue_->MakeCell(*edit, Convention::kStandard, Format::kD32Sfloat),
                   catalogue_->MakeCell(*edit, Convention::kReversed, Format::kX8D24Unorm)};
  Backend* backends[] = {vulkan_.get()};
  options.judge = JudgeSite::kHost;
  auto host = RunSweep(options, backends);
  ASSERT_TRUE(host.ok()) << host.status().message();
  options.judge = JudgeSite::kDevice;
  options.device_tuning.fusion = JudgeFusion::kFused;
  auto fused = RunSweep(options, backends);
  ASSERT_TRUE(fused.ok()) << fused.status().message();
  ASSERT_EQ(host->cells.size(), 4u);
  ASSERT_EQ(fused->cells.size(), 4u);
  for (std::size_t c = 0; c < host->cells.size(); ++c) {
    EXPECT_TRUE(host->cells[c].stats == fused->cells[c].stats) << host->cells[c].cell.Name();
    EXPECT_GT(fused->cells[c].stats.All().finite, 10'000u) << host->cells[c].cell.Name();
  }
}

TEST_F(VariantFileTest, CpuBackendSaysItCannotRunAShaderFile) {
  auto unity = AddFile((kExamples / "unity_world_position.hlsl").string());
  ASSERT_TRUE(unity.ok());
  const RunLayout layout =
      MakeRunLayout(std::vector<Cell>{catalogue_->MakeCell(*unity, Convention::kReversed, Format::kD32Sfloat)});
  const Status status = cpu_->Prepare(layout.cells);
  EXPECT_EQ(status.code(), StatusCode::kUnavailable);
  EXPECT_NE(status.message().find("runs on Vulkan only"), std::string::npos) << status.message();
}

TEST_F(VariantFileTest, DeclarationsAreChecked) {
  auto missing = AddFile(WriteShader("plain.glsl", "vec3 reconstruct(vec2 uv, float d) { return vec3(0); }\n"));
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("no '// depthbench:' line"), std::string::npos);
  auto unknown = AddFile(WriteShader("typo.glsl", "// depthbench: input=hardware handed=left\n"));
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.status().message().find("typo.glsl:1: unknown key 'handed'"), std::string::npos)
      << unknown.status().message();
  auto taken = AddFile(WriteShader("divide.glsl", "// depthbench: input=hardware\n"));
  ASSERT_FALSE(taken.ok());
  EXPECT_NE(taken.status().message().find("'divide' is taken"), std::string::npos);
  auto language = AddFile(WriteShader("f.frag", "// depthbench: input=hardware\n"));
  ASSERT_FALSE(language.ok());
  // Two files may not declare one name.
  const std::string path = (kExamples / "divide_subtract_first.glsl").string();
  auto twice =
      MakeCatalogue({path, WriteShader("other.glsl", "// depthbench: input=hardware name=divide_subtract_first\n")});
  ASSERT_FALSE(twice.ok());
  EXPECT_NE(twice.status().message().find("is taken by another --variant-file"), std::string::npos)
      << twice.status().message();
  // The same file twice is one variant.
  auto same = MakeCatalogue({path, path});
  ASSERT_TRUE(same.ok()) << same.status().message();
  EXPECT_EQ((*same)->variants().size(), static_cast<std::size_t>(kVariantCount) + 1);
}

// A catalogue belongs to the command that made it: one made with a file
// leaves the built-in catalogue, and the next one made without it, as
// they were.
TEST_F(VariantFileTest, ACatalogueLeavesNothingForTheNext) {
  auto with_file = MakeCatalogue({(kExamples / "divide_subtract_first.glsl").string()});
  ASSERT_TRUE(with_file.ok()) << with_file.status().message();
  EXPECT_TRUE((*with_file)->has_user_variants());
  EXPECT_TRUE((*with_file)->ParseVariant("divide_subtract_first").ok());
  auto without = MakeCatalogue({});
  ASSERT_TRUE(without.ok());
  for (const Catalogue* catalogue : {without->get(), &Catalogue::BuiltIn()}) {
    EXPECT_FALSE(catalogue->has_user_variants());
    EXPECT_EQ(catalogue->variants().size(), static_cast<std::size_t>(kVariantCount));
    EXPECT_EQ(catalogue->Cells().size(), AllCells().size());
    EXPECT_FALSE(catalogue->ParseVariant("divide_subtract_first").ok());
  }
}

}  // namespace
}  // namespace depthbench
