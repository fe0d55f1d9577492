// The CPU backend: the shared/ formulas compiled as C++ float32 with GLM
// (namespace f32), built with -ffp-contract=off so that every operation
// rounds as the source reads.
#pragma once

#include <memory>

#include "bench/backend.h"

namespace depthbench {

std::unique_ptr<Backend> MakeCpuBackend();

}  // namespace depthbench
