// MakeBackend: the one place that maps a backend's name to its factory.
#pragma once

#include <memory>
#include <string>

#include "bench/backends/backend.h"

namespace depthbench {

// A backend by name ("cpu" or "vulkan"); InvalidArgument naming the
// available ones otherwise.
Expected<std::unique_ptr<Backend>> MakeBackend(const std::string& name, const BackendOptions& options);

}  // namespace depthbench
