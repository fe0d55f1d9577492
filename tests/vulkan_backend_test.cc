// The Vulkan backend on lavapipe against the CPU backend: the same formulas
// on the same float32 inputs give the same positions up to the evaluation
// order GLSL leaves to the driver (lavapipe sums the columns of a
// matrix-vector product in another order than GLM). Runs with the validation
// layer on and fails on anything it reports.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <numeric>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "bench/backends/cpu/cpu_backend.h"
#include "bench/backends/factory.h"
#include "bench/backends/vulkan/vulkan_backend.h"
#include "bench/backends/vulkan/vulkan_context.h"
#include "bench/base/thread_pool.h"
#include "bench/pipeline/batch.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/sampler.h"

namespace depthbench {
namespace {

constexpr std::uint64_t kSeed = 20240611;
// Lavapipe and the CPU backend run the same float32 formulas; they differ
// only where GLSL leaves the order of a sum open: lavapipe adds the four
// products of a matrix-vector product in another order than GLM (it fuses
// nothing: a*b+c rounds twice on both). Reassociating a sum of four terms,
// each at most |p| here (camera at the origin, far/near up to 1e3), moves
// the result by at most 3 roundings of the largest partial sum, and the
// variants chain two such products at most: 6 units of 2^-24 * |p|, and
// 8 with a margin. The largest difference seen is 3.9 units (inverse_vp).
constexpr double kToleranceUnits = 8.0;

// Well-conditioned frames: the camera at the origin (no large translation
// to cancel) and moderate far/near ratios.
Domain WellConditionedDomain() {
  Domain domain;
  domain.camera_distance = {0.0, 0.0};
  domain.ratio = {10.0, 1000.0};
  return domain;
}

Batch BuildBatch(const RunLayout& layout, std::uint64_t first, std::uint32_t count) {
  const Sampler sampler(kSeed, WellConditionedDomain());
  const BatchBuilder builder(sampler, layout.encodings);
  ThreadPool pool;
  Batch batch;
  builder.Build(first, count, batch, pool);
  return batch;
}

// Sets an environment variable for one scope; the Vulkan loader reads
// VK_ICD_FILENAMES and VK_LAYER_PATH whenever an instance is created.
class ScopedEnvironment {
 public:
  ScopedEnvironment(std::string name, const std::string& value) : name_(std::move(name)) {
    if (const char* previous = std::getenv(name_.c_str())) previous_ = previous;
    setenv(name_.c_str(), value.c_str(), 1);
  }
  ~ScopedEnvironment() {
    if (previous_) {
      setenv(name_.c_str(), previous_->c_str(), 1);
    } else {
      unsetenv(name_.c_str());
    }
  }
  ScopedEnvironment(const ScopedEnvironment&) = delete;
  ScopedEnvironment& operator=(const ScopedEnvironment&) = delete;

 private:
  std::string name_;
  std::optional<std::string> previous_;
};

std::vector<std::uint32_t> AllIndices(const RunLayout& layout) {
  std::vector<std::uint32_t> which(layout.cells.size());
  std::iota(which.begin(), which.end(), 0u);
  return which;
}

class VulkanBackendTest : public ::testing::Test {
 protected:
  void SetUp() override {
    VulkanContextOptions options;
    options.validation = true;
    auto context = VulkanContext::Create(options);
    ASSERT_TRUE(context.ok()) << context.status().message();
    context_ = std::move(context).value();
    auto backend = MakeVulkanBackend(context_, BackendOptions{});
    ASSERT_TRUE(backend.ok()) << backend.status().message();
    vulkan_ = std::move(backend).value();
    cpu_ = MakeCpuBackend();
  }

  void TearDown() override {
    if (context_ == nullptr) return;
    // Destroying the device reports every object the backend leaked.
    const std::shared_ptr<ValidationLog> log = context_->validation_log();
    vulkan_.reset();
    context_.reset();
    for (const std::string& message : log->TakeMessages()) ADD_FAILURE() << message;
  }

