// MpfrReal: a minimal value type over MPFR, enough to evaluate the scalar
// formulas of shared/depth_mapping.h at any precision. It is the arbiter of
// last resort: the encoder falls back to it when a double-double result lies
// too close to a rounding boundary to decide, and the tests check the
// double-double reference against it.
#pragma once

#include <mpfr.h>

#include <utility>

namespace depthbench {

class MpfrReal {
 public:
  // Precision of every MpfrReal, in bits.
  static constexpr mpfr_prec_t kPrecision = 400;

  MpfrReal() {
    mpfr_init2(v_, kPrecision);
    mpfr_set_zero(v_, 1);
  }
  MpfrReal(double x) {
    mpfr_init2(v_, kPrecision);
    mpfr_set_d(v_, x, MPFR_RNDN);
  }  // NOLINT: exact
  MpfrReal(const MpfrReal& o) {
    mpfr_init2(v_, kPrecision);
    mpfr_set(v_, o.v_, MPFR_RNDN);
  }
  MpfrReal& operator=(const MpfrReal& o) {
    if (this != &o) mpfr_set(v_, o.v_, MPFR_RNDN);
    return *this;
  }
  ~MpfrReal() { mpfr_clear(v_); }

  mpfr_srcptr get() const { return v_; }
  mpfr_ptr get() { return v_; }
  double ToDouble() const { return mpfr_get_d(v_, MPFR_RNDN); }
  float ToFloat() const { return mpfr_get_flt(v_, MPFR_RNDN); }

  friend MpfrReal operator+(const MpfrReal& a, const MpfrReal& b) { return Apply(mpfr_add, a, b); }
  friend MpfrReal operator-(const MpfrReal& a, const MpfrReal& b) { return Apply(mpfr_sub, a, b); }
  friend MpfrReal operator*(const MpfrReal& a, const MpfrReal& b) { return Apply(mpfr_mul, a, b); }
  friend MpfrReal operator/(const MpfrReal& a, const MpfrReal& b) { return Apply(mpfr_div, a, b); }
  friend MpfrReal operator-(const MpfrReal& a) {
    MpfrReal r;
    mpfr_neg(r.v_, a.v_, MPFR_RNDN);
    return r;
  }
  friend bool operator<(const MpfrReal& a, const MpfrReal& b) { return mpfr_less_p(a.v_, b.v_); }
  friend bool operator>(const MpfrReal& a, const MpfrReal& b) { return mpfr_greater_p(a.v_, b.v_); }

 private:
  template <class Op>
  static MpfrReal Apply(Op op, const MpfrReal& a, const MpfrReal& b) {
    MpfrReal r;
    op(r.v_, a.v_, b.v_, MPFR_RNDN);
    return r;
  }
  mpfr_t v_;
};

}  // namespace depthbench
