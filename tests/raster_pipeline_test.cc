// --pipeline raster on lavapipe: every cell runs through a real graphics
// pipeline (depth attachments, texel fetch, rays from the vertex stage).
// At far/near 1e4 with the camera at the origin, in the far plane's decade:
//   - reversed D32F reads as the compute form (float32 production) within
//     half a bit;
//   - standard D24 loses more, for two measured reasons: the vertex
//     transform (the view-projection matrix times a world-space corner,
//     where depth is spread over three coordinates, rounds three to four
//     times where the compute form's A * z + B rounds twice), seen in the
//     host's model with exact interpolation; and the device's own vertex
//     arithmetic and depth-plane evaluation, which the Vulkan specification
//     leaves to the implementation (docs/raster.md): lavapipe within half a
//     bit of the host's model.
#include <algorithm>
#include <cmath>
#include <map>

#include <gtest/gtest.h>

#include "bench/backends/cpu/cpu_backend.h"
#include "bench/backends/vulkan/vulkan_backend.h"
#include "bench/sweep/sweep.h"
#include "tests/sanitized_stage.h"

namespace depthbench {
namespace {

constexpr int kDeepestDecade = 3;  // z/n in [1e3, 1e4): the far plane's decade at f/n 1e4
// The figures need 1e4 samples in the deepest decade; the sanitized stage
// runs only the tests that check what runs (sanitized_stage.h), on fewer.
constexpr std::uint64_t kSamples = testing::kSanitized ? 6000 : 60000;

class RasterPipelineTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    VulkanContextOptions context_options;
    context_options.validation = true;
    auto context = VulkanContext::Create(context_options);
    ASSERT_TRUE(context.ok()) << context.status().message();
    context_ = new std::shared_ptr<VulkanContext>(std::move(context).value());
  }
  static void TearDownTestSuite() {
    delete compute_;
    delete raster_;
    delete host_model_;
    delete context_;
  }

  // Every cell at f/n 1e4 with the camera at the origin, on the Vulkan
  // backend and the CPU backend: in the raster form the Vulkan backend
  // renders the depths both reconstruct from; without it, the CPU backend
  // alone runs the host's model of the raster pipeline.
  static Results Sweep(ProductionModel production, bool with_vulkan) {
    SweepOptions options;
    options.seed = 41;
    options.samples = kSamples;
    options.domain.ratio = {1e4, 1e4};
    options.domain.infinite_far = false;
    options.domain.camera_distance = {0.0, 0.0};
    options.domain.production = production;
    auto vulkan = MakeVulkanBackend(*context_, BackendOptions{});
    EXPECT_TRUE(vulkan.ok()) << vulkan.status().message();
    if (!vulkan.ok()) return {};
    auto cpu = MakeCpuBackend();
    std::vector<Backend*> backends = {cpu.get()};
    if (with_vulkan) backends.insert(backends.begin(), vulkan->get());
    auto run = RunSweep(options, backends);
    EXPECT_TRUE(run.ok()) << run.status().message();
    if (!run.ok()) return {};
    const std::vector<std::string> messages = (*context_)->TakeValidationMessages();
    EXPECT_TRUE(messages.empty()) << messages.front();
    return std::move(run).value();
  }

  static const CellResult* Find(const Results& results, const Cell& cell, const std::string& backend) {
    for (const CellResult& c : results.cells) {
      if (c.cell == cell && c.backend == backend) return &c;
    }
    return nullptr;
  }

  static double DeepestP999(const CellResult& c, Metric metric = Metric::kTotal) {
    const BandStats band = c.stats.ForDepth(kDeepestDecade);
    EXPECT_GT(band.finite, 10000u) << c.cell.Name();
    return BitsLost(Summarize(band, metric).p999);
  }

  // Each sweep is run once, when a test first asks for it: CTest runs the
  // binary as one test (ONE_PROCESS, vulkan_tests.cmake), and a sweep no
  // test reads (under the sanitizers most are skipped) is time lost.
  static const Results& Lazy(Results*& results, ProductionModel production, bool with_vulkan) {
    if (results == nullptr) results = new Results(Sweep(production, with_vulkan));
    return *results;
  }
  static const Results& Compute() { return Lazy(compute_, ProductionModel::kFloat32, /*with_vulkan=*/true); }
  static const Results& Raster() { return Lazy(raster_, ProductionModel::kRaster, /*with_vulkan=*/true); }
  static const Results& HostModel() { return Lazy(host_model_, ProductionModel::kRaster, /*with_vulkan=*/false); }

  static std::shared_ptr<VulkanContext>* context_;
  static Results* compute_;
  static Results* raster_;
  static Results* host_model_;
};
std::shared_ptr<VulkanContext>* RasterPipelineTest::context_ = nullptr;
Results* RasterPipelineTest::compute_ = nullptr;
Results* RasterPipelineTest::raster_ = nullptr;
Results* RasterPipelineTest::host_model_ = nullptr;

