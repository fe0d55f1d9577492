// DoubleDouble: an unevaluated sum hi + lo of two doubles with |lo| <= ulp(hi)/2,
// about 106 bits of significand. It is the `real` of the high-precision
// instantiations of shared/: hp (exact shader constants, rounding decisions,
// formula tests) and hp4, four lanes at once, where the reference decodes
// stored depths and where the exact shader constants of four frames are
// computed together. Near the far plane at far/near = 1e9 a decode can lose 30
// bits to cancellation in any precision; the reference must stay far below
// float32 rounding (2^-24) after that.
//
// The algorithms are the classical error-free transformations (Knuth's
// two-sum, Dekker's fast two-sum, an FMA-based exact product) combined as in
// Bailey's and Hida, Li & Bailey's double-double arithmetic (division as
// Joldes, Muller & Popescu give it); addition and multiplication have
// relative error below 2^-103, division below 2^-102
// (tests/reference_test.cc checks them against MPFR). They rely on IEEE
// double rounding with no contraction of a*b+c into an FMA other than the
// explicit ones: the project builds with -ffp-contract=off.
//
// One template serves both widths: the lane type D is double or Double4
// (four doubles, GCC vector extensions), and the code is branch-free
// (special values are fixed up by selects), so every lane of the wide type
// computes exactly what the scalar type computes.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "bench/base/simd.h"

#if defined(__AVX__)  // and so wherever __FMA__ is
#include <immintrin.h>
#endif

namespace depthbench {

namespace dd_detail {

inline double Fma(double a, double b, double c) { return std::fma(a, b, c); }
inline Double4 Fma(Double4 a, Double4 b, Double4 c) {
#if defined(__FMA__)
  return reinterpret_cast<Double4>(
      _mm256_fmadd_pd(reinterpret_cast<__m256d>(a), reinterpret_cast<__m256d>(b), reinterpret_cast<__m256d>(c)));
#else
  Double4 r;
  for (int k = 0; k < 4; ++k) r[k] = std::fma(a[k], b[k], c[k]);
  return r;
#endif
}

// x is neither infinite nor NaN: a bool for double, a lane mask for Double4.
template <class D>
auto Finite(D x) {
  return (x - x) == D{} * 0.0;
}

template <class D>
D Broadcast(double x) {
  return D{} * 0.0 + x;
}

// s + e == a + b exactly, s = fl(a + b).
template <class D>
void TwoSum(D a, D b, D& s, D& e) {
  s = a + b;
  D bb = s - a;
  e = (a - (s - bb)) + (b - bb);
}

// As TwoSum, valid when |a| >= |b| (or a == 0).
template <class D>
void FastTwoSum(D a, D b, D& s, D& e) {
  s = a + b;
  e = b - (s - a);
}

// p + e == a * b exactly (barring underflow), p = fl(a * b).
template <class D>
void TwoProduct(D a, D b, D& p, D& e) {
  p = a * b;
  e = Fma(a, b, -p);
}

}  // namespace dd_detail

template <class D>
class BasicDoubleDouble {
 public:
  // Trivial, so that GLM can hold it in its component unions; like a
  // double, a default-constructed value is uninitialized.
  BasicDoubleDouble() = default;
  // Implicit: every double (and float, and integer up to 2^53) is exact.
  BasicDoubleDouble(double value)  // NOLINT
      : hi_(dd_detail::Broadcast<D>(value)), lo_(dd_detail::Broadcast<D>(0.0)) {}
  static BasicDoubleDouble FromParts(D hi, D lo) {
    BasicDoubleDouble r;
    r.hi_ = hi;
    r.lo_ = lo;
    return r;
  }

  D hi() const { return hi_; }
  D lo() const { return lo_; }
  // The nearest double (hi is already the rounded sum).
  D ToDouble() const { return hi_; }

  friend BasicDoubleDouble operator+(BasicDoubleDouble a, BasicDoubleDouble b) {
    D s, e, t, f;
    dd_detail::TwoSum(a.hi_, b.hi_, s, e);
    dd_detail::TwoSum(a.lo_, b.lo_, t, f);
    e += t;
    D s2, e2;
    dd_detail::FastTwoSum(s, e, s2, e2);
    e2 += f;
    D s3, e3;
    dd_detail::FastTwoSum(s2, e2, s3, e3);
    // An infinite or NaN sum: the error terms are meaningless.
    const auto finite = dd_detail::Finite(s);
    return FromParts(finite ? s3 : s, finite ? e3 : D{} * 0.0);
  }
  friend BasicDoubleDouble operator-(BasicDoubleDouble a) { return FromParts(-a.hi_, -a.lo_); }
  friend BasicDoubleDouble operator-(BasicDoubleDouble a, BasicDoubleDouble b) { return a + (-b); }

  friend BasicDoubleDouble operator*(BasicDoubleDouble a, BasicDoubleDouble b) {
    D p, e;
    dd_detail::TwoProduct(a.hi_, b.hi_, p, e);
    e += a.hi_ * b.lo_ + a.lo_ * b.hi_;
    D p2, e2;
    dd_detail::FastTwoSum(p, e, p2, e2);
    const auto finite = dd_detail::Finite(p);
    return FromParts(finite ? p2 : p, finite ? e2 : D{} * 0.0);
  }

