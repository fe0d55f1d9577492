// The depth mapping of shared/depth_mapping.h compiled a fourth time, with
// MPFR reals (MpfrReal::kPrecision bits): the independent high-precision
// evaluation that checks the double-double reference and settles rounding
// decisions the double-double cannot.
#pragma once

#include <cstdint>
#include <utility>

#include "bench/numerics/mpfr_real.h"
#include "shared/compat.h"

namespace depthbench::mp {
using real = MpfrReal;
using uint = std::uint32_t;
// Plain holders: the mapping only builds and reads vectors. The constructor
// is spelled out because clang 14 (the fuzz and sanitizer compiler) lacks
// C++20's parenthesised initialisation of aggregates, which vec2(a, b) needs.
struct vec2 {
  vec2() = default;
  vec2(real x_in, real y_in) : x(std::move(x_in)), y(std::move(y_in)) {}
  real x, y;
};
struct vec4 {
  real x, y, z, w;
};
struct mat4 {
  vec4 columns[4];
};
// The depth mapping needs the parameter blocks first.
// clang-format off
#include "shared/params.h"
#include "shared/depth_mapping.h"
// clang-format on
}  // namespace depthbench::mp
