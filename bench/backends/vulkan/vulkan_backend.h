// The Vulkan backend: the shaders/ compute shaders, compiled with glslang at
// Prepare time; a Run dispatches once per variant, each of the variant's
// cells in a row of workgroups. Inputs go up and positions come back
// through host-visible buffers; Run waits for the device. Prepared with
// PassKind::kRaster it draws instead (raster_pass.h).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
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

// The texel bits the raster form of a Vulkan backend produced in its last
// Run, laid out as ShaderInputs::codes (0 where it drew nothing); empty for
// any other backend or form. What the device stored, for tests that compare
// the forms on the same stored depths.
std::vector<std::uint32_t> RasterTexels(const Backend& backend);

// Where a Run of the compute form left its positions in device memory:
// component c (x, y, z) of sample i of the k-th cell listed is element
// (k * 3 + c) * slice_length + lead + i of `buffer`'s first `bytes`.
// Elements the shader did not write hold the backend's unwritten-output
// bits (0x7fa00bad).
struct DevicePositions {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceSize bytes = 0;
  std::uint32_t lead = 0;
  std::uint32_t slice_length = 0;
  // The fetched texels the pass read, laid out as the positions are: depth
  // slot s's sample i at s * slice_length + lead + i.
  VkBuffer texels = VK_NULL_HANDLE;
  VkDeviceSize texel_bytes = 0;
  // The pixels the pass read (x | y << 16), sample i at lead + i.
  VkBuffer pixels = VK_NULL_HANDLE;
  VkDeviceSize pixel_bytes = 0;
};
// Where the texels come from when a judge on the device stores them
// itself: called once the backend's buffers are ready for the batch and
// before its pass is queued, with the buffers that pass writes (the
// positions) and reads (the texels, which the writer fills whole, the lead
// and padding as zeros; and the pixels where the batch has none, which
// the writer then fills whole too). It queues work on the device's queue
// that writes them and ends with a barrier before later compute reads.
using TexelWriter = std::function<Status(const DevicePositions&)>;
// Runs the listed cells as Backend::Run does, but leaves their positions on
// the device for a judge there (bench/device_judge/), valid until the
// backend's next run: nothing is read back or checked on the host. `pool`,
// where given, writes the upload. The texels are the batch's stored
// depths, uploaded, or what `write_texels` writes on the device (the
// batch's are then not read). It returns once the work is queued: a later
// submission to the device's queue reads the positions after a barrier;
// the backend's next run waits for it.
// Unavailable for a backend other than Vulkan's and for the raster form.
Expected<DevicePositions> RunLeavingOnDevice(Backend& backend, const ShaderInputs& batch,
                                             std::span<const std::uint32_t> which, ThreadPool* pool = nullptr,
                                             const TexelWriter& write_texels = nullptr);
// The device a Vulkan backend runs on (null for any other backend).
std::shared_ptr<VulkanContext> ContextOf(const Backend& backend);

}  // namespace depthbench
