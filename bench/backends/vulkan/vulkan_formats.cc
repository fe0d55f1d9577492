#include "bench/backends/vulkan/vulkan_formats.h"

namespace depthbench {

VkFormat VulkanFormatOf(Format format) {
  switch (format) {
    case Format::kD16Unorm: return VK_FORMAT_D16_UNORM;
    case Format::kX8D24Unorm: return VK_FORMAT_X8_D24_UNORM_PACK32;
    case Format::kD32Sfloat: return VK_FORMAT_D32_SFLOAT;
    case Format::kR32Sfloat: return VK_FORMAT_R32_SFLOAT;
    case Format::kR16Sfloat: return VK_FORMAT_R16_SFLOAT;
    case Format::kR16Unorm: return VK_FORMAT_R16_UNORM;
    case Format::kR32SfloatViewZ: return VK_FORMAT_R32_SFLOAT;
  }
  return VK_FORMAT_UNDEFINED;
}

bool IsDepthFormat(Format format) { return Info(format).stores == DepthInput::kHardware; }

}  // namespace depthbench
