// GpuPassTimer: times full-screen compute passes (shaders/speed/) on one
// Vulkan device with timestamp queries.
//
// Lifecycle:
//   1. Create(context, shader_dir) on an existing VulkanContext;
//   2. LoadImage(image): uploads a depth image of one encoding into a
//      device-local VkImage of its real format (a depth format as a sampled
//      depth image) and the frame's constants into a uniform buffer;
//   3. TimePasses(variants, taps, ...) any number of times: the variants'
//      passes over the loaded image, taps reconstructions per pixel, timed.
// Pipelines are built on first use, one per (variant, convention, taps).
// MeasureBandwidth, at any time, times the device's memory bandwidth with
// the same machinery (shaders/speed/bandwidth.comp): what a memory-bound
// pass can at best reach, for the memory-bound floor. MeasureStages, at
// any time, times the same arithmetic in the compute, vertex and fragment
// stages (shaders/speed/stage_probe.glsl): whether a pass drawn by the
// rasterizer computes as fast as the compute passes timed here.
//
// How passes are timed: the variants that compete (those reading the
// loaded image) are timed together, interleaved, so that a slow drift of
// the device (clocks, temperature, other work on a CPU device) reaches
// all of them alike and shows in each one's spread rather than between
// their medians. First `warmup` rounds of one pass of each variant (also
// the estimate of each one's pass time), then more rounds until at least
// kMinWarmupNs of device time has run, so that a real GPU has left its
// idle clocks; then `repetitions` rounds, each timing one group per
// variant of enough back-to-back passes to last about kMinGroupNs (one on
// a slow device). Passes are separated by barriers, as an engine's passes
// are. Each group is bracketed by two bottom-of-pipe timestamps: the first
// is written when everything before it has finished, the second when the
// group has; their difference, in the device's timestampPeriod, divided by
// the group's passes, is one repetition's time per pass.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <tuple>
#include <vector>

#include <vulkan/vulkan.h>

#include "bench/backends/vulkan/compute_pass.h"
#include "bench/backends/vulkan/timestamps.h"
#include "bench/backends/vulkan/vulkan_context.h"
#include "bench/backends/vulkan/vulkan_formats.h"
#include "bench/base/status.h"
#include "bench/pipeline/cells.h"
#include "bench/speed/depth_image.h"

namespace depthbench {

// Ok when `features` (the device's optimal-tiling features of the format)
// allow sampling the image and copying into it; otherwise Unavailable,
// naming the format, the device and what is missing.
Status CheckFormatFeatures(Format format, VkFormatFeatureFlags features, const std::string& device_name);

struct PassTiming {
  std::vector<double> ns_per_pass;  // one value per repetition
  std::uint32_t passes_per_repetition = 1;
  std::uint32_t warmup_passes = 0;
};

// A timed copy between two device-local storage buffers: every pass reads
// `bytes_read` and writes as many.
struct BandwidthTiming {
  std::uint64_t bytes_read = 0, bytes_written = 0;  // per pass
  PassTiming timing;
};

// One shader stage's run of the stage probe (MeasureStages).
struct StageTiming {
  std::string stage;  // "compute", "vertex" or "fragment"
  PassTiming timing;
  // Invocations the stage counted in one pass (every pixel once: width *
  // height), and how many processors ran them (0: the device does not name
  // its processors).
  std::uint64_t invocations = 0;
  std::uint32_t processors_used = 0;
};

// The same arithmetic in each shader stage, timed as the passes are.
struct StageTimings {
  Resolution size{0, 0};  // a pass's invocations: size.width * size.height
  std::uint32_t fma_per_invocation = 0;
  std::uint32_t processors = 0;       // the device's (shaderSMCount); 0: not named
  std::vector<StageTiming> stages;    // compute, vertex, fragment; those the device can run
  std::vector<std::string> left_out;  // a stage not measured, and why
};

class GpuPassTimer {
 public:
  static constexpr double kMinWarmupNs = 20e6;
  static constexpr double kMinGroupNs = 1e6;
  static constexpr std::uint32_t kMaxPassesPerGroup = 4096;
  static constexpr std::uint32_t kMaxTaps = 64;
  // The bandwidth probe's buffers: each far larger than any GPU's last-level
  // cache (50 MB on an H100 or H200), so that the copy runs from memory.
  static constexpr std::uint64_t kBandwidthProbeBytes = std::uint64_t{256} << 20;

  static Expected<std::unique_ptr<GpuPassTimer>> Create(std::shared_ptr<VulkanContext> context,
                                                        std::filesystem::path shader_dir);
  GpuPassTimer(const GpuPassTimer&) = delete;
  GpuPassTimer& operator=(const GpuPassTimer&) = delete;

  const VulkanDeviceProperties& device() const { return context_->properties(); }
  double timestamp_period_ns() const { return context_->properties().limits.timestampPeriod; }

