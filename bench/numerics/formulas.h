// The shared/ formulas compiled as C++, twice:
//   depthbench::f32  float32 with GLM: the CPU backend's arithmetic (built
//                    with -ffp-contract=off, so every operation rounds as
//                    written);
//   depthbench::f32x8  the same with eight float32 lanes per `real`: what
//                    the CPU backend runs, bit for bit equal to f32 per lane;
//   depthbench::ld   long double (64-bit significand on x86-64): the
//                    reference's per-sample work, which needs more than
//                    double but must stay fast;
//   depthbench::hp   DoubleDouble (about 106 bits): the exact shader
//                    constants, rounding decisions too close to call in
//                    long double, and the formula tests;
//   depthbench::hp4  the parameter blocks and the depth mapping with four
//                    DoubleDouble lanes: the reference's decode of stored
//                    depths, four samples at a time, and the exact shader
//                    constants of four frames at once.
//   depthbench::iv   the parameter blocks and the depth mapping in
//                    interval arithmetic: enclosures of the exact shader
//                    constants over a box of frames (bench/bound/).
// The third compilation is GLSL (shaders/, through glslang at run time).
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "bench/base/simd.h"
#include "bench/numerics/double_double.h"
#include "bench/numerics/enclosure.h"
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
#include "bench/numerics/formulas_body.inc"
}  // namespace depthbench::f32

namespace depthbench::f32x8 {
using real = Float8;
using uint = std::uint32_t;
using vec2 = glm::vec<2, Float8>;
using vec3 = glm::vec<3, Float8>;
using vec4 = glm::vec<4, Float8>;
using mat4 = glm::mat<4, 4, Float8>;
#include "bench/numerics/formulas_body.inc"
}  // namespace depthbench::f32x8

namespace depthbench::ld {
using real = long double;
using uint = std::uint32_t;
using vec2 = glm::vec<2, long double>;
using vec3 = glm::vec<3, long double>;
using vec4 = glm::vec<4, long double>;
using mat4 = glm::mat<4, 4, long double>;
#include "bench/numerics/formulas_body.inc"
}  // namespace depthbench::ld

namespace depthbench::hp {
using real = DoubleDouble;
using uint = std::uint32_t;
using vec2 = glm::vec<2, DoubleDouble>;
using vec3 = glm::vec<3, DoubleDouble>;
using vec4 = glm::vec<4, DoubleDouble>;
using mat4 = glm::mat<4, 4, DoubleDouble>;
#include "bench/numerics/formulas_body.inc"
}  // namespace depthbench::hp

namespace depthbench::hp4 {
using real = DoubleDouble4;
using uint = std::uint32_t;
using vec2 = glm::vec<2, DoubleDouble4>;
using vec3 = glm::vec<3, DoubleDouble4>;
using vec4 = glm::vec<4, DoubleDouble4>;
using mat4 = glm::mat<4, 4, DoubleDouble4>;
// The depth mapping needs the parameter blocks first.
// clang-format off
#include "shared/params.h"
#include "shared/depth_mapping.h"
// clang-format on
}  // namespace depthbench::hp4

namespace depthbench::iv {
using real = Enclosure;
using uint = std::uint32_t;
using vec2 = glm::vec<2, Enclosure>;
using vec3 = glm::vec<3, Enclosure>;
using vec4 = glm::vec<4, Enclosure>;
using mat4 = glm::mat<4, 4, Enclosure>;
// clang-format off
#include "shared/params.h"
#include "shared/depth_mapping.h"
// clang-format on
}  // namespace depthbench::iv

#pragma GCC diagnostic pop

namespace depthbench {

// The std430 contract: these sizes are what the shaders' buffers index by.
static_assert(sizeof(f32::FrameParams) == 17 * 16 + 2 * 64, "FrameParams std430 size");
static_assert(sizeof(f32::DepthParams) == 2 * 64 + 16 + 16, "DepthParams std430 size");
static_assert(sizeof(f32::PassConstants) == 32, "PassConstants size");
static_assert(sizeof(f32::CellSlice) == 16, "CellSlice std430 size");
static_assert(sizeof(f32::RasterSample) == 4 * 16, "RasterSample std430 size");

}  // namespace depthbench