TEST_F(RasterPipelineTest, EveryCellRunsAndIsJudged) {
  ASSERT_FALSE(Compute().cells.empty());
  int cells = 0;
  for (const CellResult& c : Compute().cells) {
    if (c.backend != "vulkan") continue;
    const CellResult* r = Find(Raster(), c.cell, "vulkan");
    ASSERT_NE(r, nullptr) << c.cell.Name() << " did not run in raster mode";
    ++cells;
    // At the origin every sample of the natural population has geometry:
    // as many are judged as in the compute form, none non-finite.
    const BandStats raster = r->stats.All(), compute = c.stats.All();
    EXPECT_GT(compute.finite, kSamples / 2) << c.cell.Name();
    // (Less those whose texel the rasterizer left as cleared: counted
    // apart, UncoveredTexelsAreCountedApartAndNotJudged.)
    EXPECT_EQ(raster.finite + raster.undrawn, compute.finite) << c.cell.Name();
    EXPECT_EQ(raster.nan + raster.inf, 0u) << c.cell.Name() << ": non-finite findings";
  }
  EXPECT_GE(cells, 8 * 3);  // every variant, with at least three encodings each
  // The compute form renders nothing: no raster agreement is recorded.
  for (const BackendRecord& b : Compute().run.backends) EXPECT_TRUE(b.raster_agreement.empty()) << b.name;
}

// The agreement of the rendered depths with the host's model is part of
// the results: one record per encoding for the backend that rendered them,
// none for the others (nor in the compute form: EveryCellRunsAndIsJudged);
// --json keeps it and merge adds the shards' counts.
TEST_F(RasterPipelineTest, TheRasterAgreementIsKeptInTheResults) {
  ASSERT_EQ(Raster().run.backends.size(), 2u);
  const std::vector<RasterAgreement>& agreement = Raster().run.backends[0].raster_agreement;
  const RunLayout layout = MakeRunLayout(Raster().run.cells);
  ASSERT_EQ(agreement.size(), layout.encodings.size());
  for (std::size_t slot = 0; slot < agreement.size(); ++slot) {
    EXPECT_EQ(agreement[slot].encoding, layout.encodings[slot]) << slot;
    // At the origin every sample of the natural population has geometry
    // (EveryCellRunsAndIsJudged), and more than half of all are natural.
    EXPECT_GT(agreement[slot].texels, kSamples / 2) << slot;
    EXPECT_LE(agreement[slot].differing, agreement[slot].texels) << slot;
  }
  EXPECT_TRUE(Raster().run.backends[1].raster_agreement.empty());  // the CPU backend renders nothing

  const Expected<Results> read = ResultsFromJson(ToJson(Raster()), "raster.json");
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(read->run.backends[0].raster_agreement, agreement);

  Results first = Raster(), second = Raster();
  first.run.shards = {Shard{1, 2}};
  second.run.shards = {Shard{2, 2}};
  const Expected<Results> merged = MergeResults({first, second}, {"first", "second"}, false);
  ASSERT_TRUE(merged.ok()) << merged.status().message();
  const std::vector<RasterAgreement>& sum = merged->run.backends[0].raster_agreement;
  ASSERT_EQ(sum.size(), agreement.size());
  for (std::size_t slot = 0; slot < sum.size(); ++slot) {
    EXPECT_EQ(sum[slot].texels, 2 * agreement[slot].texels) << slot;
    EXPECT_EQ(sum[slot].differing, 2 * agreement[slot].differing) << slot;
    EXPECT_EQ(sum[slot].max_code_distance, agreement[slot].max_code_distance) << slot;
  }
}