  // Ok when the device can sample `format` (CheckFormatFeatures).
  Status CheckFormat(Format format) const;
  // Replaces the loaded image.
  Status LoadImage(const DepthImage& image);
  // One PassTiming per variant, in order. InvalidArgument when a variant
  // does not read the loaded image's encoding (the pairing rule), when
  // there is none, when taps is 0 or above kMaxTaps, or when warmup or
  // repetitions is 0. A timer compiles each variant once, by its id: the
  // variants it times are of one catalogue.
  Expected<std::vector<PassTiming>> TimePasses(std::span<const VariantInfo> variants, std::uint32_t taps,
                                               std::uint32_t warmup, std::uint32_t repetitions);
  // The same for one variant.
  Expected<PassTiming> TimePass(const VariantInfo& variant, std::uint32_t taps, std::uint32_t warmup,
                                std::uint32_t repetitions);
  // The values the last pass wrote, one per pixel (for tests).
  Expected<std::vector<float>> ReadResults();

  // The device's memory bandwidth: a copy of `bytes` (at most; fewer where
  // the device binds or holds less, see the result) from one device-local
  // storage buffer to another, timed as TimePasses times one variant. The
  // buffers live for the call only. InvalidArgument when bytes is below
  // 1 MiB or warmup or repetitions is 0.
  Expected<BandwidthTiming> MeasureBandwidth(std::uint64_t bytes, std::uint32_t warmup, std::uint32_t repetitions);

  // How fast each shader stage computes: `size` invocations of
  // shaders/speed/stage_probe.glsl, each 4 * `iterations` fused
  // multiply-adds, as a compute dispatch, as the vertex stage of as many
  // points (the rasterizer discarding them) and as the fragment stage of a
  // full-screen triangle over `size`, interleaved and timed as TimePasses
  // times variants. A stage the device cannot run so (no graphics queue, no
  // stores from it) is left out, with the reason. InvalidArgument when a
  // side of `size` is 0 or past the device's viewport or framebuffer, when
  // the invocations are not whole workgroups of 64 (or more of them than a
  // dispatch may hold), when iterations is 0 or above 16384, or when
  // warmup or repetitions is 0.
  Expected<StageTimings> MeasureStages(Resolution size, std::uint32_t iterations, std::uint32_t warmup,
                                       std::uint32_t repetitions);

 private:
  explicit GpuPassTimer(std::shared_ptr<VulkanContext> context, std::filesystem::path shader_dir);
  VkDevice vk_device() const { return context_->device(); }

  Expected<VkPipeline> Pipeline(const VariantInfo& variant, Convention convention, std::uint32_t taps);
  // A buffer of `bytes` in device-local memory, bound to it; the buffer is
  // declared after its memory, so that it is destroyed first.
  struct BoundBuffer {
    DeviceObject<VkDeviceMemory> memory;
    DeviceObject<VkBuffer> buffer;
  };
  Expected<BoundBuffer> CreateBoundBuffer(VkDeviceSize bytes, VkBufferUsageFlags usage) const;
  Status CreateImage(const DepthImage& image);
  Status CreateResultBuffer(VkDeviceSize bytes);
  void WriteDescriptors();
  // `passes` passes of `pipeline` with barriers between them.
  void RecordPasses(VkCommandBuffer commands, VkPipeline pipeline, std::uint32_t passes) const;
  // Records `passes` passes of a pipeline of some compute pass.
  using Recorder = std::function<void(VkCommandBuffer, VkPipeline, std::uint32_t)>;
  // A group: `passes` back-to-back passes of one pipeline.
  struct Group {
    VkPipeline pipeline;
    std::uint32_t passes;
  };
  // Times the groups in order, in one submission of `pass`; ns per pass per
  // group.
  Expected<std::vector<double>> TimeGroups(ComputePass& pass, std::span<const Group> groups, const Recorder& record);
  // The schedule of TimePasses (see the top of this file) for `pipelines`
  // of `pass`, recorded by `record`.
  Expected<std::vector<PassTiming>> TimeInterleaved(ComputePass& pass, std::span<const VkPipeline> pipelines,
                                                    const Recorder& record, std::uint32_t warmup,
                                                    std::uint32_t repetitions);

  std::shared_ptr<VulkanContext> context_;  // first: everything below belongs to its device
  std::filesystem::path shader_dir_;

  // The constants, the image and the results of speed_pass.glsl; the pass
  // size pushed.
  std::unique_ptr<ComputePass> pass_;
  DeviceObject<VkSampler> sampler_;
  TimestampQueries queries_;  // grown as groups need

  std::map<Variant, std::vector<std::uint32_t>> spirv_;  // compiled once per variant
  std::map<std::tuple<Variant, Convention, std::uint32_t>, DeviceObject<VkPipeline>> pipelines_;

  // The loaded image and what its passes use. Views before images before
  // memory, so that destruction runs the other way.
  bool loaded_ = false;
  Encoding encoding_{};
  Resolution resolution_{0, 0};
  VulkanImage image_;
  VulkanBuffer constants_;
  DeviceObject<VkDeviceMemory> result_memory_;
  DeviceObject<VkBuffer> result_buffer_;
  VkDeviceSize result_bytes_ = 0;
};

}  // namespace depthbench
