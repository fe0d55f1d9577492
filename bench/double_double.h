// DoubleDouble: an unevaluated sum hi + lo of two doubles with |lo| <= ulp(hi)/2,
// about 106 bits of significand. It is the `real` of the high-precision
// instantiation of shared/ (the reference), where a plain double is not
// enough: a decode near the far plane at far/near = 1e9 cancels 30 bits, and
// the reference must stay far below float32 rounding (2^-24) after that.
//
// The algorithms are the classical error-free transformations (Knuth's
// two-sum, Dekker's fast two-sum, an FMA-based exact product) combined as in
// Bailey's and Hida, Li & Bailey's double-double arithmetic; addition and
// multiplication have relative error below 2^-103, division below 2^-102
// (tests/reference_test.cc checks the composed formulas against MPFR).
// They rely on IEEE double rounding with no contraction of a*b+c into an FMA
// other than the explicit std::fma calls: the project builds with
// -ffp-contract=off.
#pragma once

#include <cmath>
#include <cstdint>

namespace depthbench {

class DoubleDouble {
 public:
  // Trivial, so that GLM can hold it in its component unions; like a
  // double, a default-constructed value is uninitialized.
  DoubleDouble() = default;
  // Implicit: every double (and float, and integer up to 2^53) is exact.
  constexpr DoubleDouble(double value) : hi_(value), lo_(0.0) {}  // NOLINT
  static constexpr DoubleDouble FromParts(double hi, double lo) {
    DoubleDouble r(hi);
    r.hi_ = hi;
    r.lo_ = lo;
    return r;
  }

  constexpr double hi() const { return hi_; }
  constexpr double lo() const { return lo_; }
  // The nearest double (hi is already the rounded sum).
  constexpr double ToDouble() const { return hi_; }

  friend DoubleDouble operator+(DoubleDouble a, DoubleDouble b);
  friend DoubleDouble operator-(DoubleDouble a, DoubleDouble b);
  friend DoubleDouble operator*(DoubleDouble a, DoubleDouble b);
  friend DoubleDouble operator/(DoubleDouble a, DoubleDouble b);
  friend DoubleDouble operator-(DoubleDouble a) { return FromParts(-a.hi_, -a.lo_); }

  DoubleDouble& operator+=(DoubleDouble b) { return *this = *this + b; }
  DoubleDouble& operator-=(DoubleDouble b) { return *this = *this - b; }
  DoubleDouble& operator*=(DoubleDouble b) { return *this = *this * b; }
  DoubleDouble& operator/=(DoubleDouble b) { return *this = *this / b; }

  friend bool operator==(DoubleDouble a, DoubleDouble b) { return a.hi_ == b.hi_ && a.lo_ == b.lo_; }
  friend bool operator<(DoubleDouble a, DoubleDouble b) {
    return a.hi_ < b.hi_ || (a.hi_ == b.hi_ && a.lo_ < b.lo_);
  }
  friend bool operator>(DoubleDouble a, DoubleDouble b) { return b < a; }
  friend bool operator<=(DoubleDouble a, DoubleDouble b) { return !(b < a); }
  friend bool operator>=(DoubleDouble a, DoubleDouble b) { return !(a < b); }

 private:
  double hi_;
  double lo_;
};

namespace dd_detail {

// s + e == a + b exactly, s = fl(a + b).
inline void TwoSum(double a, double b, double& s, double& e) {
  s = a + b;
  double bb = s - a;
  e = (a - (s - bb)) + (b - bb);
}

// As TwoSum, valid when |a| >= |b| (or a == 0).
inline void FastTwoSum(double a, double b, double& s, double& e) {
  s = a + b;
  e = b - (s - a);
}

// p + e == a * b exactly (barring underflow), p = fl(a * b).
inline void TwoProduct(double a, double b, double& p, double& e) {
  p = a * b;
  e = std::fma(a, b, -p);
}

}  // namespace dd_detail

inline DoubleDouble operator+(DoubleDouble a, DoubleDouble b) {
  double s, e, t, f;
  dd_detail::TwoSum(a.hi_, b.hi_, s, e);
  if (!std::isfinite(s)) return DoubleDouble(s);
  dd_detail::TwoSum(a.lo_, b.lo_, t, f);
  e += t;
  dd_detail::FastTwoSum(s, e, s, e);
  e += f;
  dd_detail::FastTwoSum(s, e, s, e);
  return DoubleDouble::FromParts(s, e);
}

inline DoubleDouble operator-(DoubleDouble a, DoubleDouble b) { return a + (-b); }

inline DoubleDouble operator*(DoubleDouble a, DoubleDouble b) {
  double p, e;
  dd_detail::TwoProduct(a.hi_, b.hi_, p, e);
  if (!std::isfinite(p)) return DoubleDouble(p);
  e += a.hi_ * b.lo_ + a.lo_ * b.hi_;
  dd_detail::FastTwoSum(p, e, p, e);
  return DoubleDouble::FromParts(p, e);
}

inline DoubleDouble operator/(DoubleDouble a, DoubleDouble b) {
  // Long division: three quotient digits, each correcting the remainder of
  // the previous ones.
  double q1 = a.hi_ / b.hi_;
  if (!std::isfinite(q1) || q1 == 0.0) return DoubleDouble(q1);
  DoubleDouble r = a - b * DoubleDouble(q1);
  double q2 = r.hi_ / b.hi_;
  r = r - b * DoubleDouble(q2);
  double q3 = r.hi_ / b.hi_;
  double s, e;
  dd_detail::FastTwoSum(q1, q2, s, e);
  return DoubleDouble::FromParts(s, e) + DoubleDouble(q3);
}

inline DoubleDouble Abs(DoubleDouble a) { return a.hi() < 0.0 ? -a : a; }

inline DoubleDouble Sqrt(DoubleDouble a) {
  if (a.hi() <= 0.0) return DoubleDouble(std::sqrt(a.hi()));
  // One Newton step from the double square root doubles its precision.
  double x = std::sqrt(a.hi());
  DoubleDouble xx = DoubleDouble(x) * DoubleDouble(x);
  return DoubleDouble(x) + (a - xx) / DoubleDouble(2.0 * x);
}

inline bool IsFinite(DoubleDouble a) { return std::isfinite(a.hi()); }

// The float nearest to hi + lo (ties to even), without double rounding: a
// rounding of hi to float can only be wrong when hi lies exactly halfway
// between two floats, and then the sign of lo decides.
inline float RoundToFloat(DoubleDouble a) {
  float f = static_cast<float>(a.hi());
  if (a.lo() == 0.0 || !std::isfinite(f)) return f;
  double back = static_cast<double>(f);
  if (back == a.hi()) return f;  // hi is a float; lo is far below its half-ulp
  // Is hi exactly halfway between f and its other neighbour?
  float other = std::nextafter(f, back < a.hi() ? INFINITY : -INFINITY);
  double midpoint = (back + static_cast<double>(other)) * 0.5;  // exact: 25 bits
  if (a.hi() != midpoint) return f;
  bool lo_points_to_other = (a.lo() > 0.0) == (static_cast<double>(other) > back);
  return lo_points_to_other ? other : f;
}

}  // namespace depthbench
