// The shared/ formulas compiled as C++, twice:
//   depthbench::f32  float32 with GLM: what the CPU backend runs (built with
//                    -ffp-contract=off, so every operation rounds as written);
//   depthbench::hp   DoubleDouble: the exact constants and the reference.
// The third compilation is GLSL (shaders/, through glslang at run time).
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "bench/double_double.h"
#include "shared/compat.h"

// Formulas take parameters they do not all use (one signature for all
// variants) and use bool-returning comparisons GLSL-style.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"

namespace depthbench::f32 {
using real = float;
using uint = std::uint32_t;
using vec2 = glm::vec2;
using vec3 = glm::vec3;
using vec4 = glm::vec4;
using mat4 = glm::mat4;
#include "bench/formulas_body.inc"
}  // namespace depthbench::f32

namespace depthbench::hp {
using real = DoubleDouble;
using uint = std::uint32_t;
using vec2 = glm::vec<2, DoubleDouble>;
using vec3 = glm::vec<3, DoubleDouble>;
using vec4 = glm::vec<4, DoubleDouble>;
using mat4 = glm::mat<4, 4, DoubleDouble>;
#include "bench/formulas_body.inc"
}  // namespace depthbench::hp

#pragma GCC diagnostic pop

namespace depthbench {

// The std430 contract: these sizes are what the shaders' buffers index by.
static_assert(sizeof(f32::FrameParams) == 15 * 16 + 64, "FrameParams std430 size");
static_assert(sizeof(f32::DepthParams) == 64 + 16 + 16, "DepthParams std430 size");
static_assert(sizeof(f32::PassConstants) == 32, "PassConstants size");

}  // namespace depthbench
