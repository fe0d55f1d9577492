#include "bench/backends/factory.h"

#include "bench/backends/cpu/cpu_backend.h"
#include "bench/backends/vulkan/arithmetic_probe.h"
#include "bench/backends/vulkan/vulkan_backend.h"

namespace depthbench {

Expected<std::unique_ptr<Backend>> MakeBackend(const std::string& name, const BackendOptions& options) {
  if (name == BackendKindName(BackendKind::kCpu)) return MakeCpuBackend();
  if (name == BackendKindName(BackendKind::kVulkan)) return MakeVulkanBackend(options);
  // "vulkan:no-contraction", "vulkan:exact-division+no-contraction": the
  // Vulkan backend with arithmetic probes (backends/vulkan/arithmetic_probe.h).
  if (name.starts_with("vulkan:")) {
    BackendOptions probed = options;
    DB_ASSIGN_OR_RETURN(probed.arithmetic_probes, ParseArithmeticProbes(std::string_view(name).substr(7)));
    if (probed.arithmetic_probes == 0) return InvalidArgument("--backend vulkan: names no arithmetic probe");
    return MakeVulkanBackend(probed);
  }
  return InvalidArgument("unknown backend '" + name +
                         "'; available: cpu, vulkan, and vulkan:PROBES to measure the GPU's arithmetic "
                         "(PROBES: no-contraction, exact-division, worst-division, or several joined by '+')");
}

}  // namespace depthbench