  void PrepareBoth(const RunLayout& layout) {
    Status status = vulkan_->Prepare(layout.cells);
    ASSERT_TRUE(status.ok()) << status.message();
    ASSERT_TRUE(cpu_->Prepare(layout.cells).ok());
  }

  // Runs `which` on both backends and compares every finite CPU position.
  void ExpectBackendsAgree(const RunLayout& layout, const Batch& batch, const std::vector<std::uint32_t>& which) {
    std::vector<float> cpu_scratch;
    std::vector<float> vulkan_scratch;
    auto expected = cpu_->Run(batch, which, cpu_scratch);
    ASSERT_TRUE(expected.ok()) << expected.status().message();
    auto actual = vulkan_->Run(batch, which, vulkan_scratch);
    ASSERT_TRUE(actual.ok()) << actual.status().message();
    ASSERT_EQ(actual->size(), expected->size());

    std::size_t compared = 0;
    for (std::size_t k = 0; k < which.size(); ++k) {
      const Cell& cell = layout.cells[which[k]].cell;
      for (std::uint32_t i = 0; i < batch.count; ++i) {
        // Outputs are stored component by component.
        const std::size_t stride = batch.count;
        const float* w = expected->data() + k * stride * 3 + i;
        const float* g = actual->data() + k * stride * 3 + i;
        const double want[3] = {w[0], w[stride], w[2 * stride]};
        const double got[3] = {g[0], g[stride], g[2 * stride]};
        if (!std::isfinite(want[0]) || !std::isfinite(want[1]) || !std::isfinite(want[2])) continue;
        // The camera sits at the origin: the position is its distance.
        const double distance = std::hypot(want[0], want[1], want[2]);
        const double error = std::hypot(got[0] - want[0], got[1] - want[1], got[2] - want[2]);
        ASSERT_LE(error, kToleranceUnits * std::ldexp(distance, -24))
            << cell.Name() << " sample " << i << ": cpu (" << want[0] << ", " << want[1] << ", " << want[2]
            << ") vulkan (" << got[0] << ", " << got[1] << ", " << got[2] << ")";
        ++compared;
      }
    }
    EXPECT_GT(compared, which.size() * batch.count / 2) << "too few finite positions to compare";
  }

