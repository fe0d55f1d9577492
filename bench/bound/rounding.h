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
//
// Where the lanes hold one frame's own values rather than a normalized box
// of them (Machine::at_scale: a single sample's inputs), a lane also
// carries the set of float32 values the machine may compute, operation by
// operation: the rounded results of every operand value, the unrounded
// product beside the rounded one where a multiply may be fused into the
// next add, every order of a dot product's additions, a division's whole
// tolerance, zero for a denormal that may be flushed. At a point that set
// is a handful of floats, and its distance from the exact enclosure bounds
// the error without assuming every rounding at its worst at once; the
// smaller of the two bounds is kept. At a normalized scale the floats are
// not the frame's, and the set is the whole line.
#pragma once

#include <array>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <string_view>

#include "bench/numerics/enclosure.h"
#include "bench/numerics/float32.h"

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
  bool fuses;            // whether a multiply may be fused into the add that reads it
  bool flushes;          // whether a denormal operand or result may be flushed to zero
  bool at_scale = false;  // whether the lanes hold a frame's own values, so that its floats are known
};
inline constexpr Machine kVulkanDevice{"vulkan", 2.5, true, true, true};
inline constexpr Machine kExactlyRounded{"exactly rounded", 0.5, false, false, false};

// The same machine over lanes that hold one frame's own values.
constexpr Machine AtScale(Machine machine) {
  machine.at_scale = true;
  return machine;
}

// One float32 lane: the exact value lies in `exact`; the computed one is
// within `error` of it, and in `computed` (the whole line where the floats
// are not known). `relative` bounds the same distance point by point,
// relative to the exact value there: |computed - exact| <= relative
// |exact| (infinite where unknown). A box's absolute bound takes its
// largest magnitudes and least divisors together; the relative one holds
// at each point, so a chain of products and quotients keeps it as tight
// over a wide box as at a point.
struct Lane {
  Enclosure exact;
  double error = 0.0;
  Enclosure computed = Enclosure::Whole();
  double relative = INFINITY;
  // Set on the first three lanes of a camera-to-world product (its
  // `vector` an id of its own, `component` 0 to 2): the error vector of the
  // three is at most `distance_relative` times the exact point's distance
  // from the camera, at every point (spirv_eval.cc CameraToWorldRelative).
  std::uint32_t vector = 0;
  int component = -1;
  double distance_relative = INFINITY;

  // The largest magnitude the computed value can have.
  double computed_mag() const { return exact.mag() + error; }
  // An exact input: a float32 value the reference uses as is.
  static Lane Exact(const Enclosure& x) { return {x, 0.0, x, 0.0}; }
};

// Relative rounding bounds hold for results of at least this magnitude:
// normal floats at any scale a frame may have (kUnderflow's 2^-26 below
// the normalized one), with margin.
inline constexpr double kLeastRelative = 0x1p-90;
// A relative bound computed in double, moved up past its own rounding.
inline double Up(double relative) { return relative * (1.0 + 0x1p-50); }

// x with zero too where `machine` may flush a denormal in it.
inline Enclosure Flushed(const Enclosure& x, const Machine& machine) {
  if (!machine.flushes || x.mig() >= FLT_MIN || x.contains_zero()) return x;
  return Enclosure::Hull(x, Enclosure(0.0));
}
// The float32 nearest to each point of x (ties to even), flushed as the
// machine may; the whole line past the float range.
inline Enclosure RoundedSet(const Enclosure& x, const Machine& machine) {
  if (!(x.mag() <= FLT_MAX)) return Enclosure::Whole();
  return Flushed({NearestFloat32(x.lo), NearestFloat32(x.hi)}, machine);
}

// The spacing of float32 values at magnitude x and just above it: the ULP
// a tolerance is counted in (at most 2^-23 x; the larger spacing at a power
// of two).
inline double Ulp(double x) {
  if (!(x < FLT_MAX)) return INFINITY;
  int exponent = 0;
  std::frexp(x, &exponent);  // x = f 2^exponent, f in [0.5, 1)
  return std::ldexp(1.0, std::max(exponent, -125) - 24);
}

// The lane with its error bound tightened by its sets' distance and its
// relative bound, and its relative bound by its error bound.
inline Lane Settled(Lane lane) {
  if (lane.error < 0.0) return lane;
  if (lane.computed.finite()) lane.error = std::min(lane.error, (lane.computed - lane.exact).mag());
  if (lane.relative < INFINITY) lane.error = std::min(lane.error, Up(lane.relative * lane.exact.mag()));
  const double least = lane.exact.mig();
  if (least >= kLeastRelative) lane.relative = std::min(lane.relative, Up(lane.error / least));
  return lane;
}
// (1 + r)(1 + s) - 1 and its like: relative bounds composed, rounded up.
inline double Compose(double r, double s) { return r < INFINITY && s < INFINITY ? Up(r + s + r * s) : INFINITY; }

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