// A sample is rasterized at the same atlas texel whatever batch it is in
// (its index in the sweep places it), so that the device's texels, and
// every figure judged from them, do not depend on the batch size. When a
// sample's texel was its place in its batch, batches of 1024 and 4096
// samples on lavapipe gave other r32_sfloat and x8_d24 texels in about
// 0.2% of samples, and this test failed. Batches of 5000 over 263000
// samples include one whose texels wrap round the atlas's end (its 262144
// texels), drawn over the whole atlas.
TEST_F(RasterPipelineTest, TheTexelsDoNotDependOnTheBatchSize) {
  const auto sweep = [&](std::uint32_t batch, std::uint64_t samples, std::vector<std::string> cells) {
    SweepOptions options;
    options.seed = 3;
    options.samples = samples;
    options.batch_size = batch;
    options.domain.production = ProductionModel::kRaster;
    for (const std::string& name : cells) options.cells.push_back(*ParseCell(name));
    auto vulkan = MakeVulkanBackend(*context_, BackendOptions{});
    EXPECT_TRUE(vulkan.ok()) << vulkan.status().message();
    Backend* backends[] = {vulkan->get()};
    auto run = RunSweep(options, backends);
    EXPECT_TRUE(run.ok()) << run.status().message();
    EXPECT_TRUE((*context_)->TakeValidationMessages().empty());
    return run.ok() ? std::move(run).value() : Results{};
  };
  const auto expect_same = [](const Results& a, const Results& b) {
    ASSERT_EQ(a.cells.size(), b.cells.size());
    ASSERT_FALSE(a.cells.empty());
    const std::vector<RasterAgreement>& agreement = a.run.backends.at(0).raster_agreement;
    EXPECT_EQ(agreement, b.run.backends.at(0).raster_agreement);
    // (The comparison means something: the device and the host's model
    // differ in many texels.)
    ASSERT_FALSE(agreement.empty());
    EXPECT_GT(agreement[0].differing, 1000u);
    for (std::size_t c = 0; c < a.cells.size(); ++c) {
      EXPECT_TRUE(a.cells[c].stats == b.cells[c].stats) << a.cells[c].cell.Name();
    }
  };
  const std::vector<std::string> two = {"frustum_ray/linear/r32f", "divide/standard/d24"};
  expect_same(sweep(1024, 20000, two), sweep(4096, 20000, two));
  const std::vector<std::string> one = {"frustum_ray/linear/r32f"};
  expect_same(sweep(4096, 263000, one), sweep(5000, 263000, one));
}

// A texel the rasterizer leaves as cleared (a triangle within a float32
// step of the far plane fails the pass's depth test) holds no depth of its
// sample's: judged, it made every linear cell's maximum 24.0 bits (the
// cleared 0 denotes the camera). Each one is counted as undrawn, exactly as
// many as the agreement's uncovered texels, and the maxima are a format's.
TEST_F(RasterPipelineTest, UncoveredTexelsAreCountedApartAndNotJudged) {
  // (The sanitized stage's few thousand samples leave no texel uncovered.)
  DEPTHBENCH_FIGURES_ONLY("EveryCellRunsAndIsJudged");
  const std::vector<RasterAgreement>& agreement = Raster().run.backends[0].raster_agreement;
  const RunLayout layout = MakeRunLayout(Raster().run.cells);
  std::uint64_t uncovered = 0;
  for (const RasterAgreement& a : agreement) uncovered += a.uncovered;
  EXPECT_GT(uncovered, 0u) << "no texel left uncovered: the check below would pass on the old code";
  // Nor is an uncovered texel compared with the model: a linear or view-z
  // target's cleared 0 lies 2^14 (r16_sfloat) to 2^30 (r32_sfloat) codes
  // from the depth the model gives a sample at the far end, where the
  // drawn texels of these slots differ from it by 5 codes at most on
  // lavapipe.
  std::size_t linear_uncovered = 0;
  for (const RasterAgreement& a : agreement) {
    if (Info(a.encoding.format).stores == DepthInput::kHardware || a.uncovered == 0) continue;
    ++linear_uncovered;
    EXPECT_LE(a.max_code_distance, 16u) << Info(a.encoding.convention).name << "/" << Info(a.encoding.format).name;
  }
  EXPECT_GT(linear_uncovered, 0u);
  for (const CellResult& c : Raster().cells) {
    if (c.backend != "vulkan") continue;
    std::uint64_t undrawn = 0;
    for (const auto* bands : {&c.stats.joint, &c.stats.coverage}) {
      for (const auto& entry : *bands) undrawn += entry.second.undrawn;
    }
    const auto slot = std::find(layout.encodings.begin(), layout.encodings.end(), c.cell.encoding());
    ASSERT_NE(slot, layout.encodings.end()) << c.cell.Name();
    EXPECT_EQ(undrawn, agreement[static_cast<std::size_t>(slot - layout.encodings.begin())].uncovered)
        << c.cell.Name();
    if (Info(c.cell.format).stores == DepthInput::kHardware) continue;
    // A linear or view-z target's worst: r16_unorm's step at the far end
    // of f/n 1e4 is about 20 bits; nothing near 24.
    EXPECT_LT(BitsLost(Summarize(c.stats.All(), Metric::kTotal).max), 21.0) << c.cell.Name();
  }
}

