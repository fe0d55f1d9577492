// How the bench's storage formats are held in Vulkan images: shared by the
// raster form of the backend, which renders into them, and the speed
// timer, which uploads them.
#pragma once

#include <vulkan/vulkan.h>

#include "bench/pipeline/cells.h"

namespace depthbench {

// The Vulkan format a bench format is stored in, and whether it is a depth
// format (rendered and sampled through the depth aspect).
VkFormat VulkanFormatOf(Format format);
bool IsDepthFormat(Format format);

}  // namespace depthbench