inline Lane Add(const Lane& x, const Lane& y, const Machine& machine) {
  const Enclosure exact = x.exact + y.exact;
  const Enclosure computed = machine.at_scale
                                 ? RoundedSet(Flushed(x.computed, machine) + Flushed(y.computed, machine), machine)
                                 : Enclosure::Whole();
  // Lanes without error hold floats (inputs, literals, exact results).
  if (x.error == 0.0 && y.error == 0.0 && SumIsExact(x.exact, y.exact)) return {exact, 0.0, computed, 0.0};
  // Terms of one sign: their errors relative to each add up to at most the
  // larger relative bound of the sum.
  const bool one_sign = (x.exact.lo >= 0.0 && y.exact.lo >= 0.0) || (x.exact.hi <= 0.0 && y.exact.hi <= 0.0);
  const double relative =
      one_sign && exact.mig() >= kLeastRelative ? Compose(std::max(x.relative, y.relative), kUnitRoundoff) : INFINITY;
  return Settled({exact, Rounded(exact, x.error + y.error, 0.5), computed, relative});
}
inline Lane Negate(const Lane& x) { return {-x.exact, x.error, -x.computed, x.relative}; }
inline Lane Subtract(const Lane& x, const Lane& y, const Machine& machine) { return Add(x, Negate(y), machine); }

// What a product may compute: rounded, or left unrounded for a fused add.
inline Enclosure ProductSet(const Enclosure& x, const Enclosure& y, const Machine& machine) {
  if (!machine.at_scale) return Enclosure::Whole();
  const Enclosure product = Flushed(x, machine) * Flushed(y, machine);
  const Enclosure rounded = RoundedSet(product, machine);
  return machine.fuses ? Enclosure::Hull(rounded, product) : rounded;
}

inline Lane Multiply(const Lane& x, const Lane& y, const Machine& machine) {
  const Enclosure exact = x.exact * y.exact;
  const Enclosure computed = ProductSet(x.computed, y.computed, machine);
  const double propagated = x.exact.mag() * y.error + y.exact.mag() * x.error + x.error * y.error;
  const bool normal = exact.mig() >= kLeastRelative;
  const double operands = normal ? Compose(x.relative, y.relative) : INFINITY;
  if (PowerOfTwo(x) || PowerOfTwo(y)) return Settled({exact, propagated, computed, operands});
  return Settled({exact, Rounded(exact, propagated, 0.5), computed, Compose(operands, kUnitRoundoff)});
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
  Enclosure computed = Enclosure::Whole();
  if (machine.at_scale) {
    // Correctly rounded, or within the tolerance, from every quotient of
    // the operands' floats.
    const Enclosure q = Flushed(x.computed, machine) / Flushed(y.computed, machine);
    const double slack = machine.division_ulps * Ulp(q.mag());
    computed = machine.division_ulps == 0.5 ? RoundedSet(q, machine)
                                            : RoundedSet(Enclosure::Outward(q.lo - slack, q.hi + slack), machine);
  }
  // x~ / y~ = (x / y)(1 + dx) / (1 + dy), then the tolerance.
  double relative = INFINITY;
  if (exact.mig() >= kLeastRelative && y.relative < 1.0) {
    relative = Compose(Up((1.0 + x.relative) / (1.0 - y.relative)) - 1.0, machine.division_ulps * kUlpOfValue);
  }
  return Settled({exact, Rounded(exact, propagated, machine.division_ulps), computed, relative});
}

// Every float a sum of the n sets may round to, in any order of additions:
// each pair may be added first.
inline Enclosure AnyOrderSum(std::array<Enclosure, 4> terms, int n, const Machine& machine) {
  if (n == 1) return terms[0];
  Enclosure all = Enclosure::Whole();
  bool first = true;
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      std::array<Enclosure, 4> next = terms;
      next[i] = RoundedSet(terms[i] + terms[j], machine);
      next[j] = terms[n - 1];
      const Enclosure sum = AnyOrderSum(next, n - 1, machine);
      all = first ? sum : Enclosure::Hull(all, sum);
      first = false;
    }
  }
  return all;
}

// sum over i of x[i] * y[i], n terms, in any order, fused or not.
template <class Lanes>
Lane Dot(const Lanes& x, const Lanes& y, int n, const Machine& machine) {
  Enclosure exact(0.0);
  double propagated = 0.0, magnitude = 0.0;
  for (int i = 0; i < n; ++i) {
    exact = exact + x[i].exact * y[i].exact;
    propagated += x[i].exact.mag() * y[i].error + y[i].exact.mag() * x[i].error + x[i].error * y[i].error;
    magnitude += x[i].computed_mag() * y[i].computed_mag();
  }
  const double gamma = n * kUnitRoundoff / (1.0 - n * kUnitRoundoff);
  Enclosure computed = Enclosure::Whole();
  if (machine.at_scale && n <= 4) {
    std::array<Enclosure, 4> products{};
    for (int i = 0; i < n; ++i) products[i] = ProductSet(x[i].computed, y[i].computed, machine);
    computed = AnyOrderSum(products, n, machine);
  }
  return Settled({exact, propagated + gamma * magnitude + n * kUnderflow, computed});
}

}  // namespace depthbench::bound
