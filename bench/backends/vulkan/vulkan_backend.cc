#include "bench/backends/vulkan/vulkan_backend.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "bench/backends/vulkan/arithmetic_probe.h"
#include "bench/backends/vulkan/compute_pass.h"
#include "bench/backends/vulkan/raster_pass.h"
#include "bench/backends/vulkan/shader_compiler.h"
#include "bench/backends/vulkan/variant_program.h"
#include "bench/base/files.h"
#include "bench/base/resources.h"
#include "bench/numerics/formulas.h"

namespace depthbench {
namespace {

// shaders/compute_pass.glsl runs whole frames per workgroup: workgroup
// size (specialization constant 0) times samples per invocation (constant 1)
// is the samples per frame, and a workgroup takes `frames_per_workgroup`
// frames (constant 2) in turn. On a CPU device (lavapipe) an invocation
// loops over eight samples and reads its frame's constants once for them,
// and a workgroup takes eight frames: lavapipe calls the C allocator at
// the start of every workgroup (posix_memalign and malloc_consolidate,
// called from its JIT code, took about 5% of a run at one frame per
// workgroup). A GPU runs one sample per invocation and one frame per
// workgroup.
constexpr std::uint32_t kWorkgroupSizeConstant = 0;
constexpr std::uint32_t kSamplesPerInvocationConstant = 1;
constexpr std::uint32_t kFramesPerWorkgroupConstant = 2;
struct PassShape {
  std::uint32_t workgroup_size;
  std::uint32_t samples_per_invocation;
  std::uint32_t frames_per_workgroup;
};
constexpr std::uint32_t kCpuSamplesPerInvocation = 8;  // one SIMD group of lavapipe's 256-bit lanes per frame
constexpr std::uint32_t kCpuFramesPerWorkgroup = 8;
static_assert(kSamplesPerFrame % kCpuSamplesPerInvocation == 0);
// `options` may request either number (0: by device type).
Expected<PassShape> PassShapeFor(VkPhysicalDeviceType type, const BackendOptions& options) {
  const bool cpu = type == VK_PHYSICAL_DEVICE_TYPE_CPU;
  const std::uint32_t per_invocation = options.samples_per_invocation != 0 ? options.samples_per_invocation
                                       : cpu                               ? kCpuSamplesPerInvocation
                                                                           : 1;
  const std::uint32_t frames = options.frames_per_workgroup != 0 ? options.frames_per_workgroup
                               : cpu                             ? kCpuFramesPerWorkgroup
                                                                 : 1;
  if (kSamplesPerFrame % per_invocation != 0) {
    return InvalidArgument(fmt::format("{} samples per invocation do not divide the {} samples of a frame",
                                       per_invocation, kSamplesPerFrame));
  }
  return PassShape{kSamplesPerFrame / per_invocation, per_invocation, frames};
}

std::uint32_t WorkgroupsFor(const ShaderInputs& batch, const PassShape& shape) {
  return static_cast<std::uint32_t>((batch.frame_count() + shape.frames_per_workgroup - 1) /
                                    shape.frames_per_workgroup);
}

// Where a batch's samples lie in the per-sample slices (one per depth
// slot for the stored depths, one per cell and component for the
// positions). The quad form of the pass moves four consecutive samples
// of a frame at once, from an element that is a multiple of four: there
// the samples start `lead` elements into their slices, so that frame
// positions and elements agree modulo four, and the slices are padded to
// whole quads.
struct SliceLayout {
  std::uint32_t lead = 0;
  std::uint32_t length = 0;
  bool compact(const ShaderInputs& batch) const { return lead == 0 && length == batch.count; }
};
SliceLayout SliceLayoutFor(const ShaderInputs& batch, const PassShape& shape) {
  if (shape.samples_per_invocation % 4 != 0) return {0, batch.count};
  const std::uint32_t lead = batch.first_offset % 4;
  return {lead, (lead + batch.count + 3) / 4 * 4};
}

// The storage buffers of shaders/compute_pass.glsl, by binding number.
enum Binding : std::uint32_t {
  kFrames,
  kDepthParams,
  kPixels,
  kStoredDepths,
  kCellSlices,
  kPositions,  // the only output
  kBindingCount,
};
using BindingBytes = std::array<VkDeviceSize, kBindingCount>;

std::size_t DepthSlotsOf(const ShaderInputs& batch) { return batch.depth_slots; }

// Bytes each binding holds for a batch of `cells` cells.
BindingBytes BytesFor(const ShaderInputs& batch, const SliceLayout& slices, std::size_t cells) {
  return {batch.frame_params.size() * sizeof(f32::FrameParams),
          batch.depth_params.size() * sizeof(f32::DepthParams),
          std::size_t{slices.length} * sizeof(std::uint32_t),
          DepthSlotsOf(batch) * slices.length * sizeof(float),
          cells * sizeof(f32::CellSlice),
          cells * 3 * slices.length * sizeof(float)};
}

// The push constants of a run's dispatches, but first_cell: the CellSlice
// entry each dispatch's cells start at.
f32::PassConstants PassConstantsFor(const ShaderInputs& batch, const SliceLayout& slices) {
  return {.slice_length = slices.length,
          .samples_per_frame = kSamplesPerFrame,
          .conventions_per_frame = kHardwareConventionCount,
          .first_in_frame = batch.first_offset - slices.lead,
          .frame_count = static_cast<std::uint32_t>(batch.frame_count()),
          .first_cell = 0,
          .reserved0 = 0,
          .reserved1 = 0};
}

std::size_t VariantIndex(Variant variant) { return static_cast<std::size_t>(variant); }

// What the output buffer holds before each run, so that an output the
// shader never wrote (it returned early, or wrote elsewhere) is told apart
// from any result: a signalling NaN with a payload. Arithmetic only ever
// produces quiet NaNs, so no reconstruction can store these bits.
constexpr std::uint32_t kUnwrittenBits = 0x7fa0'0badu;

// The number of samples of the listed cell `k` with a component the
// shader left unwritten.
std::size_t UnwrittenSamples(const float* positions, const SliceLayout& slices, std::size_t k, std::size_t count) {
  std::size_t unwritten = 0;
  const auto* bits = reinterpret_cast<const std::uint32_t*>(positions) + k * 3 * slices.length + slices.lead;
  for (std::size_t i = 0; i < count; ++i) {
    const bool any = (bits[i] == kUnwrittenBits) | (bits[slices.length + i] == kUnwrittenBits) |
                     (bits[2 * slices.length + i] == kUnwrittenBits);
    unwritten += any ? 1 : 0;
  }
  return unwritten;
}

// A run's dispatches, one per variant among the listed cells, and the
// CellSlice entries they read: one dispatch's entries are consecutive. A
// cell writes the output slices of its place k in the list, whatever its
// dispatch.
struct DispatchPlan {
  struct Dispatch {
    Variant variant;
    std::uint32_t first_cell, cells;
  };
  std::vector<Dispatch> dispatches;
  std::vector<f32::CellSlice> cell_slices;
};
DispatchPlan PlanDispatches(std::span<const CellPlan> cells, std::span<const std::uint32_t> which,
                            const SliceLayout& slices) {
  DispatchPlan plan;
  for (std::size_t v = 0; v < kMostVariants; ++v) {
    const auto first = static_cast<std::uint32_t>(plan.cell_slices.size());
    for (std::size_t k = 0; k < which.size(); ++k) {
      const CellPlan& cell = cells[which[k]];
      if (VariantIndex(cell.cell.variant) != v) continue;
      plan.cell_slices.push_back({.convention_slot = cell.convention_slot,
                                  .depth_offset = cell.depth_slot * slices.length,
                                  .output_offset = static_cast<std::uint32_t>(k * slices.length * 3),
                                  .reserved = 0});
    }
    const auto count = static_cast<std::uint32_t>(plan.cell_slices.size()) - first;
    if (count > 0) plan.dispatches.push_back({static_cast<Variant>(v), first, count});
  }
  return plan;
}

// A run of the compute form whose inputs are uploaded and bound: what
// recording its dispatches needs.
struct StagedRun {
  SliceLayout slices;
  DispatchPlan plan;
  std::uint32_t workgroups = 0;
  f32::PassConstants constants{};
};

// FNV-1a (64 bits) of the sources' texts, each after its length, in the order
// compiled: it changes with any edit to a shader or a file it includes, and
// not with where the copy lies.
std::string SourcesHash(const std::vector<std::string>& sources) {
  std::uint64_t hash = 0xcbf29ce484222325u;
  const auto add = [&](std::string_view bytes) {
    for (const char c : bytes) hash = (hash ^ static_cast<unsigned char>(c)) * 0x100000001b3u;
  };
  for (const std::string& text : sources) {
    add(std::to_string(text.size()) + ":");
    add(text);
  }
  return fmt::format("fnv1a64:{:016x}", hash);
}

class VulkanBackend final : public Backend, public DeviceResidentRuns {
 public:
  static Expected<std::unique_ptr<Backend>> Create(std::shared_ptr<VulkanContext> context,
                                                   const BackendOptions& options);

