// The raster form of the Vulkan backend on lavapipe: it draws every
// sample's geometry, produces depth with the rasterizer and reconstructs in
// a fragment program; on the texels the device stored, it must agree with
// the compute form. Runs with the validation layer on and fails on anything
// it reports.
//
// The geometry here is the test's own (the host's raster model may not be
// there): for a sample of an eye-depth pick, a triangle a few pixels wide,
// facing the camera (in the plane of constant eye depth) through the
// sample's point on its pixel's ray, and a cube of half-edge a quarter of
// the eye depth around the point; other picks get none.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "bench/backends/vulkan/raster_pass.h"
#include "bench/backends/vulkan/vulkan_backend.h"
#include "bench/backends/vulkan/vulkan_context.h"
#include "bench/base/thread_pool.h"
#include "bench/pipeline/batch.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/encode.h"
#include "bench/pipeline/sampler.h"

namespace depthbench {
namespace {

constexpr std::uint64_t kSeed = 20251202;

// The camera at the origin, far/near 1e4 (and infinite far planes).
Domain RasterDomain() {
  Domain domain;
  domain.camera_distance = {0.0, 0.0};
  domain.ratio = {1e4, 1e4};
  return domain;
}

glm::vec4 Corner(const glm::dvec3& p) {
  return {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z), 1.0f};
}

// The test's geometry for sample `index` (see the top of the file).
f32::RasterSample GeometryOf(const Sampler& sampler, std::uint64_t index) {
  const Frame frame = sampler.FrameAt(index / kSamplesPerFrame);
  const PixelSample sample = sampler.SampleAt(index, frame);
  if (sample.pick != DepthPick::kEyeDepth || !(sample.eye_depth < frame.depth_limit)) return {};
  const double d = sample.eye_depth;
  const double tan_y = frame.tan_half_fov_y, tan_x = tan_y * frame.aspect;
  const double ndc_x = (sample.x + 0.5) / frame.width * 2.0 - 1.0;
  const double ndc_y = 1.0 - (sample.y + 0.5) / frame.height * 2.0;
  // One pixel at eye depth d, along x and y.
  const double px = 2.0 * tan_x * d / frame.width, py = 2.0 * tan_y * d / frame.height;
  const auto world = [&](double x, double y) {
    return frame.camera_position + frame.rotation * glm::dvec3(ndc_x * tan_x * d + x, ndc_y * tan_y * d + y, -d);
  };
  const glm::dvec3 centre = world(0.0, 0.0);
  return {Corner(world(-2.0 * px, -py)), Corner(world(2.0 * px, -py)), Corner(world(0.0, 2.0 * py)),
          {static_cast<float>(centre.x), static_cast<float>(centre.y), static_cast<float>(centre.z),
           static_cast<float>(0.25 * d)}};
}

Batch BuildBatch(const RunLayout& layout, std::uint64_t first, std::uint32_t count) {
  const Sampler sampler(kSeed, RasterDomain());
  const BatchBuilder builder(sampler, layout.encodings);
  ThreadPool pool;
  Batch batch;
  builder.Build(first, count, batch, pool);
  batch.raster.resize(count);
  for (std::uint32_t i = 0; i < count; ++i) batch.raster[i] = GeometryOf(sampler, first + i);
  return batch;
}

bool HasGeometry(const f32::RasterSample& s) {
  return s.triangle0 != glm::vec4(0.0f) || s.triangle1 != glm::vec4(0.0f) || s.triangle2 != glm::vec4(0.0f);
}

// Every variant; per variant the formats it reads under four conventions:
// standard, reversed-inf, and both GL-style ones (depth clip control).
RunLayout RepresentativeLayout() {
  CellFilter filter;
  filter.conventions = {Convention::kStandard, Convention::kReversedInf, Convention::kStandardGl,
                        Convention::kReversedGl, Convention::kLinear};
  std::vector<Cell> cells;
  for (const Cell& cell : AllCells()) {
    if (filter.Keeps(cell)) cells.push_back(cell);
  }
  return MakeRunLayout(cells);
}

std::vector<std::uint32_t> AllIndices(const RunLayout& layout) {
  std::vector<std::uint32_t> which(layout.cells.size());
  std::iota(which.begin(), which.end(), 0u);
  return which;
}

bool RayVariant(Variant variant) {
  return variant == Variant::kFrustumRay || variant == Variant::kVolumeRay || variant == Variant::kEyeRay;
}

class RasterPassTest : public ::testing::Test {
 protected:
  void SetUp() override {
    VulkanContextOptions options;
    options.validation = true;
    auto context = VulkanContext::Create(options);
    ASSERT_TRUE(context.ok()) << context.status().message();
    context_ = std::move(context).value();
    auto raster = MakeVulkanBackend(context_, BackendOptions{});
    ASSERT_TRUE(raster.ok()) << raster.status().message();
    raster_ = std::move(raster).value();
    auto compute = MakeVulkanBackend(context_, BackendOptions{});
    ASSERT_TRUE(compute.ok()) << compute.status().message();
    compute_ = std::move(compute).value();
  }

