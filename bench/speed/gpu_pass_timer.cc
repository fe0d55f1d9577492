#include "bench/speed/gpu_pass_timer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include <fmt/format.h>

#include "bench/backends/vulkan/compute_pass.h"
#include "bench/backends/vulkan/graphics_pipeline.h"
#include "bench/backends/vulkan/shader_compiler.h"
#include "bench/backends/vulkan/variant_program.h"
#include "bench/base/files.h"
#include "bench/base/interrupt.h"
#include "bench/speed/timing_stats.h"

namespace depthbench {
namespace {

// shaders/speed/speed_pass.glsl: its bindings, specialization constants and
// workgroup size.
enum Binding : std::uint32_t { kConstantsBinding = 0, kImageBinding = 1, kResultsBinding = 2 };
constexpr std::uint32_t kTapsConstant = 0;
constexpr std::uint32_t kConventionConstant = 1;
// 16x16: with 8x8 groups (two warps each) an H200 ran every memory-bound
// pass at a third of the rate (22.0 against 7.5 us at 1920x1080), bound by
// how fast it starts workgroups, not by memory.
constexpr std::uint32_t kWorkgroupSide = 16;
struct PassSize {
  std::uint32_t width;
  std::uint32_t height;
};
// The uniform block: FrameParams then DepthParams, std140 = std430 here.
struct PassConstants {
  f32::FrameParams frame;
  f32::DepthParams depth;
};
// More warm-up passes than this are not needed on any device.
constexpr std::uint64_t kMaxExtraWarmupPasses = 65536;

// shaders/speed/bandwidth.comp: its bindings, element and workgroup size.
enum ProbeBinding : std::uint32_t { kProbeSourceBinding = 0, kProbeDestinationBinding = 1 };
constexpr VkDeviceSize kProbeElementBytes = 16;  // a uvec4
constexpr std::uint32_t kProbeWorkgroupSize = 256;
// The most workgroups of one probe dispatch: below every device's
// maxComputeWorkGroupCount[0] (at least 65535), and 2^20 invocations,
// several times the resident threads of any GPU (an H200: 132 SMs of 2048);
// on a CPU device fewer, longer invocations copy faster (lavapipe: about
// 1.5 times 32768 groups' rate, 4 times 512's).
constexpr std::uint32_t kMaxProbeGroups = 4096;
// A smaller probe fits in caches and would time them, not memory.
constexpr std::uint64_t kMinProbeBytes = std::uint64_t{1} << 20;

// shaders/speed/stage_probe.glsl: its counts (one per stage, then one per
// stage and processor), push constants, specialization constant (each
// chain's multiply-adds), chains and the compute row's workgroup.
constexpr std::uint32_t kStageCounts = 3;
constexpr std::uint32_t kMostProcessors = 1024;
struct StagePush {
  std::uint32_t stage;
  std::uint32_t width;
};
constexpr std::uint32_t kStageIterationsConstant = 0;
constexpr std::uint32_t kStageChains = 4;
constexpr std::uint32_t kStageWorkgroupSize = 64;
constexpr std::uint32_t kMostStageIterations = 16384;

std::uint32_t GroupsFor(std::uint32_t pixels) { return (pixels + kWorkgroupSide - 1) / kWorkgroupSide; }

void ComputeToComputeBarrier(VkCommandBuffer commands) {
  RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

}  // namespace

Status CheckFormatFeatures(Format format, VkFormatFeatureFlags features, const std::string& device_name) {
  std::string missing;
  if ((features & VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT) == 0) missing = "sampled images";
  if ((features & VK_FORMAT_FEATURE_TRANSFER_DST_BIT) == 0) {
    missing += std::string(missing.empty() ? "" : " and ") + "transfers into images";
  }
  if (missing.empty()) return Status::Ok();
  return Unavailable(
      fmt::format("{} ({}) is not supported by Vulkan device '{}': its optimal-tiling features "
                  "lack {}, so no pass can read a real image of it",
                  Info(format).name, Info(format).vulkan_name, device_name, missing));
}

GpuPassTimer::GpuPassTimer(std::shared_ptr<VulkanContext> context, std::filesystem::path shader_dir)
    : context_(std::move(context)), shader_dir_(std::move(shader_dir)) {}

Expected<std::unique_ptr<GpuPassTimer>> GpuPassTimer::Create(std::shared_ptr<VulkanContext> context,
                                                             std::filesystem::path shader_dir) {
  if (context == nullptr) return InvalidArgument("the GPU pass timer needs a Vulkan context");
  DB_RETURN_IF_ERROR(TimestampQueries::Supported(*context));
  DB_RETURN_IF_ERROR(CheckDirectory(shader_dir, "shader directory"));
  DB_RETURN_IF_ERROR(CheckDirectory(shader_dir / "speed", "speed shader directory"));
  std::unique_ptr<GpuPassTimer> timer(new GpuPassTimer(std::move(context), std::move(shader_dir)));
  const ValidationScope validation(*timer->context_);
  const std::array<VkDescriptorSetLayoutBinding, 3> bindings = {{
      {kConstantsBinding, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
      {kImageBinding, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
      {kResultsBinding, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
  }};
  DB_ASSIGN_OR_RETURN(timer->pass_, ComputePass::Create(timer->context_, bindings, sizeof(PassSize)));
  DB_ASSIGN_OR_RETURN(timer->sampler_, timer->context_->CreateTexelSampler());
  DB_RETURN_IF_ERROR(validation.Check("the creation of the GPU pass timer"));
  return timer;
}

Status GpuPassTimer::CheckFormat(Format format) const {
  VkFormatProperties properties{};
  vkGetPhysicalDeviceFormatProperties(context_->physical_device(), VulkanFormatOf(format), &properties);
  return CheckFormatFeatures(format, properties.optimalTilingFeatures, device().name);
}

Expected<VkPipeline> GpuPassTimer::Pipeline(const VariantInfo& variant, Convention convention, std::uint32_t taps) {
  const auto key = std::make_tuple(variant.id, convention, taps);
  if (auto found = pipelines_.find(key); found != pipelines_.end()) return found->second.get();
  auto compiled = spirv_.find(variant.id);
  if (compiled == spirv_.end()) {
    DB_ASSIGN_OR_RETURN(std::vector<std::uint32_t> words, CompileVariant(variant, VariantPass::kSpeed, shader_dir_));
    compiled = spirv_.emplace(variant.id, std::move(words)).first;
  }
  const std::vector<std::uint32_t>& spirv = compiled->second;
  const std::array<std::uint32_t, 2> values = {taps, Info(convention).bits};
  const std::array<VkSpecializationMapEntry, 2> entries = {{
      {kTapsConstant, 0, sizeof(std::uint32_t)},
      {kConventionConstant, sizeof(std::uint32_t), sizeof(std::uint32_t)},
  }};
  const VkSpecializationInfo specialization{static_cast<std::uint32_t>(entries.size()), entries.data(), sizeof(values),
                                            values.data()};
  DB_ASSIGN_OR_RETURN(DeviceObject<VkPipeline> pipeline,
                      pass_->CreatePipeline(spirv, specialization, fmt::format("the {} speed pass", variant.name)));
  auto& stored = pipelines_[key];
  stored = std::move(pipeline);
  return stored.get();
}

Status GpuPassTimer::CreateImage(const DepthImage& image) {
  const Format format = image.encoding.format;
  DB_RETURN_IF_ERROR(CheckFormat(format));
  const VkImageAspectFlags aspect = IsDepthFormat(format) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
  DB_ASSIGN_OR_RETURN(VulkanImage new_image,
                      context_->CreateImage(VulkanFormatOf(format), {image.resolution.width, image.resolution.height},
                                            VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, aspect));
  const VkImage handle = new_image.image.get();

  // The texels travel through a staging buffer, as an engine uploads.
  DB_ASSIGN_OR_RETURN(
      VulkanBuffer staging,
      context_->CreateHostBuffer(image.texels.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, HostAccess::kUpload));
  std::memcpy(staging.mapped(), image.texels.data(), image.texels.size());
  DB_RETURN_IF_ERROR(staging.FlushHostWrites());
  DB_RETURN_IF_ERROR(pass_->Submit([&](VkCommandBuffer commands) {
    RecordImageBarrier(commands, new_image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                       VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, 0, VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_ACCESS_TRANSFER_WRITE_BIT);
    VkBufferImageCopy region{};
    region.imageSubresource = {aspect, 0, 0, 1};
    region.imageExtent = {image.resolution.width, image.resolution.height, 1};
    vkCmdCopyBufferToImage(commands, staging.handle(), handle, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    RecordImageBarrier(commands, new_image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                       VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
  }));
  image_.Reset();
  image_ = std::move(new_image);
  return Status::Ok();
}

Status GpuPassTimer::CreateResultBuffer(VkDeviceSize bytes) {
  if (bytes == result_bytes_) return Status::Ok();
  const VkPhysicalDeviceLimits& limits = device().limits;
  if (bytes > limits.maxStorageBufferRange) {
    return InvalidArgument(
        fmt::format("a pass over {}x{} pixels writes {} bytes; Vulkan device '{}' binds at "
                    "most {} bytes of storage buffer",
                    resolution_.width, resolution_.height, bytes, device().name, limits.maxStorageBufferRange));
  }
  result_buffer_.Reset();
  result_memory_.Reset();
  result_bytes_ = 0;
  DB_ASSIGN_OR_RETURN(BoundBuffer bound,
                      CreateBoundBuffer(bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT));
  result_memory_ = std::move(bound.memory);
  result_buffer_ = std::move(bound.buffer);
  result_bytes_ = bytes;
  return Status::Ok();
}

Expected<GpuPassTimer::BoundBuffer> GpuPassTimer::CreateBoundBuffer(VkDeviceSize bytes,
                                                                    VkBufferUsageFlags usage) const {
  VkBufferCreateInfo buffer_info{};
  buffer_info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  buffer_info.size = bytes;
  buffer_info.usage = usage;
  buffer_info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkBuffer handle = VK_NULL_HANDLE;
  DB_RETURN_IF_ERROR(CheckVk(vkCreateBuffer(vk_device(), &buffer_info, nullptr, &handle), "vkCreateBuffer"));
  BoundBuffer bound;
  bound.buffer = DeviceObject<VkBuffer>(vk_device(), handle, vkDestroyBuffer);
  VkMemoryRequirements requirements{};
  vkGetBufferMemoryRequirements(vk_device(), handle, &requirements);
  DB_ASSIGN_OR_RETURN(bound.memory, context_->AllocateDeviceLocal(requirements));
  DB_RETURN_IF_ERROR(CheckVk(vkBindBufferMemory(vk_device(), handle, bound.memory.get(), 0), "vkBindBufferMemory"));
  return bound;
}

void GpuPassTimer::WriteDescriptors() {
  const VkDescriptorBufferInfo constants_info{constants_.handle(), 0, sizeof(PassConstants)};
  const VkDescriptorImageInfo image_info{sampler_.get(), image_.view.get(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
  const VkDescriptorBufferInfo results_info{result_buffer_.get(), 0, result_bytes_};
  std::array<VkWriteDescriptorSet, 3> writes{};
  writes[0].dstBinding = kConstantsBinding;
  writes[0].descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
  writes[0].pBufferInfo = &constants_info;
  writes[1].dstBinding = kImageBinding;
  writes[1].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  writes[1].pImageInfo = &image_info;
  writes[2].dstBinding = kResultsBinding;
  writes[2].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  writes[2].pBufferInfo = &results_info;
  pass_->WriteDescriptors(writes);
}

Status GpuPassTimer::LoadImage(const DepthImage& image) {
  const ValidationScope validation(*context_);
  loaded_ = false;
  resolution_ = image.resolution;
  const std::size_t expected =
      static_cast<std::size_t>(image.resolution.width) * image.resolution.height * TexelBytes(image.encoding.format);
  if (image.texels.size() != expected || image.texel_bytes != TexelBytes(image.encoding.format)) {
    return InvalidArgument(fmt::format("depth image of {}x{} {} holds {} bytes; it needs {}", image.resolution.width,
                                       image.resolution.height, Info(image.encoding.format).name, image.texels.size(),
                                       expected));
  }
  DB_RETURN_IF_ERROR(CreateImage(image));
  DB_RETURN_IF_ERROR(
      CreateResultBuffer(static_cast<VkDeviceSize>(image.resolution.width) * image.resolution.height * sizeof(float)));
  if (constants_.handle() == VK_NULL_HANDLE) {
    DB_ASSIGN_OR_RETURN(
        constants_,
        context_->CreateHostBuffer(sizeof(PassConstants), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, HostAccess::kUpload));
  }
  const PassConstants constants{image.frame_params, image.depth_params};
  std::memcpy(constants_.mapped(), &constants, sizeof(constants));
  DB_RETURN_IF_ERROR(constants_.FlushHostWrites());
  WriteDescriptors();
  DB_RETURN_IF_ERROR(validation.Check("the loading of the depth image"));
  encoding_ = image.encoding;
  loaded_ = true;
  return Status::Ok();
}

void GpuPassTimer::RecordPasses(VkCommandBuffer commands, VkPipeline pipeline, std::uint32_t passes) const {
  pass_->Bind(commands, pipeline);
  const PassSize size{resolution_.width, resolution_.height};
  pass_->PushConstants(commands, &size, sizeof(size));
  for (std::uint32_t pass = 0; pass < passes; ++pass) {
    vkCmdDispatch(commands, GroupsFor(resolution_.width), GroupsFor(resolution_.height), 1);
    // Each pass waits for the one before, and the next submission's passes
    // for the last: they all write the same results.
    ComputeToComputeBarrier(commands);
  }
}

Expected<std::vector<double>> GpuPassTimer::TimeGroups(ComputePass& pass, std::span<const Group> groups,
                                                       const Recorder& record) {
  const auto queries = static_cast<std::uint32_t>(2 * groups.size());
  if (queries > queries_.count()) {
    DB_ASSIGN_OR_RETURN(queries_, TimestampQueries::Create(*context_, queries));
  }
  DB_RETURN_IF_ERROR(pass.Submit([&](VkCommandBuffer commands) {
    queries_.RecordReset(commands, 0, queries);
    for (std::uint32_t g = 0; g < groups.size(); ++g) {
      queries_.RecordWrite(commands, 2 * g);
      record(commands, groups[g].pipeline, groups[g].passes);
      queries_.RecordWrite(commands, 2 * g + 1);
    }
  }));
  DB_ASSIGN_OR_RETURN(const std::vector<std::uint64_t> stamps, queries_.Read(0, queries));
  std::vector<double> ns_per_pass(groups.size());
  for (std::uint32_t g = 0; g < groups.size(); ++g) {
    const double ns = queries_.IntervalNs(stamps[2 * g], stamps[2 * g + 1]);
    ns_per_pass[g] = ns / groups[g].passes;
  }
  return ns_per_pass;
}

Expected<PassTiming> GpuPassTimer::TimePass(const VariantInfo& variant, std::uint32_t taps, std::uint32_t warmup,
                                            std::uint32_t repetitions) {
  const VariantInfo variants[] = {variant};
  DB_ASSIGN_OR_RETURN(std::vector<PassTiming> timings, TimePasses(variants, taps, warmup, repetitions));
  return std::move(timings.front());
}

Expected<std::vector<PassTiming>> GpuPassTimer::TimePasses(std::span<const VariantInfo> variants, std::uint32_t taps,
                                                           std::uint32_t warmup, std::uint32_t repetitions) {
  if (!loaded_) return InvalidArgument("no depth image is loaded: LoadImage first");
  if (variants.empty()) return InvalidArgument("no variant to time");
  for (const VariantInfo& variant : variants) {
    if (!Reads(variant, encoding_.convention, encoding_.format)) {
      return InvalidArgument(
          fmt::format("{} does not read {} under the {} convention (see 'depthbench list'); "
                      "such a pass is not timed",
                      variant.name, Info(encoding_.format).name, Info(encoding_.convention).name));
    }
  }
  if (taps == 0 || taps > kMaxTaps) {
    return InvalidArgument(fmt::format("taps {} is outside 1 to {}", taps, kMaxTaps));
  }
  if (warmup == 0 || repetitions == 0) {
    return InvalidArgument("a timed pass needs at least one warm-up pass and one repetition");
  }
  const ValidationScope validation(*context_);
  std::vector<VkPipeline> pipelines;
  for (const VariantInfo& variant : variants) {
    // Compiling a pipeline takes seconds on a CPU implementation: a signal
    // stops the timing between two (a submitted pass cannot be stopped).
    if (Interrupted()) return InterruptedError("");
    DB_ASSIGN_OR_RETURN(const VkPipeline pipeline, Pipeline(variant, encoding_.convention, taps));
    pipelines.push_back(pipeline);
  }
  const Recorder record = [this](VkCommandBuffer commands, VkPipeline pipeline, std::uint32_t passes) {
    RecordPasses(commands, pipeline, passes);
  };
  DB_ASSIGN_OR_RETURN(std::vector<PassTiming> timings, TimeInterleaved(*pass_, pipelines, record, warmup, repetitions));
  DB_RETURN_IF_ERROR(validation.Check("the timing of passes"));
  return timings;
}

Expected<std::vector<PassTiming>> GpuPassTimer::TimeInterleaved(ComputePass& pass,
                                                                std::span<const VkPipeline> pipelines,
                                                                const Recorder& record, std::uint32_t warmup,
                                                                std::uint32_t repetitions) {
  const std::size_t count = pipelines.size();
  // Warm-up rounds, one pass of each pipeline: also each one's pass time.
  std::vector<Group> schedule;
  for (std::uint32_t round = 0; round < warmup; ++round) {
    for (const VkPipeline pipeline : pipelines) schedule.push_back({pipeline, 1});
  }
  DB_ASSIGN_OR_RETURN(const std::vector<double> first, TimeGroups(pass, schedule, record));
  std::vector<PassTiming> timings(count);
  std::vector<double> pass_ns(count);
  double warmed_ns = 0.0;
  double round_ns = 0.0;
  for (std::size_t v = 0; v < count; ++v) {
    std::vector<double> own;
    for (std::uint32_t round = 0; round < warmup; ++round) own.push_back(first[round * count + v]);
    DB_ASSIGN_OR_RETURN(const TimingSummary estimate, SummarizeTimings(own));
    pass_ns[v] = std::max(estimate.median, 1.0);
    for (double ns : own) warmed_ns += ns;
    round_ns += pass_ns[v];
    timings[v].warmup_passes = warmup;
  }
  // More rounds until the device has run kMinWarmupNs.
  if (warmed_ns < kMinWarmupNs) {
    const auto rounds = static_cast<std::uint32_t>(std::min<double>(
        std::ceil((kMinWarmupNs - warmed_ns) / round_ns), static_cast<double>(kMaxExtraWarmupPasses / count)));
    DB_RETURN_IF_ERROR(pass.Submit([&](VkCommandBuffer commands) {
      for (std::uint32_t round = 0; round < rounds; ++round) {
        for (const VkPipeline pipeline : pipelines) record(commands, pipeline, 1);
      }
    }));
    for (PassTiming& timing : timings) timing.warmup_passes += rounds;
  }
  if (Interrupted()) return InterruptedError("");
  // The timed rounds: one group of each variant per round.
  for (std::size_t v = 0; v < count; ++v) {
    timings[v].passes_per_repetition =
        static_cast<std::uint32_t>(std::clamp<double>(std::ceil(kMinGroupNs / pass_ns[v]), 1.0, kMaxPassesPerGroup));
  }
  schedule.clear();
  for (std::uint32_t round = 0; round < repetitions; ++round) {
    for (std::size_t v = 0; v < count; ++v) schedule.push_back({pipelines[v], timings[v].passes_per_repetition});
  }
  DB_ASSIGN_OR_RETURN(const std::vector<double> timed, TimeGroups(pass, schedule, record));
  for (std::uint32_t round = 0; round < repetitions; ++round) {
    for (std::size_t v = 0; v < count; ++v) timings[v].ns_per_pass.push_back(timed[round * count + v]);
  }
  return timings;
}

Expected<std::vector<float>> GpuPassTimer::ReadResults() {
  if (!loaded_) return InvalidArgument("no depth image is loaded: LoadImage first");
  DB_ASSIGN_OR_RETURN(VulkanBuffer readback, context_->CreateHostBuffer(result_bytes_, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                                                        HostAccess::kReadback));
  DB_RETURN_IF_ERROR(pass_->Submit([&](VkCommandBuffer commands) {
    RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                        VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    const VkBufferCopy region{0, 0, result_bytes_};
    vkCmdCopyBuffer(commands, result_buffer_.get(), readback.handle(), 1, &region);
    RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                        VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
  }));
  DB_RETURN_IF_ERROR(readback.InvalidateForHostReads());
  std::vector<float> values(result_bytes_ / sizeof(float));
  std::memcpy(values.data(), readback.mapped(), result_bytes_);
  return values;
}

Expected<BandwidthTiming> GpuPassTimer::MeasureBandwidth(std::uint64_t bytes, std::uint32_t warmup,
                                                         std::uint32_t repetitions) {
  if (bytes < kMinProbeBytes) {
    return InvalidArgument(
        fmt::format("a bandwidth probe of {} bytes is too small to time (at least {})", bytes, kMinProbeBytes));
  }
  if (warmup == 0 || repetitions == 0) {
    return InvalidArgument("a timed pass needs at least one warm-up pass and one repetition");
  }
  // As large as asked, as the device binds, and an eighth of its largest
  // device-local heap (room for the two buffers beside everything else),
  // whole workgroups of 16-byte elements.
  VkPhysicalDeviceMemoryProperties memory{};
  vkGetPhysicalDeviceMemoryProperties(context_->physical_device(), &memory);
  VkDeviceSize heap = 0;
  for (std::uint32_t h = 0; h < memory.memoryHeapCount; ++h) {
    if ((memory.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) != 0) {
      heap = std::max(heap, memory.memoryHeaps[h].size);
    }
  }
  constexpr VkDeviceSize kGroupBytes = kProbeElementBytes * kProbeWorkgroupSize;
  VkDeviceSize size = std::min<VkDeviceSize>({bytes, device().limits.maxStorageBufferRange, heap / 8});
  size -= size % kGroupBytes;
  if (size < kMinProbeBytes) {
    return Unavailable(
        fmt::format("Vulkan device '{}' binds or holds too little for a bandwidth probe of {} bytes "
                    "(maxStorageBufferRange {}, largest device-local heap {})",
                    device().name, kMinProbeBytes, device().limits.maxStorageBufferRange, heap));
  }
  const ValidationScope validation(*context_);
  const std::array<VkDescriptorSetLayoutBinding, 2> bindings = {{
      {kProbeSourceBinding, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
      {kProbeDestinationBinding, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
  }};
  DB_ASSIGN_OR_RETURN(std::unique_ptr<ComputePass> probe,
                      ComputePass::Create(context_, bindings, sizeof(std::uint32_t)));
  DB_ASSIGN_OR_RETURN(const std::vector<std::uint32_t> spirv, CompileShader(shader_dir_ / "speed" / "bandwidth.comp"));
  DB_ASSIGN_OR_RETURN(DeviceObject<VkPipeline> pipeline,
                      probe->CreatePipeline(spirv, VkSpecializationInfo{}, "the bandwidth probe"));

  // The source and the destination.
  BoundBuffer bound[2];
  for (BoundBuffer& b : bound) {
    DB_ASSIGN_OR_RETURN(b,
                        CreateBoundBuffer(size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT));
  }
  const VkDescriptorBufferInfo source_info{bound[0].buffer.get(), 0, size};
  const VkDescriptorBufferInfo destination_info{bound[1].buffer.get(), 0, size};
  std::array<VkWriteDescriptorSet, 2> writes{};
  writes[0].dstBinding = kProbeSourceBinding;
  writes[0].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  writes[0].pBufferInfo = &source_info;
  writes[1].dstBinding = kProbeDestinationBinding;
  writes[1].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  writes[1].pBufferInfo = &destination_info;
  probe->WriteDescriptors(writes);
  // Defined contents to copy (a device may skip pages never written).
  DB_RETURN_IF_ERROR(probe->Submit([&](VkCommandBuffer commands) {
    vkCmdFillBuffer(commands, bound[0].buffer.get(), 0, size, 0x3f800000u);
    RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                        VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
  }));

  const auto elements = static_cast<std::uint32_t>(size / kProbeElementBytes);
  // Every invocation copies elements a whole dispatch apart (grid-stride),
  // so that no dispatch exceeds any device's group-count limit (65535).
  const std::uint32_t groups = std::min<std::uint32_t>(elements / kProbeWorkgroupSize, kMaxProbeGroups);
  const Recorder record = [&](VkCommandBuffer commands, VkPipeline copy, std::uint32_t passes) {
    probe->Bind(commands, copy);
    probe->PushConstants(commands, &elements, sizeof(elements));
    for (std::uint32_t p = 0; p < passes; ++p) {
      vkCmdDispatch(commands, groups, 1, 1);
      // Each copy waits for the one before, as the timed passes do.
      ComputeToComputeBarrier(commands);
    }
  };
  const VkPipeline pipelines[] = {pipeline.get()};
  DB_ASSIGN_OR_RETURN(std::vector<PassTiming> timings, TimeInterleaved(*probe, pipelines, record, warmup, repetitions));
  DB_RETURN_IF_ERROR(validation.Check("the bandwidth probe"));
  return BandwidthTiming{size, size, std::move(timings.front())};
}

Expected<StageTimings> GpuPassTimer::MeasureStages(Resolution size, std::uint32_t iterations, std::uint32_t warmup,
                                                   std::uint32_t repetitions) {
  // The fragment row draws `size` in one viewport.
  const VkPhysicalDeviceLimits& limits = device().limits;
  const std::uint32_t most_width = std::min(limits.maxViewportDimensions[0], limits.maxFramebufferWidth);
  const std::uint32_t most_height = std::min(limits.maxViewportDimensions[1], limits.maxFramebufferHeight);
  if (size.width == 0 || size.height == 0 || size.width > most_width || size.height > most_height) {
    return InvalidArgument(fmt::format("a stage probe of {}x{} invocations: '{}' draws at most {}x{}", size.width,
                                       size.height, device().name, most_width, most_height));
  }
  const std::uint64_t invocations = std::uint64_t{size.width} * size.height;
  if (invocations % kStageWorkgroupSize != 0 ||
      invocations / kStageWorkgroupSize > device().limits.maxComputeWorkGroupCount[0]) {
    return InvalidArgument(
        fmt::format("a stage probe of {}x{} invocations: they must be whole workgroups of {}, "
                    "at most {} of them",
                    size.width, size.height, kStageWorkgroupSize, device().limits.maxComputeWorkGroupCount[0]));
  }
  if (iterations == 0 || iterations > kMostStageIterations) {
    return InvalidArgument(fmt::format("a stage probe of {} iterations: 1 to {}", iterations, kMostStageIterations));
  }
  if (warmup == 0 || repetitions == 0) {
    return InvalidArgument("a timed pass needs at least one warm-up pass and one repetition");
  }
  StageTimings result;
  result.fma_per_invocation = kStageChains * iterations;
  result.size = size;
  result.processors = std::min(context_->stage_probe_features().processors, kMostProcessors);
  const RasterFeatures& raster = context_->raster_features();
  const bool draws = raster.graphics_queue && raster.dynamic_rendering;
  const bool vertex = draws && context_->stage_probe_features().vertex_stores;
  const bool fragment = draws && raster.fragment_stores;
  if (!vertex) {
    result.left_out.push_back(!draws ? "vertex: the device's queue cannot draw with dynamic rendering"
                                     : "vertex: the device has no stores from the vertex stage "
                                       "(vertexPipelineStoresAndAtomics)");
  }
  if (!fragment) {
    result.left_out.push_back(!draws ? "fragment: the device's queue cannot draw with dynamic rendering"
                                     : "fragment: the device has no stores from the fragment stage "
                                       "(fragmentStoresAndAtomics)");
  }

  const ValidationScope validation(*context_);
  const VkDescriptorSetLayoutBinding binding{
      0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1,
      VK_SHADER_STAGE_COMPUTE_BIT | VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, nullptr};
  const VkShaderStageFlags pushed = binding.stageFlags;
  DB_ASSIGN_OR_RETURN(std::unique_ptr<ComputePass> probe,
                      ComputePass::Create(context_, std::span(&binding, 1), sizeof(StagePush), pushed));
  // Each program, with the processors' numbers read where the device names
  // them (the define goes after the #version line).
  const auto compile = [&](const char* file, ShaderStage stage) -> Expected<std::vector<std::uint32_t>> {
    const std::filesystem::path path = shader_dir_ / "speed" / file;
    DB_ASSIGN_OR_RETURN(std::string source, ReadFile(path, std::uintmax_t{1} << 20, "shader"));
    if (result.processors > 0) {
      const std::size_t line_end = source.find('\n');
      source.insert(line_end == std::string::npos ? source.size() : line_end + 1, "#define STAGE_PROBE_PROCESSORS 1\n");
    }
    return CompileShaderSource(std::move(source), path.string(), path.parent_path(), ShaderLanguage::kGlsl, stage);
  };
  const auto module = [&](const char* file, ShaderStage stage) -> Expected<DeviceObject<VkShaderModule>> {
    DB_ASSIGN_OR_RETURN(const std::vector<std::uint32_t> spirv, compile(file, stage));
    return CreateShaderModule(vk_device(), spirv, file);
  };
  // The counts, read back after one more pass of each stage.
  constexpr VkDeviceSize kCountBytes = sizeof(std::uint32_t) * kStageCounts * (1 + kMostProcessors);
  DB_ASSIGN_OR_RETURN(
      VulkanBuffer counts,
      context_->CreateHostBuffer(kCountBytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                 HostAccess::kReadback));
  const VkDescriptorBufferInfo counts_info{counts.handle(), 0, kCountBytes};
  VkWriteDescriptorSet write{};
  write.dstBinding = 0;
  write.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  write.pBufferInfo = &counts_info;
  probe->WriteDescriptors(std::span(&write, 1));

  struct Row {
    const char* name;
    std::uint32_t stage;
    DeviceObject<VkPipeline> pipeline;
  };
  std::vector<Row> rows;
  rows.push_back({"compute", 0, {}});
  if (vertex) rows.push_back({"vertex", 1, {}});
  if (fragment) rows.push_back({"fragment", 2, {}});
  VkRenderingInfo rendering{};
  rendering.sType = VK_STRUCTURE_TYPE_RENDERING_INFO;
  rendering.renderArea = {{0, 0}, {size.width, size.height}};
  rendering.layerCount = 1;
  const VkViewport viewport{0.0f, 0.0f, static_cast<float>(size.width), static_cast<float>(size.height), 0.0f, 1.0f};
  const Recorder record = [&](VkCommandBuffer commands, VkPipeline pipeline, std::uint32_t passes) {
    const Row& row =
        *std::find_if(rows.begin(), rows.end(), [&](const Row& r) { return r.pipeline.get() == pipeline; });
    const StagePush push{row.stage, size.width};
    const bool draw = row.stage != 0;
    probe->Bind(commands, pipeline, draw ? VK_PIPELINE_BIND_POINT_GRAPHICS : VK_PIPELINE_BIND_POINT_COMPUTE);
    probe->PushConstants(commands, &push, sizeof(push));
    for (std::uint32_t p = 0; p < passes; ++p) {
      if (draw) {
        vkCmdBeginRendering(commands, &rendering);
        vkCmdSetViewport(commands, 0, 1, &viewport);
        vkCmdSetScissor(commands, 0, 1, &rendering.renderArea);
        vkCmdDraw(commands, row.stage == 1 ? static_cast<std::uint32_t>(invocations) : 3, 1, 0, 0);
        vkCmdEndRendering(commands);
      } else {
        vkCmdDispatch(commands, static_cast<std::uint32_t>(invocations / kStageWorkgroupSize), 1, 1);
      }
      // Each pass waits for the one before, as the timed passes do.
      RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                          VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    }
  };

  // The count of multiply-adds is a constant of each pipeline.
  const VkSpecializationMapEntry iterations_entry{kStageIterationsConstant, 0, sizeof(iterations)};
  const VkSpecializationInfo constants{1, &iterations_entry, sizeof(iterations), &iterations};
  DB_ASSIGN_OR_RETURN(const std::vector<std::uint32_t> compute_spirv,
                      compile("stage_probe.comp", ShaderStage::kCompute));
  DB_ASSIGN_OR_RETURN(rows.front().pipeline,
                      probe->CreatePipeline(compute_spirv, constants, "the stage probe's compute row"));
  if (vertex || fragment) {
    DB_ASSIGN_OR_RETURN(const DeviceObject<VkShaderModule> points_vertex,
                        module("stage_probe_points.vert", ShaderStage::kVertex));
    DB_ASSIGN_OR_RETURN(const DeviceObject<VkShaderModule> screen_vertex,
                        module("stage_probe_screen.vert", ShaderStage::kVertex));
    DB_ASSIGN_OR_RETURN(const DeviceObject<VkShaderModule> probe_fragment,
                        module("stage_probe.frag", ShaderStage::kFragment));
    DrawState state;
    state.fragment = probe_fragment.get();
    state.vertex_constants = &constants;
    state.fragment_constants = &constants;
    for (Row& row : rows) {
      if (row.stage == 0) continue;
      const bool points = row.stage == 1;
      state.vertex = points ? points_vertex.get() : screen_vertex.get();
      state.topology = points ? VK_PRIMITIVE_TOPOLOGY_POINT_LIST : VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
      state.rasterizer_discard = points;
      DB_ASSIGN_OR_RETURN(row.pipeline, CreateGraphicsPipeline(vk_device(), probe->pipeline_layout(), state,
                                                               fmt::format("the stage probe's {} row", row.name)));
    }
  }

  std::vector<VkPipeline> pipelines;
  for (const Row& row : rows) pipelines.push_back(row.pipeline.get());
  DB_ASSIGN_OR_RETURN(std::vector<PassTiming> timings, TimeInterleaved(*probe, pipelines, record, warmup, repetitions));
  DB_RETURN_IF_ERROR(probe->Submit([&](VkCommandBuffer commands) {
    vkCmdFillBuffer(commands, counts.handle(), 0, kCountBytes, 0);
    RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                        VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    for (const VkPipeline pipeline : pipelines) record(commands, pipeline, 1);
    RecordMemoryBarrier(commands, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                        VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
  }));
  DB_RETURN_IF_ERROR(counts.InvalidateForHostReads());
  DB_RETURN_IF_ERROR(validation.Check("the stage probe"));
  const auto* const counted = static_cast<const std::uint32_t*>(counts.mapped());
  for (std::size_t r = 0; r < rows.size(); ++r) {
    StageTiming stage{rows[r].name, std::move(timings[r]), counted[rows[r].stage], 0};
    const std::uint32_t* const by_processor = counted + kStageCounts + rows[r].stage * kMostProcessors;
    stage.processors_used = static_cast<std::uint32_t>(
        std::count_if(by_processor, by_processor + (result.processors > 0 ? kMostProcessors : 0),
                      [](std::uint32_t n) { return n > 0; }));
    result.stages.push_back(std::move(stage));
  }
  return result;
}

}  // namespace depthbench
