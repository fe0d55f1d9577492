// Graphics pipelines as the bench draws them: the vertex stage fetches its
// own vertices (no vertex input), one sample a pixel, dynamic rendering
// (Vulkan 1.3) into the attachments named, viewport and scissor set when
// drawing. The raster form's passes and the speed timer's stage probe make
// theirs here.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "bench/backends/vulkan/vulkan_context.h"
#include "bench/base/status.h"

namespace depthbench {

// What one graphics pipeline differs in.
struct DrawState {
  VkShaderModule vertex = VK_NULL_HANDLE;
  VkShaderModule fragment = VK_NULL_HANDLE;
  const VkSpecializationInfo* vertex_constants = nullptr;
  const VkSpecializationInfo* fragment_constants = nullptr;
  std::vector<VkFormat> colors;
  VkFormat depth = VK_FORMAT_UNDEFINED;  // a depth attachment, tested ALWAYS and written
  VkPrimitiveTopology topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  std::uint32_t viewports = 1;      // and as many scissors; the vertex stage picks one
  bool clip_minus_one = false;      // GL-style clip depth (VK_EXT_depth_clip_control)
  bool light_volume = false;        // back faces only, depth clamped rather than clipped
  bool rasterizer_discard = false;  // the vertex stage alone runs
};

// A pipeline of `state` over `layout`; `what` names it in errors.
Expected<DeviceObject<VkPipeline>> CreateGraphicsPipeline(VkDevice device, VkPipelineLayout layout,
                                                          const DrawState& state, const std::string& what);

}  // namespace depthbench
