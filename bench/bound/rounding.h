// Rounding-error bounds of float32 arithmetic, one rule per operation, for
// two kinds of machine:
//   any conformant Vulkan device: the specification's "Precision and
//     Operation of SPIR-V Instructions": additions, subtractions and
//     multiplications correctly rounded; a multiply and an add may be
//     fused into one rounding unless decorated NoContraction; division
//     (a reciprocal included: 1/x is a division) within 2.5 ULP of the
//     quotient of its operands, for divisors of magnitude 2^-126 to 2^126;
//     dot products and matrix products inherit the multiply and add rules
//     in an unspecified order; denormals may be flushed to zero.
//   an exactly rounded machine: every operation correctly rounded, as the
//     CPU backend's float32 arithmetic is (built without contraction).
//
// A lane of a computed value is described by an enclosure of the value
// exact arithmetic gives on the exact inputs and a bound on how far the
// float32 value computed from the rounded inputs may lie from it. Each rule
// below is a theorem about that pair; none drops a higher-order term:
//   sum:      |(x~ + y~)(1 + d) - (x + y)| <= ex + ey + u |x~ + y~| + eta
//   product:  |x~ y~ - x y| <= |x| ey + |y| ex + ex ey, then the rounding
//   quotient: |x~ / y~ - x / y| <= ex / |y~| + |x| ey / (|y| |y~|), then the
//             rounding, k ULP of the quotient at most k 2^-23 of it
//   n-term dot product in any order, fused or not:
//             |fl(sum) - sum| <= gamma_n sum |x~_i y~_i| + n eta,
//             gamma_n = n u / (1 - n u) (Higham, Accuracy and Stability of
//             Numerical Algorithms, 2nd ed., section 3.1)
// with u = 2^-24, the unit roundoff. Fusing a multiply and an add removes
// the product's rounding, so the unfused bound covers both. eta covers a
// result in the denormal range rounded or flushed to zero; it is 2^-100,
// not 2^-126, because the analysis runs at a normalized scale (the near
// plane at 1, bench/bound/bound.h) and a frame may be 2^-26 times as
// small.
#pragma once

#include <cmath>
#include <string_view>

#include "bench/numerics/enclosure.h"

namespace depthbench::bound {

inline constexpr double kUnitRoundoff = 0x1p-24;
inline constexpr double kUlpOfValue = 0x1p-23;  // an ULP is at most this times the value's magnitude
inline constexpr double kUnderflow = 0x1p-100;
// The divisor range in which Vulkan's division tolerance holds.
inline constexpr double kLeastDivisor = 0x1p-126;
inline constexpr double kLargestDivisor = 0x1p126;

// Which machine a bound is for.
struct Machine {
  std::string_view name;
  double division_ulps;  // a division's error in ULP of its result
  bool divisor_range;    // whether the division rule holds only for divisors in [2^-126, 2^126]
};
inline constexpr Machine kVulkanDevice{"vulkan", 2.5, true};
inline constexpr Machine kExactlyRounded{"exactly rounded", 0.5, false};

// One float32 lane: the exact value lies in `exact`; the computed one is
// within `error` of it.
struct Lane {
  Enclosure exact;
  double error = 0.0;

  // The largest magnitude the computed value can have.
  double computed_mag() const { return exact.mag() + error; }
  // An exact input: a float32 value the reference uses as is.
  static Lane Exact(const Enclosure& x) { return {x, 0.0}; }
};

// The error after rounding a result whose exact-on-computed-operands value
// is within `propagated` of `exact`, to within `ulps` ULP.
inline double Rounded(const Enclosure& exact, double propagated, double ulps) {
  return propagated + ulps * kUlpOfValue * (exact.mag() + propagated) + kUnderflow;
}

// Whether x is a power of two, so that multiplying a float by it is exact
// (short of overflow and underflow, which the magnitudes here stay far from).
inline bool PowerOfTwo(const Lane& x) {
  if (x.error != 0.0 || x.exact.lo != x.exact.hi || x.exact.lo == 0.0) return false;
  int exponent = 0;
  return std::fabs(std::frexp(x.exact.lo, &exponent)) == 0.5;
}

// Whether every x + y of the two ranges is a float when x and y are
// floats: one of them is 0, or they have opposite signs and within a factor
// of two of each other in magnitude (Sterbenz's lemma), as -1 + 2 d is for a
// stored depth d in [0.25, 1].
inline bool SumIsExact(const Enclosure& x, const Enclosure& y) {
  if (x == Enclosure(0.0) || y == Enclosure(0.0)) return true;
  const bool opposite = (x.lo > 0.0 && y.hi < 0.0) || (x.hi < 0.0 && y.lo > 0.0);
  return opposite && 2.0 * x.mig() >= y.mag() && 2.0 * y.mig() >= x.mag();
}

inline Lane Add(const Lane& x, const Lane& y) {
  const Enclosure exact = x.exact + y.exact;
  // Lanes without error hold floats (inputs, literals, exact results).
  if (x.error == 0.0 && y.error == 0.0 && SumIsExact(x.exact, y.exact)) return {exact, 0.0};
  return {exact, Rounded(exact, x.error + y.error, 0.5)};
}
inline Lane Negate(const Lane& x) { return {-x.exact, x.error}; }
inline Lane Subtract(const Lane& x, const Lane& y) { return Add(x, Negate(y)); }

inline Lane Multiply(const Lane& x, const Lane& y) {
  const Enclosure exact = x.exact * y.exact;
  const double propagated = x.exact.mag() * y.error + y.exact.mag() * x.error + x.error * y.error;
  if (PowerOfTwo(x) || PowerOfTwo(y)) return {exact, propagated};
  return {exact, Rounded(exact, propagated, 0.5)};
}

// Division: the error, or a negative error when the divisor may be zero
// or lie outside the range where `machine`'s rule holds.
inline Lane Divide(const Lane& x, const Lane& y, const Machine& machine) {
  const double least = y.exact.mig() - y.error;  // the smallest |y~|
  if (!(least > 0.0)) return {Enclosure::Whole(), -1.0};
  if (machine.divisor_range && (least < kLeastDivisor || y.computed_mag() > kLargestDivisor)) {
    return {Enclosure::Whole(), -1.0};
  }
  const Enclosure exact = x.exact / y.exact;
  const double propagated = x.error / least + x.exact.mag() * y.error / (y.exact.mig() * least);
  return {exact, Rounded(exact, propagated, machine.division_ulps)};
}

// sum over i of x[i] * y[i], n terms, in any order, fused or not.
template <class Lanes>
Lane Dot(const Lanes& x, const Lanes& y, int n) {
  Enclosure exact(0.0);
  double propagated = 0.0, magnitude = 0.0;
  for (int i = 0; i < n; ++i) {
    exact = exact + x[i].exact * y[i].exact;
    propagated += x[i].exact.mag() * y[i].error + y[i].exact.mag() * x[i].error + x[i].error * y[i].error;
    magnitude += x[i].computed_mag() * y[i].computed_mag();
  }
  const double gamma = n * kUnitRoundoff / (1.0 - n * kUnitRoundoff);
  return {exact, propagated + gamma * magnitude + n * kUnderflow};
}

}  // namespace depthbench::bound
