#include "bench/backends/factory.h"

#include "bench/backends/cpu/cpu_backend.h"
#include "bench/backends/vulkan/vulkan_backend.h"

namespace depthbench {

Expected<std::unique_ptr<Backend>> MakeBackend(const std::string& name, const BackendOptions& options) {
  if (name == "cpu") return MakeCpuBackend();
  if (name == "vulkan") return MakeVulkanBackend(options);
  return InvalidArgument("unknown backend '" + name + "'; available: cpu, vulkan");
}

}  // namespace depthbench
