// The Vulkan backend: the shaders/ compute shaders, compiled with glslang at
// Prepare time; a Run dispatches once per variant, each of the variant's
// cells in a row of workgroups. Inputs go up and positions come back
// through host-visible buffers; Run waits for the device. Prepared with
// PassKind::kRaster it draws instead (raster_pass.h). A judge on the same
// device reaches its runs that leave the positions there through
// Backend::device_resident (DeviceResidentRuns, below).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "bench/backends/backend.h"
#include "bench/backends/vulkan/vulkan_context.h"
#include "bench/base/thread_pool.h"

namespace depthbench {

// A backend on the device that options.device names (lavapipe when empty),
// with validation when options.validation or DEPTHBENCH_VALIDATION=1.
Expected<std::unique_ptr<Backend>> MakeVulkanBackend(const BackendOptions& options);

// A backend on a device the caller created. The caller may keep `context`,
// for instance to read its validation log after the backend is gone;
// options.device and options.validation do not apply (the context decided).
Expected<std::unique_ptr<Backend>> MakeVulkanBackend(std::shared_ptr<VulkanContext> context,
                                                     const BackendOptions& options);

// Why a cell's shader left `unwritten` outputs unwritten ("12 of 1000"),
// in the message that refuses its batch: the host's check and the device
// judge's say the same.
Status UnwrittenOutputs(const Cell& cell, const std::string& unwritten);

// The buffers of a staged run (DeviceResidentRuns),
// in device memory. Its positions: component c (x, y, z) of sample i of
// the k-th cell listed is element (k * 3 + c) * slice_length + lead + i
// of `positions`' first `position_bytes`; an element the shader did not
// write holds the backend's unwritten-output bits (0x7fa00bad).
struct DeviceRunBuffers {
  VkBuffer positions = VK_NULL_HANDLE;
  VkDeviceSize position_bytes = 0;
  std::uint32_t lead = 0;
  std::uint32_t slice_length = 0;
  // The fetched texels the pass reads, laid out as the positions are:
  // depth slot s's sample i at s * slice_length + lead + i.
  VkBuffer texels = VK_NULL_HANDLE;
  VkDeviceSize texel_bytes = 0;
  // The pixels the pass reads (x | y << 16), sample i at lead + i.
  VkBuffer pixels = VK_NULL_HANDLE;
  VkDeviceSize pixel_bytes = 0;
  // The frames' constants the pass reads: the batch's FrameParams, and its
  // DepthParams (kHardwareConventionCount per frame).
  VkBuffer frame_params = VK_NULL_HANDLE;
  VkDeviceSize frame_param_bytes = 0;
  VkBuffer depth_params = VK_NULL_HANDLE;
  VkDeviceSize depth_param_bytes = 0;
  // The raster form's: per texel, laid out as `texels`, whether the
  // rasterizer drew it (shared/params.h's DB_RASTER_TEXEL_*). Null for the
  // compute form, whose texels are all stored.
  VkBuffer texel_status = VK_NULL_HANDLE;
  VkDeviceSize texel_status_bytes = 0;
};

// What a Vulkan backend offers a judge on its device
// (Backend::device_resident): runs whose positions stay in device memory,
// nothing read back or checked on the host. The
// judge sequences each run's steps with its own passes on the device's
// queue; the backend never calls back:
//   1. Stage(batch, which, pool) waits for the backend's last run, uploads
//      what the listed cells' reconstruction reads but the texels (and the
//      pixels, where the batch has none), and returns the run's buffers;
//   2. the caller queues work that writes the texels, whole (the lead and
//      padding as zeros), and the pixels the batch lacks, ending with a
//      barrier before later compute reads;
//   3. QueueStaged() queues the reconstruction and returns: a later
//      submission to the queue reads the positions after a barrier. They
//      stay valid until the backend's next run or Stage, which waits for
//      the pass.
// Or, in place of step 3, the caller runs the reconstruction itself, in
// its own program around each variant's function (CompileJudged), from
// the buffers Stage returned.
// The raster form renders its own texels: Stage uploads what it draws
// (the batch's codes are kept, to count how the device's texels agree
// with them), step 2 has nothing to write, and QueueStaged queues the
// depth pass, the fetch of every texel (into `texels`, with
// `texel_status`) and the reconstruction.
class DeviceResidentRuns {
 public:
  virtual ~DeviceResidentRuns() = default;

  // The device the runs use, for the caller's own passes.
  virtual const std::shared_ptr<VulkanContext>& context() const = 0;
  // `pool`, where given, writes the upload. The batch's stored depths are
  // not read.
  virtual Expected<DeviceRunBuffers> Stage(const ShaderInputs& batch, std::span<const std::uint32_t> which,
                                           ThreadPool* pool) = 0;
  // The staged run's reconstruction, queued; refused where nothing is
  // staged (a Run in between discards what Stage staged).
  virtual Status QueueStaged() = 0;
  // Waits for the run QueueStaged queued, if any, and takes in what the
  // host keeps of it: the raster form's agreement with the host's model
  // (Backend::raster_agreement). Stage does the same for the run before.
  virtual Status FinishQueued() = 0;
  // The device seconds of the finished runs' own parts, in order, where
  // the runs time them (the raster form's: RasterPass::part_seconds).
  virtual std::vector<std::pair<std::string, double>> part_seconds() const { return {}; }
  // `variant`'s function in the device judge's fused program
  // (VariantPass::kJudged), compiled as this backend compiles its own pass:
  // the same source of the function and the same arithmetic probes.
  // Unavailable for a variant the program cannot hold (an HLSL function).
  virtual Expected<std::vector<std::uint32_t>> CompileJudged(const VariantInfo& variant) const = 0;
};

}  // namespace depthbench