  std::string name() const override {
    const std::string kind = BackendKindName(BackendKind::kVulkan);
    return options_.arithmetic_probes == 0 ? kind : kind + ":" + ArithmeticProbesName(options_.arithmetic_probes);
  }
  ~VulkanBackend() override {
    // Work QueueStaged left queued reads the buffers destroyed below.
    if (pass_ != nullptr) (void)pass_->Wait();
  }

  const DeviceInfo& device() const override { return device_; }
  ProgramInfo program() const override { return program_; }
  // One command buffer, one fence and one set of buffers: one Run at a time.
  bool concurrent() const override { return false; }

  Status Prepare(std::span<const CellPlan> cells, PassKind pass) override;
  Expected<std::span<const float>> Run(const ShaderInputs& batch, std::span<const std::uint32_t> which,
                                       std::vector<float>& scratch) override;
  std::uint64_t MaxBatchSamples() const override;
  bool renders_depths() const override { return raster_ != nullptr; }
  Expected<RenderedDepths> RenderDepths(const ShaderInputs& batch) override;
  std::vector<RasterAgreement> raster_agreement() const override {
    return raster_ != nullptr ? raster_->agreement() : std::vector<RasterAgreement>{};
  }
  std::vector<std::uint32_t> raster_texels() const override {
    return raster_ != nullptr ? raster_->texels() : std::vector<std::uint32_t>{};
  }
  DeviceResidentRuns* device_resident() override { return this; }

