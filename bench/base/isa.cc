#include "bench/base/isa.h"

namespace depthbench {

bool ProcessorRuns(Isa isa) {
  switch (isa) {
    case Isa::kWidest:
    case Isa::kBaseline: return true;
    case Isa::kAvx512: {
      static const bool has = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                              __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw") &&
                              __builtin_cpu_supports("avx512cd");
      return has;
    }
  }
  return false;
}

Isa Resolve(Isa isa) {
  if (isa != Isa::kWidest) return isa;
  return ProcessorRuns(Isa::kAvx512) ? Isa::kAvx512 : Isa::kBaseline;
}

}  // namespace depthbench
