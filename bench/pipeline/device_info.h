// DeviceInfo: what results record about the device a backend ran on. A
// plain record, so that readers of results need nothing of the backends.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace depthbench {

// What kind of processor runs a device's work: a CPU (the CPU backend, and
// software Vulkan such as lavapipe) or a GPU.
enum class DeviceKind : std::uint8_t { kCpu, kGpu };
inline const char* DeviceKindName(DeviceKind kind) { return kind == DeviceKind::kGpu ? "gpu" : "cpu"; }
inline std::optional<DeviceKind> ParseDeviceKind(std::string_view name) {
  if (name == "cpu") return DeviceKind::kCpu;
  if (name == "gpu") return DeviceKind::kGpu;
  return std::nullopt;
}

// What runs a cell's formulas: depthbench's own float32 build of them on
// the CPU (GLM), or a Vulkan device's shaders. A backend's name is its
// kind's ("cpu", "vulkan"), or, for the Vulkan backend with arithmetic
// probes, "vulkan:" and the probes ("vulkan:no-contraction"); results keep
// the whole name, and ask for the kind through BackendKindOf.
enum class BackendKind : std::uint8_t { kCpu, kVulkan };
inline const char* BackendKindName(BackendKind kind) { return kind == BackendKind::kVulkan ? "vulkan" : "cpu"; }
// The kind of the backend named `name`; nullopt for a name of neither.
inline std::optional<BackendKind> BackendKindOf(std::string_view name) {
  if (name == "cpu") return BackendKind::kCpu;
  if (name == "vulkan" || name.starts_with("vulkan:")) return BackendKind::kVulkan;
  return std::nullopt;
}

struct DeviceInfo {
  std::string name;    // "llvmpipe (LLVM 15.0.6, 256 bits)", "cpu"
  std::string driver;  // "Mesa 22.3.6", "GLM float32, -ffp-contract=off"
  std::string api;     // "Vulkan 1.3.230"
  DeviceKind kind = DeviceKind::kCpu;
  std::string compiler;  // how the formulas were compiled ("glslang 12.0.0", "g++ 12.2.0")
};

// What a backend's formulas were built from: two runs ran the same program
// exactly when `hash` is the same (results of different programs must not
// be added up).
struct ProgramInfo {
  std::string shaders;  // the shader directory as given ("default": the installed one); "built-in" for the CPU
  std::string hash;     // "fnv1a64:..." of every shader source compiled, includes too; the CPU: "depthbench VERSION"
  friend bool operator==(const ProgramInfo&, const ProgramInfo&) = default;
};

}  // namespace depthbench