TEST_F(RasterPipelineTest, FarPlaneFiguresFollowTheComputeFormAndTheHostModel) {
  DEPTHBENCH_FIGURES_ONLY("EveryCellRunsAndIsJudged");
  int compared = 0;
  for (const CellResult& c : Compute().cells) {
    if (c.backend != "vulkan") continue;
    const bool standard_d24 = c.cell.convention == Convention::kStandard && c.cell.format == Format::kX8D24Unorm;
    const bool reversed_d32 = c.cell.convention == Convention::kReversed && c.cell.format == Format::kD32Sfloat;
    if (!standard_d24 && !reversed_d32) continue;
    const CellResult* device = Find(Raster(), c.cell, "vulkan");
    const CellResult* model = Find(HostModel(), c.cell, "cpu");
    ASSERT_NE(device, nullptr);
    ASSERT_NE(model, nullptr);
    const double compute_bits = DeepestP999(c), model_bits = DeepestP999(*model), device_bits = DeepestP999(*device);
    if (reversed_d32) {
      // Float32 depth keeps its relative precision through any few
      // roundings: half a bit.
      EXPECT_NEAR(device_bits, compute_bits, 0.5) << c.cell.Name();
    } else {
      // The vertex transform: the host's model (exact interpolation) loses
      // up to a bit more than the compute form, never less than it less
      // a quarter (the quarter-bit bins).
      EXPECT_LT(model_bits - compute_bits, 1.0) << c.cell.Name();
      EXPECT_GT(model_bits - compute_bits, -0.25) << c.cell.Name();
    }
    // The device's rasterizer against the host's model of it. Lavapipe's
    // depth differs from the exact interpolation of its vertices by up to
    // 4 or 5 codes of D24 (about as many ulps of 1, the depth plane being
    // evaluated in float32 from an origin away from the pixel; forbidding
    // contraction changes nothing), where the format's own step is one
    // code: up to about half a bit at p99.9 (0.54 measured), plus the
    // quarter-bit bins and the sampling noise of 1e4 samples in the decade.
    EXPECT_NEAR(device_bits, model_bits, 0.75) << c.cell.Name();
    ++compared;
  }
  EXPECT_EQ(compared, 8);  // the four projective variants, two encodings each
}

TEST_F(RasterPipelineTest, TheShaderPartIsTheComputeFormsOnTheDevicesTexels) {
  DEPTHBENCH_FIGURES_ONLY("EveryCellRunsAndIsJudged");
  // The device's texels (and its fetch's conversion to float) are adopted
  // into the reference, so with clip depth [0, 1] the shader part of a
  // variant without rays is its arithmetic alone, as in the compute form:
  // within the quarter-bit bins and the sampling noise of a p99.9 (half a
  // bit). Before the fetch was adopted, lavapipe's unorm conversion (up to
  // 2 ulps off) read as 13 bits of "shader" error here.
  int compared = 0;
  for (const CellResult& c : Compute().cells) {
    if (c.backend != "vulkan" || Info(c.cell.variant).input != DepthInput::kHardware) continue;
    if ((Info(c.cell.convention).bits & f32::DB_CONVENTION_CLIP_MINUS_ONE) != 0u) continue;
    const CellResult* device = Find(Raster(), c.cell, "vulkan");
    ASSERT_NE(device, nullptr);
    EXPECT_NEAR(DeepestP999(*device, Metric::kArith), DeepestP999(c, Metric::kArith), 0.5) << c.cell.Name();
    ++compared;
  }
  EXPECT_EQ(compared, 4 * 3 * 2);  // four variants, three formats, standard and reversed (finite far)
}

TEST_F(RasterPipelineTest, RasterizedFloatDepthShowsTheCostOfTheGlRemap) {
  DEPTHBENCH_FIGURES_ONLY("EveryCellRunsAndIsJudged");
  // What only the raster form shows: with GL-style clip depth the shader
  // maps window depth d back to NDC as -1 + 2d. The compute form's d was
  // made as 0.5 * ndc + 0.5 from a float NDC, so that map gives the NDC
  // back exactly (Sterbenz) and costs nothing. A rasterizer interpolates
  // d itself, with float32's full resolution near 0 (reversed Z's far
  // plane), and -1 + 2d rounds that to the resolution of 1: several bits
  // of the shader's (10.7 measured for reciprocal against 1.5). The host's
  // model shows the same, so it is the pipeline, not lavapipe.
  const Cell cell{Variant::kReciprocal, Convention::kReversedGl, Format::kD32Sfloat};
  const CellResult* compute = Find(Compute(), cell, "vulkan");
  const CellResult* device = Find(Raster(), cell, "vulkan");
  const CellResult* model = Find(HostModel(), cell, "cpu");
  ASSERT_TRUE(compute != nullptr && device != nullptr && model != nullptr);
  EXPECT_GT(DeepestP999(*device, Metric::kArith), DeepestP999(*compute, Metric::kArith) + 4.0);
  EXPECT_GT(DeepestP999(*model, Metric::kArith), DeepestP999(*compute, Metric::kArith) + 4.0);
}

}  // namespace
}  // namespace depthbench
