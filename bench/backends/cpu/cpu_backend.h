// The CPU backend: the shared/ formulas compiled as C++ float32 with GLM,
// built with -ffp-contract=off so that every operation rounds as the source
// reads. It runs the eight-lane instantiation (namespace f32x8), whose
// lanes compute exactly what the scalar one (f32) computes.
#pragma once

#include <memory>

#include "bench/backends/backend.h"

namespace depthbench {

std::unique_ptr<Backend> MakeCpuBackend();

}  // namespace depthbench
