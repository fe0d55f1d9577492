// Probes of a GPU's float32 arithmetic: rewrites of a compiled SPIR-V
// module that take one freedom away from the driver's compiler, so that a
// run with and without the rewrite measures what that freedom costs.
//
//   no-contraction: every floating-point arithmetic result is decorated
//     NoContraction (what GLSL's `precise` does), so a multiply and an add
//     stay two roundings instead of becoming one fused multiply-add;
//   exact-division: every float32 division becomes a float64 division of
//     the widened operands, rounded once to float32: the correctly rounded
//     quotient (Vulkan lets a float32 division be off by 2.5 ulp; a float64
//     quotient rounded to float32 is wrong only when the exact quotient lies
//     within about 2^-29 ulp of a rounding midpoint);
//   worst-division: that correctly rounded quotient then moved two steps
//     of its bits away from zero: 2 to 2.5 ulp from the exact quotient,
//     every time, the same way. A device that uses the whole tolerance
//     Vulkan allows a division (an infinite quotient becomes NaN), which is
//     what a bound's division rule must cover (bench/bound).
//
// And one probe of the raster form's inputs, which rewrites nothing:
//
//   compute-attributes: the reconstruction's fragment gets the screen
//     attributes (the rays, the light volume's position) as the compute
//     form computes them at the pixel from the frame's constants, in place
//     of what the rasterizer interpolated (vulkan/raster_pass.h), so that
//     a run with and without it measures what the interpolation costs.
//
// The Vulkan backend applies them when its name says so
// ("vulkan:no-contraction", "vulkan:exact-division", "vulkan:worst-division",
// "vulkan:compute-attributes", or several joined by '+').
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "bench/base/status.h"

namespace depthbench {

enum ArithmeticProbe : std::uint32_t {
  kNoContraction = 1u << 0,
  kExactDivision = 1u << 1,
  kWorstDivision = 1u << 2,
  kComputeAttributes = 1u << 3,  // the raster form's; ApplyArithmeticProbes leaves it alone
};

// "no-contraction+exact-division" <-> bits; "" for none.
Expected<std::uint32_t> ParseArithmeticProbes(std::string_view text);
std::string ArithmeticProbesName(std::uint32_t probes);

// The module with the probes applied. InvalidArgument when the words are not
// a SPIR-V module.
Expected<std::vector<std::uint32_t>> ApplyArithmeticProbes(std::span<const std::uint32_t> spirv, std::uint32_t probes);

}  // namespace depthbench