  std::shared_ptr<VulkanContext> context_;
  std::unique_ptr<Backend> vulkan_;
  std::unique_ptr<Backend> cpu_;
};

TEST_F(VulkanBackendTest, DescribesLavapipe) {
  const DeviceInfo& device = vulkan_->device();
  EXPECT_EQ(vulkan_->name(), "vulkan");
  EXPECT_FALSE(vulkan_->concurrent());
  EXPECT_NE(device.name.find("llvmpipe"), std::string::npos) << device.name;
  EXPECT_EQ(device.kind, DeviceKind::kCpu);
  EXPECT_EQ(device.api.rfind("Vulkan 1.", 0), 0u) << device.api;
  EXPECT_EQ(device.compiler.rfind("glslang ", 0), 0u) << device.compiler;
  EXPECT_NE(device.driver.find("Mesa"), std::string::npos) << device.driver;
  EXPECT_TRUE(context_->validation_enabled());
}

// The checks for an empty validation log mean something only if misuse
// does get recorded.
TEST_F(VulkanBackendTest, ValidationLayerRecordsMisuse) {
  const std::uint64_t errors_before = context_->validation_log()->error_count();
  VkBufferCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  info.size = 16;
  info.usage = 0;  // invalid: at least one usage bit is required
  VkBuffer buffer = VK_NULL_HANDLE;
  if (vkCreateBuffer(context_->device(), &info, nullptr, &buffer) == VK_SUCCESS) {
    vkDestroyBuffer(context_->device(), buffer, nullptr);
  }
  EXPECT_GT(context_->validation_log()->error_count(), errors_before);
  const std::vector<std::string> messages = context_->TakeValidationMessages();
  ASSERT_FALSE(messages.empty());
  EXPECT_NE(messages.front().find("VUID-VkBufferCreateInfo-usage-requiredbitmask"), std::string::npos)
      << messages.front();
}

TEST_F(VulkanBackendTest, AllCellsMatchCpuBackend) {
  const RunLayout layout = MakeRunLayout(AllCells());
  PrepareBoth(layout);
  // A batch that starts and ends inside a frame and is not a whole number
  // of workgroups.
  const Batch batch = BuildBatch(layout, 4101, 1000);
  ExpectBackendsAgree(layout, batch, AllIndices(layout));
  EXPECT_TRUE(context_->TakeValidationMessages().empty());
}

// The GPU's pass shape (one sample per invocation, 64 per workgroup) is
// never run by CI otherwise: on lavapipe it must give exactly the positions
// of the CPU-device shape (eight samples per invocation), and a shape that
// does not divide a frame is refused. Same arithmetic per sample, so any
// difference is an indexing error.
TEST_F(VulkanBackendTest, EveryPassShapeGivesTheSamePositions) {
  const RunLayout layout = MakeRunLayout(AllCells());
  const std::vector<std::uint32_t> which = AllIndices(layout);
  // Both batches start and end inside a frame. The first (18 frames)
  // leaves the last workgroup part empty at 8 frames per workgroup, the
  // second (16 frames) at 3. The first starts one sample past a quad, so
  // the quad shapes (4, 8 or 64 samples per invocation) run it with a lead
  // and padding and gather the positions; the second is quad-aligned and
  // comes back as the device wrote it.
  const std::vector<Batch> batches = {BuildBatch(layout, 4101, 1100), BuildBatch(layout, 4104, 1000)};
  // (samples per invocation, frames per workgroup): a GPU's shape first,
  // lavapipe's default among the others.
  const std::vector<std::pair<std::uint32_t, std::uint32_t>> shapes = {{1, 1}, {4, 8}, {8, 8}, {64, 8}, {8, 1}, {8, 3}};
  std::vector<std::vector<std::vector<float>>> outputs(batches.size());  // [batch][shape]
  for (const auto& [per_invocation, frames] : shapes) {
    BackendOptions options;
    options.samples_per_invocation = per_invocation;
    options.frames_per_workgroup = frames;
    auto backend = MakeVulkanBackend(context_, options);
    ASSERT_TRUE(backend.ok()) << backend.status().message();
    Status status = (*backend)->Prepare(layout.cells);
    ASSERT_TRUE(status.ok()) << status.message();
    for (std::size_t b = 0; b < batches.size(); ++b) {
      std::vector<float> scratch;
      auto out = (*backend)->Run(batches[b], which, scratch);
      ASSERT_TRUE(out.ok()) << out.status().message();
      outputs[b].emplace_back(out->begin(), out->end());
    }
  }
  for (std::size_t b = 0; b < batches.size(); ++b) {
    for (std::size_t k = 1; k < shapes.size(); ++k) {
      ASSERT_EQ(outputs[b][k].size(), outputs[b][0].size());
      // Bitwise, so that NaN outputs compare too.
      EXPECT_EQ(std::memcmp(outputs[b][k].data(), outputs[b][0].data(), outputs[b][0].size() * sizeof(float)), 0)
          << "batch " << b << ", " << shapes[k].first << " samples per invocation, " << shapes[k].second
          << " frames per workgroup";
    }
  }
  BackendOptions bad;
  bad.samples_per_invocation = 3;
  auto backend = MakeVulkanBackend(context_, bad);
  ASSERT_TRUE(backend.ok());
  const Status status = (*backend)->Prepare(layout.cells);
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("do not divide"), std::string::npos) << status.message();
  EXPECT_TRUE(context_->TakeValidationMessages().empty());
}

TEST_F(VulkanBackendTest, SubsetsInAnyOrderAndGrowingBatches) {
  const RunLayout layout = MakeRunLayout(AllCells());
  PrepareBoth(layout);
  const std::uint32_t last = static_cast<std::uint32_t>(layout.cells.size() - 1);
  ExpectBackendsAgree(layout, BuildBatch(layout, 0, 100), {last, 0, 17});
  // Larger buffers than the first run needed: the backend reallocates.
  ExpectBackendsAgree(layout, BuildBatch(layout, 64, 3000), {3, last, 40, 3});
  EXPECT_TRUE(context_->TakeValidationMessages().empty());
}

TEST_F(VulkanBackendTest, EmptyRunsReturnNothing) {
  const RunLayout layout = MakeRunLayout(AllCells());
  PrepareBoth(layout);
  std::vector<float> scratch;
  const Batch empty = BuildBatch(layout, 0, 0);
  auto none = vulkan_->Run(empty, AllIndices(layout), scratch);
  ASSERT_TRUE(none.ok()) << none.status().message();
  EXPECT_TRUE(none->empty());
  auto no_cells = vulkan_->Run(BuildBatch(layout, 0, 10), {}, scratch);
  ASSERT_TRUE(no_cells.ok()) << no_cells.status().message();
  EXPECT_TRUE(no_cells->empty());
}

// Runs that leave their positions on the device are the Vulkan backend's
// capability, and come in steps a judge on the device sequences:
// QueueStaged queues what Stage staged, once; a Run in between discards
// it; the raster form stages nothing.
TEST_F(VulkanBackendTest, DeviceResidentRunsAreStagedThenQueuedOnce) {
  EXPECT_EQ(cpu_->device_resident(), nullptr);
  DeviceResidentRuns* runs = vulkan_->device_resident();
  ASSERT_NE(runs, nullptr);
  EXPECT_EQ(runs->context(), context_);
  const RunLayout layout =
      MakeRunLayout(std::vector<Cell>{{Variant::kInverseVp, Convention::kStandard, Format::kD32Sfloat},
                                      {Variant::kPq, Convention::kReversed, Format::kD16Unorm}});
  ASSERT_TRUE(vulkan_->Prepare(layout.cells, PassKind::kCompute).ok());
  const std::vector<std::uint32_t> which = AllIndices(layout);
  const Batch batch = BuildBatch(layout, 4101, 1000);
  EXPECT_EQ(runs->QueueStaged().code(), StatusCode::kInternal);  // nothing staged yet

  auto staged = runs->Stage(batch, which, nullptr);
  ASSERT_TRUE(staged.ok()) << staged.status().message();
  EXPECT_NE(staged->positions, VK_NULL_HANDLE);
  EXPECT_NE(staged->texels, VK_NULL_HANDLE);
  EXPECT_GE(staged->slice_length, staged->lead + batch.count);
  EXPECT_EQ(staged->position_bytes, 3 * which.size() * staged->slice_length * sizeof(float));
  EXPECT_EQ(staged->texel_bytes, layout.encodings.size() * staged->slice_length * sizeof(float));
  const Status queued = runs->QueueStaged();
  ASSERT_TRUE(queued.ok()) << queued.message();
  EXPECT_EQ(runs->QueueStaged().code(), StatusCode::kInternal);  // queued already

  ASSERT_TRUE(runs->Stage(batch, which, nullptr).ok());
  std::vector<float> scratch;
  ASSERT_TRUE(vulkan_->Run(batch, which, scratch).ok());
  EXPECT_EQ(runs->QueueStaged().code(), StatusCode::kInternal);

  // The raster form stages a run too, but only of a batch with geometry to draw.
  ASSERT_TRUE(vulkan_->Prepare(layout.cells, PassKind::kRaster).ok());
  EXPECT_EQ(runs->Stage(batch, which, nullptr).status().code(), StatusCode::kInvalidArgument);
  EXPECT_TRUE(context_->TakeValidationMessages().empty());
}

TEST_F(VulkanBackendTest, CellIndexOutOfRangeIsInvalidArgument) {
  const RunLayout layout = MakeRunLayout(AllCells());
  PrepareBoth(layout);
  std::vector<float> scratch;
  const std::vector<std::uint32_t> which = {static_cast<std::uint32_t>(layout.cells.size())};
  auto result = vulkan_->Run(BuildBatch(layout, 0, 10), which, scratch);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument);
}

