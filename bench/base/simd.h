// Float8: eight float32 lanes, the `real` of the CPU backend's SIMD
// instantiation of shared/ (namespace f32x8 in formulas.h). Every operator
// is one IEEE single-precision operation per lane (GCC vector extensions;
// with -ffp-contract=off nothing is fused), so each lane computes bit for
// bit what the scalar float32 formula computes: the CPU backend runs eight
// pixels at a time, the way a GPU runs a wave, without changing a result.
// The formulas branch only on uint values (uniform across the lanes), as
// shader code over a frame's constants does.
#pragma once

#include <cstdint>
#include <type_traits>

namespace depthbench {

// Four double or int64 lanes, for the double-precision side (reference,
// judge): GCC vector extensions, one IEEE operation per lane.
using Double4 = double __attribute__((vector_size(32)));
using Int4 = std::int64_t __attribute__((vector_size(32)));

// The lane types of an N-lane loop: N = 4 in the baseline copies of the
// hot loops, 8 (one 512-bit register each) in those compiled for AVX-512
// (bench/base/isa.h). Doubles, int64, and the float32 values that widen into
// doubles.
//
// The N = 8 loops are written in functions compiled without AVX-512 and
// inlined into ones compiled with it. GCC keeps arithmetic, comparisons of
// doubles with one select, and shifts of the wide types whole, but splits
// some other operations into lanes before that inlining (two integer
// comparisons joined, conversions from bytes, chains of selects): check the
// generated code when a loop changes. (One specialization per width: GCC
// ignores a vector_size that depends on a template parameter.)
template <int N>
struct Lanes;
template <>
struct Lanes<4> {
  using Double = Double4;
  using Int = Int4;
  using Float = float __attribute__((vector_size(16)));
};
template <>
struct Lanes<8> {
  using Double = double __attribute__((vector_size(64)));
  using Int = std::int64_t __attribute__((vector_size(64)));
  using Float = float __attribute__((vector_size(32)));
};

class Float8 {
 public:
  using Lanes = float __attribute__((vector_size(32)));
  static constexpr int kLanes = 8;

  Float8() = default;  // trivial, as GLM's component unions need
  // Broadcast: literals, uniforms and integer constants GLM builds.
  template <class T, class = std::enable_if_t<std::is_arithmetic_v<T>>>
  Float8(T scalar) : v_(Lanes{} + static_cast<float>(scalar)) {}  // NOLINT: implicit by design
  static Float8 FromLanes(Lanes lanes) {
    Float8 r;
    r.v_ = lanes;
    return r;
  }

  Lanes lanes() const { return v_; }
  float operator[](int lane) const { return v_[lane]; }

  friend Float8 operator+(Float8 a, Float8 b) { return FromLanes(a.v_ + b.v_); }
  friend Float8 operator-(Float8 a, Float8 b) { return FromLanes(a.v_ - b.v_); }
  friend Float8 operator*(Float8 a, Float8 b) { return FromLanes(a.v_ * b.v_); }
  friend Float8 operator/(Float8 a, Float8 b) { return FromLanes(a.v_ / b.v_); }
  friend Float8 operator-(Float8 a) { return FromLanes(-a.v_); }
  Float8& operator+=(Float8 b) { return *this = *this + b; }
  Float8& operator-=(Float8 b) { return *this = *this - b; }
  Float8& operator*=(Float8 b) { return *this = *this * b; }
  Float8& operator/=(Float8 b) { return *this = *this / b; }

 private:
  Lanes v_;
};

}  // namespace depthbench
