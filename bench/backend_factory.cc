// MakeBackend: the one place that maps a backend's name to its factory.
#include "bench/backend.h"
#include "bench/backend_cpu.h"
#include "bench/vulkan/vulkan_backend.h"

namespace depthbench {

Expected<std::unique_ptr<Backend>> MakeBackend(const std::string& name, const BackendOptions& options) {
  if (name == "cpu") return MakeCpuBackend();
  if (name == "vulkan") return MakeVulkanBackend(options);
  return InvalidArgument("unknown backend '" + name + "'; available: cpu, vulkan");
}

}  // namespace depthbench
