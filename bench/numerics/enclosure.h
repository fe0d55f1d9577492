// Enclosure: a closed range of reals that is guaranteed to hold the exact
// result of the operations it went through. Every operation computes its
// endpoints in double and then moves each one at least an ulp outwards,
// which covers the double rounding of that operation (round to nearest
// errs by half an ulp at most). It is the arithmetic the bound analysis (bench/bound/)
// evaluates the shared/ constant formulas in: the exact constants of a
// whole box of frames at once.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

namespace depthbench {

struct Enclosure {
  double lo;
  double hi;

  // Trivial, as GLM's vectors need of their components: left undefined,
  // or 0 when value-initialized (Enclosure{}).
  Enclosure() = default;
  // A point: exact, as the double holds it.
  constexpr Enclosure(double x) : lo(x), hi(x) {}  // NOLINT(google-explicit-constructor): a real's literal
  constexpr Enclosure(double low, double high) : lo(low), hi(high) {}

  static Enclosure Whole() {
    return {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  }
  // [low, high] widened by one to four ulps each way: an ulp of x is at
  // most 2^-52 |x|, and adding 2^-51 |x| (rounded to nearest) moves x by at
  // least one; 2^-1074 moves a denormal or zero. (Cheaper than nextafter,
  // which the analysis would spend a sixth of its time in.)
  static Enclosure Outward(double low, double high) {
    return {low - (std::fabs(low) * 0x1p-51 + 0x1p-1074), high + (std::fabs(high) * 0x1p-51 + 0x1p-1074)};
  }
  // The hull of two intervals.
  static Enclosure Hull(const Enclosure& a, const Enclosure& b) { return {std::min(a.lo, b.lo), std::max(a.hi, b.hi)}; }

  bool contains_zero() const { return lo <= 0.0 && hi >= 0.0; }
  // The largest and the smallest magnitude of its points.
  double mag() const { return std::max(std::fabs(lo), std::fabs(hi)); }
  double mig() const { return contains_zero() ? 0.0 : std::min(std::fabs(lo), std::fabs(hi)); }
  double width() const { return hi - lo; }
  double mid() const { return 0.5 * (lo + hi); }
  bool finite() const { return std::isfinite(lo) && std::isfinite(hi); }

  friend Enclosure operator-(const Enclosure& a) { return {-a.hi, -a.lo}; }
  friend Enclosure operator+(const Enclosure& a, const Enclosure& b) { return Outward(a.lo + b.lo, a.hi + b.hi); }
  friend Enclosure operator-(const Enclosure& a, const Enclosure& b) { return Outward(a.lo - b.hi, a.hi - b.lo); }
  friend Enclosure operator*(const Enclosure& a, const Enclosure& b) {
    const double p[4] = {a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi};
    // 0 * inf is NaN: an unbounded factor times one that may be zero may be anything.
    for (double x : p) {
      if (std::isnan(x)) return Whole();
    }
    return Outward(*std::min_element(p, p + 4), *std::max_element(p, p + 4));
  }
  friend Enclosure operator/(const Enclosure& a, const Enclosure& b) {
    if (b.contains_zero()) return Whole();
    return a * Outward(1.0 / b.hi, 1.0 / b.lo);
  }
  Enclosure& operator+=(const Enclosure& b) { return *this = *this + b; }
  Enclosure& operator-=(const Enclosure& b) { return *this = *this - b; }
  Enclosure& operator*=(const Enclosure& b) { return *this = *this * b; }
  Enclosure& operator/=(const Enclosure& b) { return *this = *this / b; }
  friend bool operator==(const Enclosure&, const Enclosure&) = default;
};

// sqrt of the nonnegative part.
inline Enclosure Sqrt(const Enclosure& a) {
  return Enclosure::Outward(std::sqrt(std::max(a.lo, 0.0)), std::sqrt(std::max(a.hi, 0.0)));
}
// The squares of the points (tighter than a * a when a holds 0).
inline Enclosure Square(const Enclosure& a) {
  const double m = a.mig(), x = a.mag();
  return Enclosure::Outward(m * m, x * x);
}

}  // namespace depthbench