  friend BasicDoubleDouble operator/(BasicDoubleDouble a, BasicDoubleDouble b) {
    // Joldes, Muller and Popescu's DWDivDW2 ("Tight and rigorous error
    // bounds for basic building blocks of double-word arithmetic", ACM
    // TOMS 44(2), 2017), relative error at most 15 * 2^-106: a first
    // quotient digit q1 from the leading parts; b * q1 as a double-double
    // (their DWTimesFP1); the remainder a - b * q1, whose leading part
    // cancels exactly; and a correcting digit from it.
    const D q1 = a.hi_ / b.hi_;
    D product, product_error;
    dd_detail::TwoProduct(b.hi_, q1, product, product_error);
    D bq_hi, bq_lo;
    {
      D s, e;
      dd_detail::FastTwoSum(product, b.lo_ * q1, s, e);
      dd_detail::FastTwoSum(s, e + product_error, bq_hi, bq_lo);
    }
    D rest_hi, rest_lo;
    dd_detail::TwoSum(a.hi_, -bq_hi, rest_hi, rest_lo);
    const D rest = rest_hi + ((rest_lo - bq_lo) + a.lo_);
    const D q2 = rest / b.hi_;
    D s, e;
    dd_detail::FastTwoSum(q1, q2, s, e);
    // Division by zero, infinities, or an exact zero quotient: the first
    // digit is the answer.
    const auto plain = !dd_detail::Finite(q1) || q1 == D{} * 0.0;
    return FromParts(plain ? q1 : s, plain ? D{} * 0.0 : e);
  }

  BasicDoubleDouble& operator+=(BasicDoubleDouble b) { return *this = *this + b; }
  BasicDoubleDouble& operator-=(BasicDoubleDouble b) { return *this = *this - b; }
  BasicDoubleDouble& operator*=(BasicDoubleDouble b) { return *this = *this * b; }
  BasicDoubleDouble& operator/=(BasicDoubleDouble b) { return *this = *this / b; }

 private:
  D hi_;
  D lo_;
};

using DoubleDouble = BasicDoubleDouble<double>;
using DoubleDouble4 = BasicDoubleDouble<Double4>;

// Scalar comparisons (only the narrow type is ever compared).
inline bool operator==(DoubleDouble a, DoubleDouble b) { return a.hi() == b.hi() && a.lo() == b.lo(); }
inline bool operator<(DoubleDouble a, DoubleDouble b) {
  return a.hi() < b.hi() || (a.hi() == b.hi() && a.lo() < b.lo());
}
inline bool operator>(DoubleDouble a, DoubleDouble b) { return b < a; }
inline bool operator<=(DoubleDouble a, DoubleDouble b) { return !(b < a); }
inline bool operator>=(DoubleDouble a, DoubleDouble b) { return !(a < b); }

// The float next to the finite float f: above it when `up`, else below
// (what std::nextafter gives, without the library call, which the
// per-frame rounding of shader constants made a visible cost). The bits
// of a float's magnitude count its steps from zero.
inline float NextFloat(float f, bool up) {
  const auto bits = std::bit_cast<std::uint32_t>(f);
  if ((bits & 0x7fffffffu) == 0) {
    return up ? std::numeric_limits<float>::denorm_min() : -std::numeric_limits<float>::denorm_min();
  }
  const bool away_from_zero = up == ((bits >> 31) == 0);
  return std::bit_cast<float>(away_from_zero ? bits + 1 : bits - 1);
}

// The float nearest to hi + lo (ties to even), without double rounding: a
// rounding of hi to float can only be wrong when hi lies exactly halfway
// between two floats, and then the sign of lo decides.
inline float RoundToFloat(DoubleDouble a) {
  float f = static_cast<float>(a.hi());
  if (a.lo() == 0.0 || !std::isfinite(f)) return f;
  double back = static_cast<double>(f);
  if (back == a.hi()) return f;  // hi is a float; lo is far below its half-ulp
  // Is hi exactly halfway between f and its other neighbour?
  float other = NextFloat(f, back < a.hi());
  double midpoint = (back + static_cast<double>(other)) * 0.5;  // exact: 25 bits
  if (a.hi() != midpoint) return f;
  bool lo_points_to_other = (a.lo() > 0.0) == (static_cast<double>(other) > back);
  return lo_points_to_other ? other : f;
}

// RoundToFloat four lanes at a time, each lane bit for bit what the scalar
// function gives (the shader constants of four frames are rounded at once).
// float(hi) is already the answer unless lo is nonzero and hi lies exactly
// halfway between two floats. In the range of normal floats (and up to
// 2^128, where a halfway hi between the largest float and 2^128 rounds to
// infinity) that shows in hi's bits: the 29 low fraction bits that a float
// does not keep read 1000...0. Lanes that are halfway, or that lie outside
// that range (float subnormals, infinities, NaN) with a nonzero lo, go
// through the scalar function; in shader constants they are rare.
inline Lanes<4>::Float RoundToFloat(DoubleDouble4 a) {
  const Double4 hi = a.hi(), lo = a.lo();
  Lanes<4>::Float f = __builtin_convertvector(hi, Lanes<4>::Float);
  const Int4 bits = reinterpret_cast<Int4>(hi);
  const Double4 magnitude = reinterpret_cast<Double4>(bits & 0x7fffffffffffffff);
  const Int4 halfway = (bits & 0x1fffffff) == 0x10000000;
  const Int4 in_range = (magnitude >= 0x1p-126) & (magnitude < 0x1p128);
  const Int4 settled = (in_range & ~halfway) | (lo == 0.0);
#if defined(__AVX__)
  if (_mm256_movemask_pd(reinterpret_cast<__m256d>(settled)) == 0xf) return f;
#endif
  for (int k = 0; k < 4; ++k) {
    if (!settled[k]) f[k] = RoundToFloat(DoubleDouble::FromParts(hi[k], lo[k]));
  }
  return f;
}

}  // namespace depthbench