  void TearDown() override {
    if (context_ == nullptr) return;
    const std::shared_ptr<ValidationLog> log = context_->validation_log();
    raster_.reset();
    compute_.reset();
    context_.reset();
    for (const std::string& message : log->TakeMessages()) ADD_FAILURE() << message;
  }

  std::shared_ptr<VulkanContext> context_;
  std::unique_ptr<Backend> raster_;
  std::unique_ptr<Backend> compute_;
};

TEST_F(RasterPassTest, LavapipeHasEverythingTheRasterFormNeeds) {
  const RunLayout layout = MakeRunLayout(AllCells());
  const Status status = CheckRasterFeatures(context_->raster_features(), layout.cells, context_->properties().name);
  EXPECT_TRUE(status.ok()) << status.message();
}

// The compute form's positions on the texels the raster form stored must
// be the raster form's, up to what the two forms do differently: nothing
// but where the rays come from.
TEST_F(RasterPassTest, AgreesWithTheComputeFormOnTheSameTexels) {
  const RunLayout layout = RepresentativeLayout();
  const std::vector<std::uint32_t> which = AllIndices(layout);
  Status status = raster_->Prepare(layout.cells, PassKind::kRaster);
  ASSERT_TRUE(status.ok()) << status.message();
  status = compute_->Prepare(layout.cells, PassKind::kCompute);
  ASSERT_TRUE(status.ok()) << status.message();

  // Starts and ends inside a frame, and inside an atlas row.
  Batch batch = BuildBatch(layout, 4101, 1000);
  std::vector<float> scratch;
  auto drawn = raster_->Run(batch, which, scratch);
  ASSERT_TRUE(drawn.ok()) << drawn.status().message();
  const std::vector<float> raster(drawn->begin(), drawn->end());

  // The compute form, given what the device stored. A device converts a
  // unorm texel to float with a tolerance (lavapipe multiplies by a rounded
  // reciprocal, measured up to 2 ulps from the correctly rounded quotient
  // the host's FetchTexel gives), so for the unorm formats the compute form
  // also runs on the neighbours of that value, up to kDecodeUlps away; a
  // raster position is compared with the nearest of them.
  constexpr int kDecodeUlps = 2;
  const std::vector<std::uint32_t> texels = RasterTexels(*raster_);
  ASSERT_EQ(texels.size(), batch.codes.size());
  std::vector<std::vector<float>> computed;
  for (int shift = -kDecodeUlps; shift <= kDecodeUlps; ++shift) {
    for (std::size_t slot = 0; slot < layout.encodings.size(); ++slot) {
      const Format format = layout.encodings[slot].format;
      for (std::uint32_t i = 0; i < batch.count; ++i) {
        const std::size_t at = slot * batch.count + i;
        batch.codes[at] = texels[at];
        float depth = FetchTexel(format, texels[at]);
        for (int step = 0; Info(format).texel == TexelKind::kUnorm && step < std::abs(shift); ++step) {
          depth = std::nextafter(depth, shift < 0 ? -1.0f : 2.0f);
        }
        batch.depths[at] = depth;
      }
    }
    auto positions = compute_->Run(batch, which, scratch);
    ASSERT_TRUE(positions.ok()) << positions.status().message();
    computed.emplace_back(positions->begin(), positions->end());
  }

  std::size_t with_geometry = 0;
  for (std::uint32_t i = 0; i < batch.count; ++i) with_geometry += HasGeometry(batch.raster[i]) ? 1 : 0;
  ASSERT_GT(with_geometry, batch.count / 2) << "too few samples with geometry to compare";

  for (std::size_t k = 0; k < which.size(); ++k) {
    const Cell& cell = layout.cells[which[k]].cell;
    // Non-ray variants run the same float32 arithmetic on the same inputs
    // (the stored value among those the compute form ran on): the same
    // bits. Ray variants take their rays from the rasterizer's
    // interpolation instead of origin + du*u + dv*v: the ray differs by a
    // few roundings of its largest term (lavapipe evaluates a plane
    // equation from the vertices at the corners of a 2x2-screen triangle,
    // whose values are up to 3 times the ray at the pixel), then scaled by
    // the depth; volume_ray also divides by the interpolated surface z.
    // 64 units of 2^-24 |p| allows 16 such roundings of a term 4 times |p|.
    const double units = RayVariant(cell.variant) ? 64.0 : 0.0;
    double worst = 0.0;
    std::size_t finite = 0, compared = 0;
    for (std::uint32_t i = 0; i < batch.count; ++i) {
      if (!HasGeometry(batch.raster[i])) continue;
      const std::size_t n = batch.count;
      const float* r = raster.data() + k * 3 * n + i;
      const double got[3] = {r[0], r[n], r[2 * n]};
      const bool got_finite = std::isfinite(got[0]) && std::isfinite(got[1]) && std::isfinite(got[2]);
      // The compute form's position nearest the raster form's.
      double want[3] = {0, 0, 0};
      double error = INFINITY;
      bool want_finite = false;
      for (std::size_t run = 0; run < computed.size(); ++run) {
        const float* c = computed[run].data() + k * 3 * n + i;
        const double candidate[3] = {c[0], c[n], c[2 * n]};
        const double distance = std::hypot(got[0] - candidate[0], got[1] - candidate[1], got[2] - candidate[2]);
        if (run == 0 || std::isnan(error) || distance < error) {
          error = distance;
          std::copy(candidate, candidate + 3, want);
        }
        want_finite |= std::isfinite(candidate[0]) && std::isfinite(candidate[1]) && std::isfinite(candidate[2]);
      }
      ASSERT_EQ(got_finite, want_finite) << cell.Name() << " sample " << i << ": raster (" << got[0] << ", "
                                         << got[1] << ", " << got[2] << ") compute (" << want[0] << ", " << want[1]
                                         << ", " << want[2] << ")";
      if (!want_finite) continue;
      ++finite;
      // The camera sits at the origin: the position is its distance.
      const double distance = std::hypot(want[0], want[1], want[2]);
      worst = std::max(worst, error / std::ldexp(distance, -24));
      ASSERT_LE(error, units * std::ldexp(distance, -24))
          << cell.Name() << " sample " << i << ": raster (" << got[0] << ", " << got[1] << ", " << got[2]
          << ") compute (" << want[0] << ", " << want[1] << ", " << want[2] << ")";
      ++compared;
    }
    // Positions are infinite only where a stored value denotes infinity
    // (an infinite far plane's, rounded there): a few samples, no more.
    EXPECT_GE(finite, with_geometry * 95 / 100) << cell.Name();
    RecordProperty(cell.Name(), std::to_string(worst));
    EXPECT_GT(compared, 0u) << cell.Name();
  }
  EXPECT_TRUE(context_->TakeValidationMessages().empty());
}

// The texels the device stored, against the batch's codes: the accounting
// per depth slot.
TEST_F(RasterPassTest, CountsAgreementPerDepthSlot) {
  const RunLayout layout = RepresentativeLayout();
  const std::vector<std::uint32_t> which = AllIndices(layout);
  Status status = raster_->Prepare(layout.cells, PassKind::kRaster);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(raster_->raster_agreement().size(), layout.encodings.size());
  std::vector<RasterAgreement> expected(layout.encodings.size());
  for (const auto& [first, count] : {std::pair<std::uint64_t, std::uint32_t>{0, 700}, {9000, 1500}}) {
    const Batch batch = BuildBatch(layout, first, count);
    std::vector<float> scratch;
    auto drawn = raster_->Run(batch, which, scratch);
    ASSERT_TRUE(drawn.ok()) << drawn.status().message();
    const std::vector<std::uint32_t> texels = RasterTexels(*raster_);
    for (std::size_t slot = 0; slot < expected.size(); ++slot) {
      for (std::uint32_t i = 0; i < count; ++i) {
        if (!HasGeometry(batch.raster[i])) continue;
        const std::uint32_t device = texels[slot * count + i], host = batch.codes[slot * count + i];
        ++expected[slot].texels;
        expected[slot].differing += device != host ? 1 : 0;
        expected[slot].max_code_distance =
            std::max(expected[slot].max_code_distance, device > host ? device - host : host - device);
      }
    }
  }
  const std::vector<RasterAgreement> agreement = raster_->raster_agreement();
  ASSERT_EQ(agreement.size(), expected.size());
  for (std::size_t slot = 0; slot < expected.size(); ++slot) {
    const std::string name = std::string(Info(layout.encodings[slot].convention).name) + "/" +
                             std::string(Info(layout.encodings[slot].format).name);
    EXPECT_EQ(agreement[slot].texels, expected[slot].texels) << name;
    EXPECT_EQ(agreement[slot].differing, expected[slot].differing) << name;
    EXPECT_EQ(agreement[slot].max_code_distance, expected[slot].max_code_distance) << name;
    // Every test triangle covers its pixel's centre by two pixels or more.
    EXPECT_EQ(agreement[slot].uncovered, 0u) << name;
    RecordProperty(name, fmt::format("{} of {} texels equal the batch's code, largest distance {}",
                                     agreement[slot].texels - agreement[slot].differing, agreement[slot].texels,
                                     agreement[slot].max_code_distance));
  }
  EXPECT_TRUE(context_->TakeValidationMessages().empty());
}

TEST_F(RasterPassTest, ABatchWithoutGeometryIsRefused) {
  const RunLayout layout = RepresentativeLayout();
  ASSERT_TRUE(raster_->Prepare(layout.cells, PassKind::kRaster).ok());
  Batch batch = BuildBatch(layout, 0, 100);
  batch.raster.clear();
  std::vector<float> scratch;
  auto result = raster_->Run(batch, AllIndices(layout), scratch);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(result.status().message().find("--pipeline raster"), std::string::npos) << result.status().message();
}

// A device without what the raster form needs is refused at Prepare, with
// what it lacks; the GL-style conventions and volume_ray need more than
// the rest.
TEST(RasterFeaturesTest, NamesWhatTheDeviceLacks) {
  RasterFeatures all{true, true, true, true, true, true, true};
  const RunLayout everything = MakeRunLayout(AllCells());
  EXPECT_TRUE(CheckRasterFeatures(all, everything.cells, "Test GPU").ok());

  RasterFeatures no_clip_control = all;
  no_clip_control.depth_clip_control = false;
  const Status gl = CheckRasterFeatures(no_clip_control, everything.cells, "Test GPU");
  EXPECT_EQ(gl.code(), StatusCode::kUnavailable);
  EXPECT_NE(gl.message().find("Vulkan device 'Test GPU'"), std::string::npos) << gl.message();
  EXPECT_NE(gl.message().find("VK_EXT_depth_clip_control"), std::string::npos) << gl.message();
  EXPECT_NE(gl.message().find("standard-gl, reversed-gl, standard-inf-gl, reversed-inf-gl"), std::string::npos)
      << gl.message();
  // Without GL-style cells, the extension is not needed.
  CellFilter clip_zero_to_one;
  clip_zero_to_one.conventions = {Convention::kStandard, Convention::kReversed, Convention::kLinear};
  std::vector<Cell> cells;
  for (const Cell& cell : AllCells()) {
    if (clip_zero_to_one.Keeps(cell)) cells.push_back(cell);
  }
  EXPECT_TRUE(CheckRasterFeatures(no_clip_control, MakeRunLayout(cells).cells, "Test GPU").ok());

  RasterFeatures old = all;
  old.dynamic_rendering = false;
  old.depth_clamp = false;
  const Status missing = CheckRasterFeatures(old, everything.cells, "Test GPU");
  EXPECT_NE(missing.message().find("dynamicRendering (Vulkan 1.3)"), std::string::npos) << missing.message();
  EXPECT_NE(missing.message().find("depthClamp"), std::string::npos) << missing.message();
}

}  // namespace
}  // namespace depthbench
