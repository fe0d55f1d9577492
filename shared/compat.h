// The one file of shared/ that knows whether it is being compiled as GLSL 450,
// as C++ or (for the programs around a user's HLSL function, shaders/user/)
// as HLSL, which defines DB_HLSL first. Everything else in shared/ is written
// in the common subset:
//   - scalars are `real` (float in GLSL and in the CPU backend, a double-double
//     in the high-precision reference) and `uint`;
//   - vectors and matrices are vec2/vec3/vec4/mat4 (GLM types in C++);
//   - a matrix times a vector or matrix is DB_MUL(m, v) (HLSL's `*` is
//     element by element);
//   - functions are declared with DB_FN, take their arguments by value and
//     return one value (no out/inout), use no swizzles, and use only
//     built-ins that GLM also has;
//   - literals are f-suffixed and exactly representable, and are wrapped in
//     real(...) where they meet a vector, so that every instantiation rounds
//     them the same way (not at all).
// Formula headers carry no include guard: C++ includes each of them once per
// precision namespace (see bench/numerics/formulas.h), GLSL once per shader.
#ifndef DEPTHBENCH_SHARED_COMPAT_H
#define DEPTHBENCH_SHARED_COMPAT_H

#ifdef __cplusplus

#include <bit>
#include <cstdint>

#include <glm/glm.hpp>

// Inlined everywhere, as a shader compiler inlines: the SIMD
// instantiations then keep their lanes in registers across calls.
#define DB_FN inline __attribute__((always_inline))
// Carries its own ';' in C++; expands to nothing in GLSL, where a stray ';'
// at file scope is an error. Use it without a trailing ';'.
#define DB_STATIC_ASSERT(condition, message) static_assert(condition, message);
// A named integer constant: `const uint` in both languages.
#define DB_CONST_UINT(name, value) [[maybe_unused]] constexpr std::uint32_t name = value;
#define DB_MUL(m, v) ((m) * (v))
// The double with these high and low 32 bits, exactly.
#define DB_DOUBLE_BITS(high, low) std::bit_cast<double>(std::uint64_t{high} << 32 | (low))
// Keeps a compiler from fusing this variable's products into adds: C++
// is built with -ffp-contract=off, GLSL and HLSL need the qualifier.
#define DB_PRECISE

#elif defined(DB_HLSL)

#define DB_FN
#define DB_STATIC_ASSERT(condition, message)
#define DB_CONST_UINT(name, value) static const uint name = value;
#define DB_MUL(m, v) mul(m, v)
#define DB_DOUBLE_BITS(high, low) asdouble(low, high)
#define DB_PRECISE precise
#define real float
#define vec2 float2
#define vec3 float3
#define vec4 float4
#define mat4 float4x4

#else  // GLSL

#define DB_FN
#define DB_STATIC_ASSERT(condition, message)
#define DB_CONST_UINT(name, value) const uint name = value;
#define DB_MUL(m, v) ((m) * (v))
#define DB_DOUBLE_BITS(high, low) packDouble2x32(uvec2(low, high))
#define DB_PRECISE precise
#define real float

#endif

#endif  // DEPTHBENCH_SHARED_COMPAT_H
