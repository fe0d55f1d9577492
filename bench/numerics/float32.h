// Rounding a double to float32 and back, which the compiler must not skip.
#pragma once

namespace depthbench {

// x rounded to the nearest float32 (ties to even), as a double. Through a
// volatile float: GCC 12 at -O2 drops a double-to-float-to-double round
// trip whose result goes into a struct's or an array's double members
// (seen in the sampler's vectorised camera loop, and in the bound's
// enclosures of rounded constants); clang keeps it.
inline double NearestFloat32(double x) {
  const volatile float rounded = static_cast<float>(x);
  return rounded;
}

}  // namespace depthbench
