// Isa: the instruction sets the hot loops (the judge, the storage
// statistics, the double-double decode and the reference) are compiled
// for, chosen at run time. The build's baseline (x86-64-v3 where
// the build machine has it) runs everywhere the program runs; AVX-512 runs
// where the processor has it and gives the same results: the loops are
// IEEE operations lane by lane with no contraction, and AVX-512 only adds
// wider and more registers, mask compares and conversions AVX2 lacks. A
// body may take the lane count it is given (4 or 8 doubles, simd.h's
// Lanes) or ignore it: the judge's loops take it; the reference stays at
// four, where eight measured slower, and so does the decode (its
// double-double formulas come through GLM, not measured at eight).
//
// A hot function writes its body as an always_inline function and calls
//   RunWith(isa, [&](auto lanes) __attribute__((always_inline)) {
//     Body<decltype(lanes)::value>(...);
//   });
// RunBaseline and RunAvx512 each get a whole copy of the body, compiled for
// their instruction set; what the body calls and GCC does not inline stays
// baseline code, so AVX-512 instructions never leak into the baseline copy.
#pragma once

#include <type_traits>

namespace depthbench {

enum class Isa {
  kWidest,  // the widest this processor runs
  kBaseline,
  kAvx512,  // AVX-512 F, VL, DQ, BW and CD
};

bool ProcessorRuns(Isa isa);
// kWidest made concrete.
Isa Resolve(Isa isa);

// The body is called with the lane count of its double-precision loops,
// as a std::integral_constant: 4 (256-bit registers) in the baseline copy,
// 8 (512-bit) in the AVX-512 one.
template <class Body>
void RunBaseline(Body body) {
  body(std::integral_constant<int, 4>{});
}

template <class Body>
[[gnu::target("avx512f,avx512vl,avx512dq,avx512bw,avx512cd")]] void RunAvx512(Body body) {
  body(std::integral_constant<int, 8>{});
}

// `isa` must be one the processor runs.
template <class Body>
void RunWith(Isa isa, Body body) {
  if (Resolve(isa) == Isa::kAvx512) {
    RunAvx512(body);
  } else {
    RunBaseline(body);
  }
}

}  // namespace depthbench