  const std::shared_ptr<VulkanContext>& context() const override { return context_; }
  Expected<DeviceRunBuffers> Stage(const ShaderInputs& batch, std::span<const std::uint32_t> which,
                                   ThreadPool* pool) override;
  Status QueueStaged() override;
  Status FinishQueued() override;
  std::vector<std::pair<std::string, double>> part_seconds() const override {
    return raster_ != nullptr ? raster_->part_seconds() : std::vector<std::pair<std::string, double>>{};
  }
  Expected<std::vector<std::uint32_t>> CompileJudged(const VariantInfo& variant) const override;

 private:
  VulkanBackend(std::shared_ptr<VulkanContext> context, std::filesystem::path shader_dir,
                const BackendOptions& options);

  std::string DeviceContext() const { return fmt::format("Vulkan device '{}'", device_.name); }

  Status PrepareOnDevice(std::span<const CellPlan> cells, PassKind pass);
  // `sources` collects the text of every source file compiled.
  Expected<DeviceObject<VkPipeline>> BuildPipeline(const VariantInfo& variant, const PassShape& shape,
                                                   std::vector<std::string>& sources) const;

  Expected<std::span<const float>> RunOnDevice(const ShaderInputs& batch, std::span<const std::uint32_t> which,
                                               std::vector<float>& scratch);
  // The compute form's upload, after waiting for the last run: the
  // positions go where positions_access_ says, laid out as the returned
  // run's slices say, once Record's commands run. `host_texels`: whether
  // the batch's texels (depths) go up too.
  Expected<StagedRun> StageCompute(const ShaderInputs& batch, std::span<const std::uint32_t> which, ThreadPool* pool,
                                   bool host_texels);
  // The buffers of a staged run of `cells` cells, for a judge on the device.
  DeviceRunBuffers BuffersOf(const ShaderInputs& batch, const SliceLayout& slices, std::size_t cells) const;
  // What either form would read out of bounds.
  // `host_texels`: whether the run reads the batch's texels (depths), or
  // the caller of Stage writes them on the device.
  Status CheckBatch(const ShaderInputs& batch, std::span<const std::uint32_t> which, bool host_texels = true) const;
  // Whether the raster form's device can bind the positions of `which`.
  Status CheckRasterOutputs(const ShaderInputs& batch, std::span<const std::uint32_t> which) const;
  Expected<DeviceRunBuffers> StageRaster(const ShaderInputs& batch, std::span<const std::uint32_t> which,
                                         ThreadPool* pool);
  // What the compute form's device cannot address or dispatch.
  Status CheckRun(const ShaderInputs& batch, std::span<const std::uint32_t> which, const BindingBytes& bytes) const;
  Status CheckEveryOutputWritten(const float* positions, const ShaderInputs& batch,
                                 std::span<const std::uint32_t> which, const SliceLayout& slices) const;
  Status EnsureCapacity(Binding binding, VkDeviceSize bytes);
  // `texels`: whether the batch's stored depths are uploaded too.
  Status Upload(const ShaderInputs& batch, const SliceLayout& slices, const BindingBytes& bytes,
                std::span<const f32::CellSlice> cell_slices, ThreadPool* pool, bool texels);
  void BindBuffers(const BindingBytes& bytes);
  void Record(VkCommandBuffer commands, const StagedRun& run) const;

  std::shared_ptr<VulkanContext> context_;  // first: everything below belongs to its device
  std::filesystem::path shader_dir_;
  BackendOptions options_;                   // the requested pass shape (PassShapeFor)
  PassShape shape_{kSamplesPerFrame, 1, 1};  // of the prepared pipelines
  DeviceInfo device_;
  ProgramInfo program_;  // of the prepared pipelines
  std::vector<CellPlan> cells_;