TEST_F(VulkanBackendTest, MissingShaderDirectoryIsNotFound) {
  BackendOptions options;
  options.shader_dir = "/nonexistent/depthbench/shaders";
  auto backend = MakeVulkanBackend(context_, options);
  ASSERT_TRUE(backend.ok()) << backend.status().message();
  const RunLayout layout = MakeRunLayout(AllCells());
  Status status = (*backend)->Prepare(layout.cells);
  EXPECT_EQ(status.code(), StatusCode::kNotFound);
  EXPECT_NE(status.message().find("shader directory '/nonexistent/depthbench/shaders' does not exist"),
            std::string::npos)
      << status.message();
}

TEST_F(VulkanBackendTest, UnknownDeviceIsNotFoundAndListsDevices) {
  VulkanContextOptions options;
  options.device = "no-such-gpu";
  auto context = VulkanContext::Create(options);
  ASSERT_FALSE(context.ok());
  EXPECT_EQ(context.status().code(), StatusCode::kNotFound);
  EXPECT_NE(context.status().message().find("no Vulkan device matches 'no-such-gpu'; available: "), std::string::npos)
      << context.status().message();
  EXPECT_NE(context.status().message().find("llvmpipe"), std::string::npos) << context.status().message();
}

TEST_F(VulkanBackendTest, NoDriverIsUnavailableWithHint) {
  const ScopedEnvironment no_driver("VK_ICD_FILENAMES", "/nonexistent/depthbench_icd.json");
  auto context = VulkanContext::Create(VulkanContextOptions{});
  ASSERT_FALSE(context.ok());
  EXPECT_EQ(context.status().code(), StatusCode::kUnavailable);
  EXPECT_NE(context.status().message().find("mesa-vulkan-drivers"), std::string::npos) << context.status().message();
  EXPECT_NE(context.status().message().find("VK_ICD_FILENAMES"), std::string::npos) << context.status().message();
}

