// The raster form of the Vulkan backend on lavapipe: it draws every
// sample's geometry, produces depth with the rasterizer and reconstructs in
// a fragment program; on the texels the device stored, it must agree with
// the compute form. Runs with the validation layer on and fails on anything
// it reports.
//
// The geometry is the host's (bench/pipeline/raster_model.h): per sample
// of an eye-depth pick, a camera-facing triangle around the pixel centre
// and a light-volume cube around the point; other samples draw nothing.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "bench/backends/vulkan/arithmetic_probe.h"
#include "bench/backends/vulkan/raster_pass.h"
#include "bench/backends/vulkan/vulkan_backend.h"
#include "bench/backends/vulkan/vulkan_context.h"
#include "bench/base/thread_pool.h"
#include "bench/pipeline/batch.h"
#include "bench/pipeline/encode.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/encode.h"
#include "bench/pipeline/sampler.h"
#include "bench/pipeline/user_variant.h"

namespace depthbench {
namespace {

constexpr std::uint64_t kSeed = 20251202;

// The camera at the origin, far/near 1e4 (and infinite far planes), depth
// produced by the raster pipeline.
Domain RasterDomain() {
  Domain domain;
  domain.camera_distance = {0.0, 0.0};
  domain.ratio = {1e4, 1e4};
  domain.production = ProductionModel::kRaster;
  return domain;
}

Batch BuildBatch(const RunLayout& layout, std::uint64_t first, std::uint32_t count) {
  const Sampler sampler(kSeed, RasterDomain());
  const BatchBuilder builder(sampler, layout.encodings);
  ThreadPool pool;
  Batch batch;
  builder.Build(first, count, batch, pool);
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
// but where the rays come from. With the compute-attributes probe the rays
// come from the compute form's formula too, and every bit agrees.
class AgreementTest : public RasterPassTest, public ::testing::WithParamInterface<std::uint32_t> {};

TEST_P(AgreementTest, AgreesWithTheComputeFormOnTheSameTexels) {
  const std::uint32_t probes = GetParam();
  BackendOptions options;
  options.arithmetic_probes = probes;
  auto probed = MakeVulkanBackend(context_, options);
  ASSERT_TRUE(probed.ok()) << probed.status().message();
  const RunLayout layout = RepresentativeLayout();
  const std::vector<std::uint32_t> which = AllIndices(layout);
  Status status = (*probed)->Prepare(layout.cells, PassKind::kRaster);
  ASSERT_TRUE(status.ok()) << status.message();
  status = compute_->Prepare(layout.cells, PassKind::kCompute);
  ASSERT_TRUE(status.ok()) << status.message();

  // Starts and ends inside a frame, and inside an atlas row.
  Batch batch = BuildBatch(layout, 4101, 1000);
  std::vector<float> scratch;
  auto drawn = (*probed)->Run(batch, which, scratch);
  ASSERT_TRUE(drawn.ok()) << drawn.status().message();
  const std::vector<float> raster(drawn->begin(), drawn->end());

  // The compute form, given what the device stored. A device converts a
  // unorm texel to float with a tolerance (lavapipe multiplies by a rounded
  // reciprocal, measured up to 2 ulps from the correctly rounded quotient
  // the host's FetchTexel gives), so for the unorm formats the compute form
  // also runs on the neighbours of that value, up to kDecodeUlps away; a
  // raster position is compared with the nearest of them.
  constexpr int kDecodeUlps = 2;
  const std::vector<std::uint32_t> texels = (*probed)->raster_texels();
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
    // With compute-attributes the rays are the compute form's: no units.
    const bool interpolated = RayVariant(cell.variant) && (probes & kComputeAttributes) == 0;
    const double units = interpolated ? 64.0 : 0.0;
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
  probed->reset();
}

INSTANTIATE_TEST_SUITE_P(Probes, AgreementTest, ::testing::Values(0u, std::uint32_t{kComputeAttributes}),
                         [](const ::testing::TestParamInfo<std::uint32_t>& info) {
                           return info.param == 0 ? std::string("Interpolated") : std::string("ComputeAttributes");
                         });

// The compute-attributes probe changes only the raster form; the compute
// form is refused it, with what to run instead.
TEST_F(RasterPassTest, TheComputeFormRefusesTheComputeAttributesProbe) {
  BackendOptions options;
  options.arithmetic_probes = kComputeAttributes;
  auto probed = MakeVulkanBackend(context_, options);
  ASSERT_TRUE(probed.ok()) << probed.status().message();
  EXPECT_EQ((*probed)->name(), "vulkan:compute-attributes");
  const Status status = (*probed)->Prepare(RepresentativeLayout().cells, PassKind::kCompute);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(status.message().find("--pipeline raster"), std::string::npos) << status.message();
  probed->reset();
}

// The texels the device stored, against the batch's codes (the host's model
// of a rasterizer): the accounting per depth slot, and how often they agree
// (recorded as test properties: ctest's XML output, --gtest_output).
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
    const std::vector<std::uint32_t> texels = raster_->raster_texels();
    for (std::size_t slot = 0; slot < expected.size(); ++slot) {
      for (std::uint32_t i = 0; i < count; ++i) {
        if (!HasGeometry(batch.raster[i])) continue;
        const std::uint32_t device = texels[slot * count + i], host = batch.codes[slot * count + i];
        ++expected[slot].texels;
        expected[slot].differing += device != host ? 1 : 0;
        expected[slot].max_code_distance =
            std::max(expected[slot].max_code_distance, CodeDistance(layout.encodings[slot].format, device, host));
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
    // The host's triangles keep the pixel centre 0.75 pixels inside every
    // edge (raster_model.h): none may be missed.
    EXPECT_EQ(agreement[slot].uncovered, 0u) << name;
    // A 16-bit code spans 2^8 float ulps (of values in [0.5, 1), more
    // below): a device interpolating a few ulps off the exact value (the
    // host's model) changes the code only for values that close to a
    // rounding midpoint, about 1% of them at 2 ulps. 98% leaves a margin.
    if (Info(layout.encodings[slot].format).bits == 16 &&
        Info(layout.encodings[slot].format).texel == TexelKind::kUnorm) {
      EXPECT_GE(agreement[slot].texels - agreement[slot].differing, agreement[slot].texels * 98 / 100) << name;
    }
    RecordProperty(name, fmt::format("{} of {} texels equal the batch's code, largest distance {}",
                                     agreement[slot].texels - agreement[slot].differing, agreement[slot].texels,
                                     agreement[slot].max_code_distance));
  }
  EXPECT_TRUE(context_->TakeValidationMessages().empty());
}

// volume_ray must read its light volume's back face, the face behind the
// point: a copy of the shaders whose raster pass writes the interpolated
// view-space surface position instead of the reconstruction shows where it
// lies. (The reconstruction itself cannot tell the faces apart: both lie on
// the pixel's ray.)
TEST_F(RasterPassTest, LightVolumesDrawTheirBackFaces) {
  const std::filesystem::path copy = std::filesystem::path(::testing::TempDir()) / "raster_pass_test_shaders";
  std::filesystem::remove_all(copy);
  std::filesystem::create_directories(copy);
  std::filesystem::copy(DEPTHBENCH_SOURCE_DIR "/shaders", copy / "shaders", std::filesystem::copy_options::recursive);
  std::filesystem::copy(DEPTHBENCH_SOURCE_DIR "/shared", copy / "shared", std::filesystem::copy_options::recursive);
  const std::filesystem::path pass = copy / "shaders" / "raster" / "reconstruct.inc";
  std::ifstream in(pass);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  const std::string call = "function(rasterized_frame(i, light_volume), depth, uv, stored)";
  ASSERT_NE(text.find(call), std::string::npos);
  text.replace(text.find(call), call.size(), "rasterized_frame(i, light_volume).volume_position_origin.xyz");
  std::ofstream(pass) << text;

  BackendOptions options;
  options.shader_dir = (copy / "shaders").string();
  auto backend = MakeVulkanBackend(context_, options);
  ASSERT_TRUE(backend.ok()) << backend.status().message();
  const RunLayout layout = MakeRunLayout(std::vector<Cell>{{Variant::kVolumeRay, Convention::kLinear, Format::kR32Sfloat}});
  Status status = (*backend)->Prepare(layout.cells, PassKind::kRaster);
  ASSERT_TRUE(status.ok()) << status.message();
  const Batch batch = BuildBatch(layout, 0, 500);
  std::vector<float> scratch;
  const std::vector<std::uint32_t> which = {0};
  auto surface = (*backend)->Run(batch, which, scratch);
  ASSERT_TRUE(surface.ok()) << surface.status().message();
  std::size_t behind = 0, drawn = 0;
  for (std::uint32_t i = 0; i < batch.count; ++i) {
    if (!HasGeometry(batch.raster[i])) continue;
    ++drawn;
    // The cube's back faces lie between 1 and 1.25 (along the axes) or
    // 1.75 (at a corner, at most) times the point's eye depth away.
    const double eye_depth = -(*surface)[2 * batch.count + i];
    behind += eye_depth > batch.samples.eye_depth[i] ? 1 : 0;
  }
  EXPECT_GT(drawn, batch.count / 2);
  EXPECT_EQ(behind, drawn);
  backend->reset();
  std::filesystem::remove_all(copy);
}

// The built-in cells of a depth slot reconstruct in one draw, each into
// the slice the run lists it at: a run of some cells, in another order,
// writes each one's positions where that run puts them, the same bits as
// in a run of every cell, and nothing else.
TEST_F(RasterPassTest, ARunOfSomeCellsWritesTheirSlicesAlone) {
  const RunLayout layout = RepresentativeLayout();
  ASSERT_TRUE(raster_->Prepare(layout.cells, PassKind::kRaster).ok());
  const Batch batch = BuildBatch(layout, 0, 500);
  const std::uint32_t count = batch.count;
  std::vector<float> scratch;
  const std::vector<std::uint32_t> every = AllIndices(layout);
  auto all = raster_->Run(batch, every, scratch);
  ASSERT_TRUE(all.ok()) << all.status().message();
  const std::vector<float> whole(all->begin(), all->end());
  // Every third cell, last first: slots keep some of their cells.
  std::vector<std::uint32_t> some;
  for (std::uint32_t index = 0; index < layout.cells.size(); index += 3) some.insert(some.begin(), index);
  ASSERT_GT(some.size(), 3u);
  auto part = raster_->Run(batch, some, scratch);
  ASSERT_TRUE(part.ok()) << part.status().message();
  ASSERT_EQ(part->size(), std::size_t{3} * some.size() * count);
  for (std::size_t k = 0; k < some.size(); ++k) {
    const std::size_t slice = std::size_t{3} * count;
    EXPECT_EQ(std::memcmp(part->data() + k * slice, whole.data() + some[k] * slice, slice * sizeof(float)), 0)
        << layout.cells[some[k]].cell.Name() << ", listed " << k << "th";
  }
  EXPECT_TRUE(context_->TakeValidationMessages().empty());
}

// Pass 2a draws each sample at its real pixel, through its frame's own
// viewport: what the rasterizer interpolates there depends on the frame
// and the pixel alone, not on where the sample lies in the batch or the
// atlas. Frames 1 to 7 of the batch are made copies of frame 0 (its
// constants, pixels and geometry), so that each sample of frame 0 has seven
// twins at other atlas texels; where a twin's depth texel is the same bits,
// its position must be too. Drawing pass 2a at the sample's atlas texel,
// as the raster form once did, gives lavapipe other roundings of the rays
// at other texels.
TEST_F(RasterPassTest, TheAttributesDependOnTheFrameAndPixelAlone) {
  const RunLayout layout = MakeRunLayout(std::vector<Cell>{{Variant::kFrustumRay, Convention::kLinear, Format::kR32Sfloat},
                                                           {Variant::kEyeRay, Convention::kLinear, Format::kR32SfloatViewZ},
                                                           {Variant::kVolumeRay, Convention::kLinear, Format::kR32Sfloat}});
  Status status = raster_->Prepare(layout.cells, PassKind::kRaster);
  ASSERT_TRUE(status.ok()) << status.message();
  constexpr std::uint32_t kFrames = 8;
  Batch batch = BuildBatch(layout, 0, kFrames * kSamplesPerFrame);
  const std::uint32_t count = batch.count;
  ASSERT_EQ(batch.frame_count(), kFrames);
  for (std::uint32_t f = 1; f < kFrames; ++f) {
    batch.frame_params[f] = batch.frame_params[0];
    std::copy_n(batch.depth_params.begin(), kHardwareConventionCount,
                batch.depth_params.begin() + f * kHardwareConventionCount);
    for (std::uint32_t j = 0; j < kSamplesPerFrame; ++j) {
      const std::uint32_t twin = f * kSamplesPerFrame + j;
      batch.pixels[twin] = batch.pixels[j];
      batch.raster[twin] = batch.raster[j];
      for (std::uint32_t slot = 0; slot < batch.depth_slots; ++slot) {
        batch.codes[slot * count + twin] = batch.codes[slot * count + j];
        batch.depths[slot * count + twin] = batch.depths[slot * count + j];
      }
    }
  }
  std::vector<float> scratch;
  const std::vector<std::uint32_t> which = AllIndices(layout);
  auto positions = raster_->Run(batch, which, scratch);
  ASSERT_TRUE(positions.ok()) << positions.status().message();
  const std::vector<std::uint32_t> texels = raster_->raster_texels();
  ASSERT_EQ(texels.size(), std::size_t{batch.depth_slots} * count);
  for (std::size_t k = 0; k < which.size(); ++k) {
    const std::uint32_t slot = layout.cells[which[k]].depth_slot;
    std::size_t compared = 0, differing = 0;
    for (std::uint32_t j = 0; j < kSamplesPerFrame; ++j) {
      if (!HasGeometry(batch.raster[j])) continue;
      for (std::uint32_t f = 1; f < kFrames; ++f) {
        const std::uint32_t twin = f * kSamplesPerFrame + j;
        if (texels[slot * count + twin] != texels[slot * count + j]) continue;
        ++compared;
        for (std::size_t c = 0; c < 3; ++c) {
          const float* component = positions->data() + (k * 3 + c) * count;
          differing += std::bit_cast<std::uint32_t>(component[twin]) != std::bit_cast<std::uint32_t>(component[j]);
        }
      }
    }
    const std::string name = layout.cells[which[k]].cell.Name();
    EXPECT_GT(compared, 200u) << name;
    EXPECT_EQ(differing, 0u) << name << ": twins on the same texel bits reconstruct differently";
  }
}

// A variant from the user's file, GLSL or HLSL, gets its raster program by
// the same mechanism as the built-in ones, and runs the compute form's
// arithmetic on the same stored depth: the same bits (d32_sfloat, so that
// the host reads exactly the device's value). The HLSL example is the
// inverse view-projection written as a Unity project writes it: its
// raster program is the HLSL pass, with the texture turned into the
// combined image sampler the host binds.
TEST_F(RasterPassTest, UserVariantsInBothLanguagesRunAsInTheComputeForm) {
  const std::filesystem::path examples = std::filesystem::path(DEPTHBENCH_SOURCE_DIR) / "bench" / "examples";
  for (const char* file : {"divide_subtract_first.glsl", "unity_world_position.hlsl"}) {
    SCOPED_TRACE(file);
    auto catalogue = MakeCatalogue({(examples / file).string()});
    ASSERT_TRUE(catalogue.ok()) << catalogue.status().message();
    const Variant user = (*catalogue)->variants().back().id;
    const RunLayout layout =
        MakeRunLayout(std::vector<Cell>{(*catalogue)->MakeCell(user, Convention::kStandard, Format::kD32Sfloat)});
    Status status = raster_->Prepare(layout.cells, PassKind::kRaster);
    ASSERT_TRUE(status.ok()) << status.message();
    ASSERT_TRUE(compute_->Prepare(layout.cells, PassKind::kCompute).ok());
    Batch batch = BuildBatch(layout, 640, 300);
    const std::vector<std::uint32_t> which = {0};
    std::vector<float> scratch;
    auto drawn = raster_->Run(batch, which, scratch);
    ASSERT_TRUE(drawn.ok()) << drawn.status().message();
    const std::vector<float> raster(drawn->begin(), drawn->end());
    const std::vector<std::uint32_t> texels = raster_->raster_texels();
    for (std::uint32_t i = 0; i < batch.count; ++i) batch.depths[i] = FetchTexel(Format::kD32Sfloat, texels[i]);
    auto computed = compute_->Run(batch, which, scratch);
    ASSERT_TRUE(computed.ok()) << computed.status().message();
    std::size_t compared = 0;
    for (std::uint32_t i = 0; i < batch.count; ++i) {
      if (!HasGeometry(batch.raster[i])) continue;
      for (std::uint32_t c = 0; c < 3; ++c) {
        const float got = raster[c * batch.count + i], want = (*computed)[c * batch.count + i];
        EXPECT_EQ(std::memcmp(&got, &want, sizeof(got)), 0) << "sample " << i << " component " << c << ": " << got
                                                            << " vs " << want;
      }
      ++compared;
    }
    EXPECT_GT(compared, batch.count / 2);
  }
}

// The arithmetic probes rewrite the raster form's programs too (its
// program hash says so), and the rewritten programs run: no-contraction
// changes no bit on lavapipe, which fuses nothing.
TEST_F(RasterPassTest, ArithmeticProbesApplyToTheRasterPrograms) {
  const RunLayout layout = RepresentativeLayout();
  const std::vector<std::uint32_t> which = AllIndices(layout);
  ASSERT_TRUE(raster_->Prepare(layout.cells, PassKind::kRaster).ok());
  BackendOptions options;
  options.arithmetic_probes = kNoContraction;
  auto probed = MakeVulkanBackend(context_, options);
  ASSERT_TRUE(probed.ok()) << probed.status().message();
  const Status status = (*probed)->Prepare(layout.cells, PassKind::kRaster);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ((*probed)->name(), "vulkan:no-contraction");
  EXPECT_NE((*probed)->program().hash, raster_->program().hash);
  EXPECT_NE((*probed)->program().hash.find("no-contraction"), std::string::npos);
  const Batch batch = BuildBatch(layout, 128, 400);
  std::vector<float> scratch, probed_scratch;
  auto plain = raster_->Run(batch, which, scratch);
  ASSERT_TRUE(plain.ok()) << plain.status().message();
  auto rewritten = (*probed)->Run(batch, which, probed_scratch);
  ASSERT_TRUE(rewritten.ok()) << rewritten.status().message();
  ASSERT_EQ(plain->size(), rewritten->size());
  EXPECT_EQ(std::memcmp(plain->data(), rewritten->data(), plain->size() * sizeof(float)), 0);
  probed->reset();
}

// The sweep's order: RenderDepths draws every depth slot (the sweep adopts
// the texels into the batch), then Run reconstructs from those atlases
// without drawing them again. The positions are those of a Run that draws
// both passes itself, and the texels those it stored.
TEST_F(RasterPassTest, RenderDepthsThenRunReadsTheRenderedAtlases) {
  const RunLayout layout = RepresentativeLayout();
  const std::vector<std::uint32_t> which = AllIndices(layout);
  ASSERT_TRUE(raster_->Prepare(layout.cells, PassKind::kRaster).ok());
  EXPECT_TRUE(raster_->renders_depths());
  EXPECT_FALSE(compute_->renders_depths());
  const Batch batch = BuildBatch(layout, 3000, 777);
  std::vector<float> scratch;
  auto alone = raster_->Run(batch, which, scratch);
  ASSERT_TRUE(alone.ok()) << alone.status().message();
  const std::vector<float> both_passes(alone->begin(), alone->end());
  const std::vector<std::uint32_t> texels = raster_->raster_texels();

  // Another batch in between, so that the atlases hold something else.
  ASSERT_TRUE(raster_->Run(BuildBatch(layout, 0, 300), which, scratch).ok());
  auto rendered = raster_->RenderDepths(batch);
  ASSERT_TRUE(rendered.ok()) << rendered.status().message();
  EXPECT_EQ(std::vector<std::uint32_t>(rendered->codes.begin(), rendered->codes.end()), texels);
  // What the device's texel fetch returns for each code: the float itself
  // for float formats; for unorm codes the device's conversion, within
  // 2 ulps of the correctly rounded one (lavapipe's is up to 2 off; the
  // Vulkan specification does not require correct rounding).
  ASSERT_EQ(rendered->fetched.size(), rendered->codes.size());
  for (std::size_t s = 0; s < layout.encodings.size(); ++s) {
    const Format format = layout.encodings[s].format;
    for (std::size_t i = 0; i < batch.count; ++i) {
      if (batch.raster[i].triangle0.w == 0.0f) continue;
      const std::size_t at = s * batch.count + i;
      const float exact = FetchTexel(format, rendered->codes[at]);
      const float device = rendered->fetched[at];
      if (Info(format).texel == TexelKind::kUnorm) {
        const float ulp = std::nextafter(exact, 2.0f) - exact;
        EXPECT_LE(std::fabs(device - exact), 2.0f * ulp)
            << Info(format).name << " code " << rendered->codes[at];
      } else {
        EXPECT_EQ(device, exact) << Info(format).name << " code " << rendered->codes[at];
      }
    }
  }
  auto after = raster_->Run(batch, which, scratch);
  ASSERT_TRUE(after.ok()) << after.status().message();
  ASSERT_EQ(after->size(), both_passes.size());
  EXPECT_EQ(std::memcmp(after->data(), both_passes.data(), both_passes.size() * sizeof(float)), 0);
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

// The raster form's float16 targets lose a bit more than the compute
// form's (13.99 against 12.99 bits p99.9 at f/n 1e4): the cause, measured.
// The G-buffer fragment writes the same float into the R32_SFLOAT and the
// R16_SFLOAT target of a sample, so the 32-bit texel is what the 16-bit
// one was converted from. Vulkan leaves that conversion's rounding to the
// device; lavapipe rounds toward zero in every texel, which doubles the
// largest rounding error of the nearest-even rounding the compute form's
// encoder uses: one bit.
TEST_F(RasterPassTest, LavapipeRoundsFloat16TargetsTowardZero) {
  const RunLayout layout = MakeRunLayout(std::vector<Cell>{{Variant::kTanAspect, Convention::kLinear, Format::kR32Sfloat},
                                                           {Variant::kTanAspect, Convention::kLinear, Format::kR16Sfloat}});
  ASSERT_EQ(layout.encodings.size(), 2u);
  ASSERT_TRUE(raster_->Prepare(layout.cells, PassKind::kRaster).ok());
  const Batch batch = BuildBatch(layout, 0, 4000);
  std::vector<float> scratch;
  ASSERT_TRUE(raster_->Run(batch, AllIndices(layout), scratch).ok());
  const std::vector<std::uint32_t> texels = raster_->raster_texels();
  std::size_t compared = 0, nearest_differs = 0;
  for (std::uint32_t i = 0; i < batch.count; ++i) {
    if (!HasGeometry(batch.raster[i])) continue;
    const float value = std::bit_cast<float>(texels[i]);  // slot 0: r32_sfloat
    const auto half = static_cast<std::uint16_t>(texels[batch.count + i]);
    ASSERT_TRUE(value > 0.0f && value <= 1.0f) << "sample " << i << ": linear depth " << value;
    const std::uint16_t nearest = FloatToHalf(value);
    // For a positive value, the code below the nearest one where that one
    // lies above the value.
    const std::uint16_t toward_zero = HalfToFloat(nearest) > value ? nearest - 1 : nearest;
    ASSERT_EQ(half, toward_zero) << "sample " << i << ": " << value << " stored as " << HalfToFloat(half);
    nearest_differs += half != nearest ? 1 : 0;
    ++compared;
  }
  ASSERT_GT(compared, batch.count / 2);
  // Rounding toward zero differs from nearest-even wherever the value lies
  // in the upper half of its step: about half of them; a third is a margin.
  EXPECT_GT(nearest_differs, compared / 3);
  RecordProperty("differs_from_nearest", fmt::format("{} of {}", nearest_differs, compared));
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