  std::unique_ptr<ComputePass> pass_;  // the storage buffers of compute_pass.glsl, PassConstants pushed
  // Indexed by Variant; null for variants no prepared cell uses.
  std::vector<DeviceObject<VkPipeline>> pipelines_;
  std::array<VulkanBuffer, kBindingCount> buffers_;
  std::unique_ptr<RasterPass> raster_;  // the raster form, when prepared for it
  // What Stage uploaded, for QueueStaged to queue.
  std::optional<StagedRun> staged_;
  bool raster_staged_ = false;  // Stage staged a raster run (RasterPass::StageResident)
  // Where the compute form's positions go: memory the host reads them from
  // (Run), or device memory alone, where a judge on the device reads them
  // (Stage); and the kind the buffer now is.
  HostAccess positions_access_ = HostAccess::kReadback;
  HostAccess positions_held_in_ = HostAccess::kReadback;
};

VulkanBackend::VulkanBackend(std::shared_ptr<VulkanContext> context, std::filesystem::path shader_dir,
                             const BackendOptions& options)
    : context_(std::move(context)),
      shader_dir_(std::move(shader_dir)),
      options_(options),
      device_(DeviceInfoOf(context_->properties())) {}

Expected<std::unique_ptr<Backend>> VulkanBackend::Create(std::shared_ptr<VulkanContext> context,
                                                         const BackendOptions& options) {
  if (context == nullptr) return InvalidArgument("the Vulkan backend needs a Vulkan context");
  std::filesystem::path shader_dir = options.shader_dir;
  if (shader_dir.empty()) DB_RETURN_IF_ERROR(StoreInto(DataPath("shaders"), shader_dir));
  if ((options.arithmetic_probes & kExactDivision) != 0 && !context->shader_float64()) {
    return Unavailable(fmt::format("the exact-division probe divides in float64, which Vulkan device '{}' lacks",
                                   context->properties().name));
  }
  std::unique_ptr<VulkanBackend> backend(new VulkanBackend(std::move(context), std::move(shader_dir), options));
  const ValidationScope validation(*backend->context_);
  std::array<VkDescriptorSetLayoutBinding, kBindingCount> bindings{};
  for (std::uint32_t i = 0; i < kBindingCount; ++i) {
    bindings[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  }
  Status status =
      StoreInto(ComputePass::Create(backend->context_, bindings, sizeof(f32::PassConstants)), backend->pass_);
  if (status.ok()) status = validation.Check("backend creation");
  if (!status.ok()) return status.WithContext(backend->DeviceContext());
  return std::unique_ptr<Backend>(std::move(backend));
}

Status VulkanBackend::Prepare(std::span<const CellPlan> cells, PassKind pass) {
  const ValidationScope validation(*context_);
  Status status = PrepareOnDevice(cells, pass);
  if (status.ok()) status = validation.Check("Prepare");
  return status.WithContext(DeviceContext());
}

Status VulkanBackend::PrepareOnDevice(std::span<const CellPlan> cells, PassKind pass) {
  DB_RETURN_IF_ERROR(CheckDirectory(shader_dir_, "shader directory"));
  // Built aside so that a failure leaves the previous preparation intact.
  DB_ASSIGN_OR_RETURN(const PassShape shape, PassShapeFor(context_->properties().type, options_));
  std::vector<DeviceObject<VkPipeline>> pipelines(kMostVariants);
  std::vector<std::string> sources;
  std::unique_ptr<RasterPass> raster;
  if (pass == PassKind::kRaster) {
    DB_ASSIGN_OR_RETURN(raster, RasterPass::Create(context_, cells, shader_dir_, options_.arithmetic_probes, sources));
  } else if ((options_.arithmetic_probes & kComputeAttributes) != 0) {
    return InvalidArgument(
        "the compute-attributes probe replaces what the raster form's rasterizer interpolates; the compute form "
        "computes those attributes already (run it with --pipeline raster)");
  } else {
    for (const CellPlan& plan : cells) {
      DeviceObject<VkPipeline>& pipeline = pipelines[VariantIndex(plan.cell.variant)];
      if (pipeline.get() != VK_NULL_HANDLE) continue;
      DB_ASSIGN_OR_RETURN(pipeline, BuildPipeline(plan.cell.variant_info(), shape, sources));
    }
  }
  pipelines_ = std::move(pipelines);
  raster_ = std::move(raster);
  staged_.reset();  // its dispatches would bind the replaced pipelines
  raster_staged_ = false;
  // The probes change the program as much as an edit would.
  const std::string probes = ArithmeticProbesName(options_.arithmetic_probes);
  program_ = {options_.shader_dir.empty() ? "default" : options_.shader_dir,
              SourcesHash(sources) + (probes.empty() ? "" : " " + probes)};
  shape_ = shape;
  cells_.assign(cells.begin(), cells.end());
  return Status::Ok();
}

std::uint64_t VulkanBackend::MaxBatchSamples() const {
  const VkPhysicalDeviceLimits& limits = context_->properties().limits;
  if (raster_ != nullptr) {
    // The positions of every cell, in one storage buffer.
    const std::uint64_t positions =
        limits.maxStorageBufferRange / (sizeof(float) * 3 * std::max<std::size_t>(cells_.size(), 1));
    return std::min(raster_->MaxBatchSamples(), positions);
  }
  std::uint64_t slots = 1;
  for (const CellPlan& plan : cells_) slots = std::max<std::uint64_t>(slots, plan.depth_slot + 1u);
  // The widest per-sample binding (every cell's positions, or every slot's
  // stored depths), less the lead and padding of the quad layout.
  const std::uint64_t per_sample_bytes = sizeof(float) * std::max<std::uint64_t>(3 * cells_.size(), slots);
  const std::uint64_t fit = limits.maxStorageBufferRange / per_sample_bytes;
  std::uint64_t most = fit > 8 ? fit - 8 : 1;
  // Workgroups along x, each taking frames_per_workgroup frames (the first
  // frame of a batch may be partial).
  const std::uint64_t frames =
      std::uint64_t{limits.maxComputeWorkGroupCount[0]} * std::max<std::uint32_t>(shape_.frames_per_workgroup, 1);
  most = std::min(most, (frames - 1) * kSamplesPerFrame);
  return most;
}

Expected<DeviceObject<VkPipeline>> VulkanBackend::BuildPipeline(const VariantInfo& variant, const PassShape& shape,
                                                                std::vector<std::string>& sources) const {
  DB_ASSIGN_OR_RETURN(const std::vector<std::uint32_t> compiled,
                      CompileVariant(variant, VariantPass::kAccuracy, shader_dir_, &sources));
  DB_ASSIGN_OR_RETURN(const std::vector<std::uint32_t> spirv,
                      ApplyArithmeticProbes(compiled, options_.arithmetic_probes));
  const std::array<VkSpecializationMapEntry, 3> entries = {
      VkSpecializationMapEntry{kWorkgroupSizeConstant, offsetof(PassShape, workgroup_size), sizeof(std::uint32_t)},
      VkSpecializationMapEntry{kSamplesPerInvocationConstant, offsetof(PassShape, samples_per_invocation),
                               sizeof(std::uint32_t)},
      VkSpecializationMapEntry{kFramesPerWorkgroupConstant, offsetof(PassShape, frames_per_workgroup),
                               sizeof(std::uint32_t)}};
  const VkSpecializationInfo specialization{static_cast<std::uint32_t>(entries.size()), entries.data(), sizeof(shape),
                                            &shape};
  return pass_->CreatePipeline(spirv, specialization,
                               fmt::format("'{}'", VariantProgramName(variant, VariantPass::kAccuracy, shader_dir_)));
}

Expected<std::vector<std::uint32_t>> VulkanBackend::CompileJudged(const VariantInfo& variant) const {
  DB_ASSIGN_OR_RETURN(const std::vector<std::uint32_t> compiled,
                      CompileVariant(variant, VariantPass::kJudged, shader_dir_));
  return ApplyArithmeticProbes(compiled, options_.arithmetic_probes);
}

Expected<RenderedDepths> VulkanBackend::RenderDepths(const ShaderInputs& batch) {
  if (raster_ == nullptr) return Unavailable(name() + " renders depths only when prepared for the raster form");
  if (batch.count == 0) return RenderedDepths{};
  std::vector<std::uint32_t> every_cell(cells_.size());
  for (std::uint32_t k = 0; k < every_cell.size(); ++k) every_cell[k] = k;
  DB_RETURN_IF_ERROR(CheckBatch(batch, every_cell).WithContext(DeviceContext()));
  const ValidationScope validation(*context_);
  Expected<RenderedDepths> rendered = raster_->Render(batch);
  if (!rendered.ok()) return rendered.status().WithContext(DeviceContext());
  DB_RETURN_IF_ERROR(validation.Check("RenderDepths").WithContext(DeviceContext()));
  return rendered;
}

// The positions stay in the mapped readback buffer when their slices are
// compact; otherwise they are gathered into `scratch`.
Expected<std::span<const float>> VulkanBackend::Run(const ShaderInputs& batch, std::span<const std::uint32_t> which,
                                                    std::vector<float>& scratch) {
  Expected<std::span<const float>> positions = RunOnDevice(batch, which, scratch);
  if (!positions.ok()) return positions.status().WithContext(DeviceContext());
  return positions;
}

Expected<std::span<const float>> VulkanBackend::RunOnDevice(const ShaderInputs& batch,
                                                            std::span<const std::uint32_t> which,
                                                            std::vector<float>& scratch) {
  const std::size_t output_floats = std::size_t{3} * batch.count * which.size();
  if (output_floats == 0) return std::span<const float>();
  DB_RETURN_IF_ERROR(CheckBatch(batch, which));
  raster_staged_ = false;  // a Run discards what Stage staged
  if (raster_ != nullptr) {
    DB_RETURN_IF_ERROR(CheckRasterOutputs(batch, which));
    const ValidationScope validation(*context_);
    DB_ASSIGN_OR_RETURN(const float* positions, raster_->Run(batch, which, kUnwrittenBits));
    DB_RETURN_IF_ERROR(validation.Check("Run"));
    DB_RETURN_IF_ERROR(CheckEveryOutputWritten(positions, batch, which, SliceLayout{0, batch.count}));
    return std::span<const float>(positions, output_floats);
  }
  const ValidationScope validation(*context_);
  staged_.reset();
  positions_access_ = HostAccess::kReadback;
  DB_ASSIGN_OR_RETURN(const StagedRun run, StageCompute(batch, which, nullptr, /*host_texels=*/true));
  DB_RETURN_IF_ERROR(pass_->Submit([&](VkCommandBuffer commands) { Record(commands, run); }));
  const SliceLayout& slices = run.slices;
  DB_RETURN_IF_ERROR(buffers_[kPositions].InvalidateForHostReads());
  DB_RETURN_IF_ERROR(validation.Check("Run"));
  const auto* device_positions = static_cast<const float*>(buffers_[kPositions].mapped());
  DB_RETURN_IF_ERROR(CheckEveryOutputWritten(device_positions, batch, which, slices));
  if (slices.compact(batch)) return std::span<const float>(device_positions, output_floats);
  // Every slice's samples, without the lead and the padding.
  scratch.resize(output_floats);
  for (std::size_t slice = 0; slice < 3 * which.size(); ++slice) {
    std::memcpy(scratch.data() + slice * batch.count, device_positions + slice * slices.length + slices.lead,
                batch.count * sizeof(float));
  }
  return std::span<const float>(scratch);
}

Expected<StagedRun> VulkanBackend::StageCompute(const ShaderInputs& batch, std::span<const std::uint32_t> which,
                                                ThreadPool* pool, bool host_texels) {
  // The last run's work, if it was left queued, reads what this one rewrites.
  DB_RETURN_IF_ERROR(pass_->Wait());
  StagedRun run;
  run.slices = SliceLayoutFor(batch, shape_);
  const BindingBytes bytes = BytesFor(batch, run.slices, which.size());
  DB_RETURN_IF_ERROR(CheckRun(batch, which, bytes));
  run.plan = PlanDispatches(cells_, which, run.slices);
  run.workgroups = WorkgroupsFor(batch, shape_);
  run.constants = PassConstantsFor(batch, run.slices);
  DB_RETURN_IF_ERROR(Upload(batch, run.slices, bytes, run.plan.cell_slices, pool, host_texels));
  return run;
}

DeviceRunBuffers VulkanBackend::BuffersOf(const ShaderInputs& batch, const SliceLayout& slices,
                                          std::size_t cells) const {
  return DeviceRunBuffers{buffers_[kPositions].handle(),
                          std::size_t{3} * cells * slices.length * sizeof(float),
                          slices.lead,
                          slices.length,
                          buffers_[kStoredDepths].handle(),
                          DepthSlotsOf(batch) * slices.length * sizeof(float),
                          buffers_[kPixels].handle(),
                          std::size_t{slices.length} * sizeof(std::uint32_t),
                          buffers_[kFrames].handle(),
                          batch.frame_params.size() * sizeof(f32::FrameParams),
                          buffers_[kDepthParams].handle(),
                          batch.depth_params.size() * sizeof(f32::DepthParams)};
}

Expected<DeviceRunBuffers> VulkanBackend::Stage(const ShaderInputs& batch, std::span<const std::uint32_t> which,
                                                ThreadPool* pool) {
  staged_.reset();
  raster_staged_ = false;
  if (raster_ != nullptr) return StageRaster(batch, which, pool);
  if (batch.count == 0 || which.empty()) {
    staged_ = StagedRun{};  // no dispatch to queue
    return DeviceRunBuffers{};
  }
  DB_RETURN_IF_ERROR(CheckBatch(batch, which, /*host_texels=*/false).WithContext(DeviceContext()));
  const ValidationScope validation(*context_);
  positions_access_ = HostAccess::kNone;
  Expected<StagedRun> run = StageCompute(batch, which, pool, /*host_texels=*/false);
  if (!run.ok()) return run.status().WithContext(DeviceContext());
  DB_RETURN_IF_ERROR(validation.Check("Stage").WithContext(DeviceContext()));
  const DeviceRunBuffers buffers = BuffersOf(batch, run->slices, which.size());
  staged_ = std::move(run).value();
  return buffers;
}

// The raster form's resident run: the batch's codes are the host's model,
// which the device's texels are counted against.
Expected<DeviceRunBuffers> VulkanBackend::StageRaster(const ShaderInputs& batch, std::span<const std::uint32_t> which,
                                                      ThreadPool* pool) {
  if (batch.count == 0 || which.empty()) {
    DB_RETURN_IF_ERROR(raster_->FinishResident(pool).WithContext(DeviceContext()));
    staged_ = StagedRun{};  // no draw to queue
    return DeviceRunBuffers{};
  }
  DB_RETURN_IF_ERROR(CheckBatch(batch, which).WithContext(DeviceContext()));
  DB_RETURN_IF_ERROR(CheckRasterOutputs(batch, which).WithContext(DeviceContext()));
  const ValidationScope validation(*context_);
  Expected<DeviceRunBuffers> buffers = raster_->StageResident(batch, which, kUnwrittenBits, pool);
  if (!buffers.ok()) return buffers.status().WithContext(DeviceContext());
  DB_RETURN_IF_ERROR(validation.Check("Stage").WithContext(DeviceContext()));
  raster_staged_ = true;
  return buffers;
}

Status VulkanBackend::FinishQueued() {
  const ValidationScope validation(*context_);
  Status status = raster_ != nullptr ? raster_->FinishResident() : pass_->Wait();
  if (status.ok()) status = validation.Check("FinishQueued");
  return status.WithContext(DeviceContext());
}

Status VulkanBackend::QueueStaged() {
  if (raster_staged_) {
    raster_staged_ = false;
    const ValidationScope validation(*context_);
    Status status = raster_->QueueResident();
    if (status.ok()) status = validation.Check("QueueStaged");
    return status.WithContext(DeviceContext());
  }
  if (!staged_) {
    return Internal("no staged run to queue: Stage comes first, and a Run after it discards what it staged");
  }
  const StagedRun run = std::move(*staged_);
  staged_.reset();
  if (run.plan.dispatches.empty()) return Status::Ok();
  const ValidationScope validation(*context_);
  Status status = pass_->SubmitWithoutWaiting([&](VkCommandBuffer commands) { Record(commands, run); });
  if (status.ok()) status = validation.Check("QueueStaged");
  return status.WithContext(DeviceContext());
}

Status VulkanBackend::CheckRasterOutputs(const ShaderInputs& batch, std::span<const std::uint32_t> which) const {
  const std::uint64_t bytes = std::uint64_t{3} * batch.count * which.size() * sizeof(float);
  if (bytes <= context_->properties().limits.maxStorageBufferRange) return Status::Ok();
  return InvalidArgument(fmt::format("{} cells of {} samples write {} bytes; the device binds at most {}", which.size(),
                                     batch.count, bytes, context_->properties().limits.maxStorageBufferRange));
}

// Outputs a shader never wrote would be judged as if it had: refused, with
// the variant and the count.
Status VulkanBackend::CheckEveryOutputWritten(const float* positions, const ShaderInputs& batch,
                                              std::span<const std::uint32_t> which, const SliceLayout& slices) const {
  for (std::size_t k = 0; k < which.size(); ++k) {
    const std::size_t unwritten = UnwrittenSamples(positions, slices, k, batch.count);
    if (unwritten == 0) continue;
    return UnwrittenOutputs(cells_[which[k]].cell, fmt::format("{} of {}", unwritten, batch.count));
  }
  return Status::Ok();
}

Status VulkanBackend::CheckBatch(const ShaderInputs& batch, std::span<const std::uint32_t> which,
                                 bool host_texels) const {
  const std::size_t frames = std::size_t{batch.FrameOf(batch.count - 1)} + 1;
  // (Texels the device stores are not read from the batch, whatever it
  // holds; nor are pixels where it has none.)
  const std::size_t depths = std::size_t{batch.depth_slots} * batch.count;
  const bool device_pixels = !host_texels && batch.pixels.empty();
  if (batch.frame_params.size() < frames || batch.depth_params.size() < frames * kHardwareConventionCount ||
      (!device_pixels && batch.pixels.size() < batch.count) || (host_texels && batch.depths.size() != depths)) {
    return InvalidArgument(fmt::format(
        "batch of {} samples in {} depth slots has {} frame parameters, {} depth parameters, {} "
        "pixels and {} stored depths; it needs {}, {}, {} and {}",
        batch.count, batch.depth_slots, batch.frame_params.size(), batch.depth_params.size(), batch.pixels.size(),
        batch.depths.size(), frames, frames * kHardwareConventionCount, batch.count, depths));
  }
  for (std::uint32_t index : which) {
    if (index >= cells_.size()) {
      return InvalidArgument(fmt::format("cell index {} out of range; {} cells prepared", index, cells_.size()));
    }
    if (cells_[index].depth_slot >= batch.depth_slots) {
      return InvalidArgument(fmt::format("cell {} reads depth slot {}; the batch has {}", cells_[index].cell.Name(),
                                         cells_[index].depth_slot, batch.depth_slots));
    }
  }
  return Status::Ok();
}

Status VulkanBackend::CheckRun(const ShaderInputs& batch, std::span<const std::uint32_t> which,
                               const BindingBytes& bytes) const {
  const VkPhysicalDeviceLimits& limits = context_->properties().limits;
  const std::uint32_t groups = WorkgroupsFor(batch, shape_);
  if (groups > limits.maxComputeWorkGroupCount[0]) {
    return InvalidArgument(fmt::format("a batch of {} samples needs {} workgroups; the device dispatches at most {}",
                                       batch.count, groups, limits.maxComputeWorkGroupCount[0]));
  }
  // A dispatch runs one variant's cells, a workgroup row each.
  if (which.size() > limits.maxComputeWorkGroupCount[1]) {
    return InvalidArgument(fmt::format("{} cells at once need as many workgroup rows; the device dispatches at most {}",
                                       which.size(), limits.maxComputeWorkGroupCount[1]));
  }
  // Within this limit every element offset also fits the shaders' uints.
  for (std::uint32_t binding = 0; binding < kBindingCount; ++binding) {
    if (bytes[binding] > limits.maxStorageBufferRange) {
      return InvalidArgument(
          fmt::format("binding {} needs {} bytes; the device binds at most {} (run fewer samples "
                      "or cells at once)",
                      binding, bytes[binding], limits.maxStorageBufferRange));
    }
  }
  return Status::Ok();
}

Status VulkanBackend::EnsureCapacity(Binding binding, VkDeviceSize bytes) {
  const HostAccess access = binding == kPositions ? positions_access_ : HostAccess::kUpload;
  if (binding == kPositions && positions_held_in_ != positions_access_) {
    buffers_[kPositions] = VulkanBuffer();  // (the previous run has completed)
    positions_held_in_ = positions_access_;
  }
  // The output is filled with kUnwrittenBits on the device before each
  // run; a judge on the device may copy the inputs (the texels it stored,
  // for tests; the frames' constants and the pixels, for its fused pass).
  const VkBufferUsageFlags usage =
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
      (binding == kPositions ? VkBufferUsageFlags{VK_BUFFER_USAGE_TRANSFER_DST_BIT}
       : binding == kCellSlices ? VkBufferUsageFlags{0}
                                : VkBufferUsageFlags{VK_BUFFER_USAGE_TRANSFER_SRC_BIT});
  // The previous run has completed (Run waits), so the old buffer can go.
  return context_->GrowHostBuffer(buffers_[binding], bytes, usage, access);
}

Status VulkanBackend::Upload(const ShaderInputs& batch, const SliceLayout& slices, const BindingBytes& bytes,
                             std::span<const f32::CellSlice> cell_slices, ThreadPool* pool, bool texels) {
  for (std::uint32_t binding = 0; binding < kBindingCount; ++binding) {
    DB_RETURN_IF_ERROR(EnsureCapacity(static_cast<Binding>(binding), bytes[binding]));
  }
  // The frames' constants, 1.6 kB per frame: at a GPU's rate one thread's
  // copies are a visible share of a batch, so the pool's threads copy.
  const auto copy = [pool](void* to, const void* from, std::size_t n) {
    if (pool != nullptr) {
      pool->Copy(to, from, n);
    } else {
      std::memcpy(to, from, n);
    }
  };
  copy(buffers_[kFrames].mapped(), batch.frame_params.data(), bytes[kFrames]);
  copy(buffers_[kDepthParams].mapped(), batch.depth_params.data(), bytes[kDepthParams]);
  std::memcpy(buffers_[kCellSlices].mapped(), cell_slices.data(), bytes[kCellSlices]);
  // The per-sample inputs, slice by slice; the lead and the padding are
  // zeros (the shader reconstructs them too, into positions nobody reads).
  static_assert(sizeof(batch.pixels[0]) == 4 && sizeof(batch.depths[0]) == 4);
  const auto put_slice = [&](Binding binding, std::size_t slice, const void* samples) {
    auto* to = static_cast<std::byte*>(buffers_[binding].mapped()) + slice * slices.length * 4;
    const std::size_t end = std::size_t{slices.lead} + batch.count;
    std::memset(to, 0, std::size_t{slices.lead} * 4);
    std::memcpy(to + std::size_t{slices.lead} * 4, samples, std::size_t{batch.count} * 4);
    std::memset(to + end * 4, 0, (slices.length - end) * 4);
  };
  // Slice 0 of the pixels (unless the device writes them), then each
  // depth slot's texels: on the pool's threads where there is one (at a
  // GPU's rate one thread's copies are a visible share of a batch).
  const std::size_t pixel_slices = texels || !batch.pixels.empty() ? 1 : 0;
  const auto put = [&](std::size_t begin, std::size_t end, unsigned) {
    for (std::size_t k = begin; k < end; ++k) {
      if (k < pixel_slices) {
        put_slice(kPixels, 0, batch.pixels.data());
      } else {
        put_slice(kStoredDepths, k - pixel_slices, batch.depths.data() + (k - pixel_slices) * batch.count);
      }
    }
  };
  const std::size_t slices_to_put = pixel_slices + (texels ? DepthSlotsOf(batch) : 0);
  if (pool != nullptr) {
    pool->ParallelFor(slices_to_put, put);
  } else {
    put(0, slices_to_put, 0);
  }
  for (std::uint32_t binding = 0; binding < kPositions; ++binding) {
    DB_RETURN_IF_ERROR(buffers_[binding].FlushHostWrites());
  }
  BindBuffers(bytes);
  return Status::Ok();
}

// Points the descriptors at exactly the bytes this run uses: buffers may
// have been reallocated, and a range past the data would hide overruns.
void VulkanBackend::BindBuffers(const BindingBytes& bytes) {
  std::array<VkDescriptorBufferInfo, kBindingCount> infos{};
  std::array<VkWriteDescriptorSet, kBindingCount> writes{};
  for (std::uint32_t binding = 0; binding < kBindingCount; ++binding) {
    infos[binding] = {buffers_[binding].handle(), 0, bytes[binding]};
    writes[binding].dstBinding = binding;
    writes[binding].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[binding].pBufferInfo = &infos[binding];
  }
  pass_->WriteDescriptors(writes);
}

void VulkanBackend::Record(VkCommandBuffer commands, const StagedRun& run) const {
  // Every output starts as kUnwrittenBits; the shaders' writes come after.
  vkCmdFillBuffer(commands, buffers_[kPositions].handle(), 0, VK_WHOLE_SIZE, kUnwrittenBits);
  RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT);
  // Cells write disjoint slices and only read the inputs: no barriers between dispatches.
  for (const DispatchPlan::Dispatch& dispatch : run.plan.dispatches) {
    pass_->Bind(commands, pipelines_[VariantIndex(dispatch.variant)].get());
    f32::PassConstants constants = run.constants;
    constants.first_cell = dispatch.first_cell;
    pass_->PushConstants(commands, &constants, sizeof(constants));
    vkCmdDispatch(commands, run.workgroups, dispatch.cells, 1);
  }
  // The host reads the positions once the fence signals.
  RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                      VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
}

}  // namespace

Status UnwrittenOutputs(const Cell& cell, const std::string& unwritten) {
  return InvalidArgument(fmt::format(
      "the {} shader did not write its output for {} samples (cell {}): the program returns before storing "
      "it or stores another element, or the device cut the invocation short (lavapipe ends the loops of an "
      "invocation after 65535 iterations); nothing it did not write is judged",
      cell.variant_info().name, unwritten, cell.Name()));
}

Expected<std::unique_ptr<Backend>> MakeVulkanBackend(const BackendOptions& options) {
  VulkanContextOptions context_options;
  context_options.device = options.device;
  context_options.validation = options.validation;
  DB_ASSIGN_OR_RETURN(std::unique_ptr<VulkanContext> context, VulkanContext::Create(context_options));
  return VulkanBackend::Create(std::move(context), options);
}

Expected<std::unique_ptr<Backend>> MakeVulkanBackend(std::shared_ptr<VulkanContext> context,
                                                     const BackendOptions& options) {
  return VulkanBackend::Create(std::move(context), options);
}

}  // namespace depthbench