TEST_F(VulkanBackendTest, MissingValidationLayerNamesThePackage) {
  const ScopedEnvironment no_layers("VK_LAYER_PATH", "/nonexistent/depthbench_layers");
  VulkanContextOptions options;
  options.validation = true;
  auto context = VulkanContext::Create(options);
  ASSERT_FALSE(context.ok());
  EXPECT_EQ(context.status().code(), StatusCode::kUnavailable);
  EXPECT_NE(context.status().message().find("vulkan-validationlayers"), std::string::npos)
      << context.status().message();
}

TEST_F(VulkanBackendTest, DeviceNamesMatchIgnoringCase) {
  VulkanContextOptions options;
  options.device = "LLVMPIPE";
  auto context = VulkanContext::Create(options);
  ASSERT_TRUE(context.ok()) << context.status().message();
  EXPECT_NE((*context)->properties().name.find("llvmpipe"), std::string::npos);
}

TEST_F(VulkanBackendTest, ListsLavapipe) {
  auto devices = ListVulkanDevices();
  ASSERT_TRUE(devices.ok()) << devices.status().message();
  ASSERT_FALSE(devices->empty());
  bool found = false;
  for (const VulkanDeviceSummary& device : *devices) {
    if (device.name.find("llvmpipe") == std::string::npos) continue;
    found = true;
    EXPECT_EQ(device.type, "cpu");
    EXPECT_FALSE(device.driver.empty());
    EXPECT_EQ(device.api.rfind("1.", 0), 0u) << device.api;
  }
  EXPECT_TRUE(found);
}

TEST_F(VulkanBackendTest, FactoryKnowsBothBackends) {
  auto cpu = MakeBackend("cpu", BackendOptions{});
  ASSERT_TRUE(cpu.ok());
  EXPECT_EQ((*cpu)->name(), "cpu");
  auto vulkan = MakeBackend("vulkan", BackendOptions{});
  ASSERT_TRUE(vulkan.ok()) << vulkan.status().message();
  EXPECT_EQ((*vulkan)->name(), "vulkan");
  auto unknown = MakeBackend("metal", BackendOptions{});
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(unknown.status().message().find("cpu, vulkan"), std::string::npos) << unknown.status().message();
}

}  // namespace
}  // namespace depthbench
