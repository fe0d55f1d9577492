// The depth conventions: how eye depth z (= -view.z, > 0) maps to the
// window-space depth in [0, 1] that a depth buffer stores, and back.
//
// In every convention window depth is  d = a + b / z  with
//   standard, finite far:   a = f/(f-n),   b = -n f/(f-n)
//   reversed, finite far:   a = -n/(f-n),  b =  n f/(f-n)
//   standard, infinite far: a = 1,         b = -n
//   reversed, infinite far: a = 0,         b =  n
// Under an orthographic projection window depth is linear in eye depth:
//   standard:  d = (z - n) / (f - n)        reversed:  d = (f - z) / (f - n)
// (no infinite far plane), so NDC depth is A + B * z.
// GL-style clip depth ([-1, 1]) keeps the same window depth: its NDC depth
// is 2d - 1, so its NDC coefficients are (2a - 1, 2b). The difference
// between the two clip conventions is therefore not in the mapping but in
// the float32 arithmetic around it (bench/pipeline/encode.cc, screen.h).
//
// Written as ratios of sums of positive terms, never as b / (d - a): the
// latter cancels catastrophically near the far plane (at f/n = 1e9 it loses
// 30 bits in any precision), and these functions are also what the
// high-precision reference evaluates.
// No include guard: see compat.h. Needs params.h.

// Window depth in [0, 1] of eye depth z.
DB_FN real window_depth_from_eye_depth(real near, real far, uint convention, real z) {
  bool reversed = (convention & DB_CONVENTION_REVERSED) != 0u;
  if ((convention & DB_CONVENTION_ORTHOGRAPHIC) != 0u) {
    return reversed ? (far - z) / (far - near) : (z - near) / (far - near);
  }
  if ((convention & DB_CONVENTION_INFINITE) != 0u) {
    return reversed ? near / z : (z - near) / z;
  }
  if (reversed) {
    return (near * (far - z)) / (z * (far - near));
  }
  return (far * (z - near)) / (z * (far - near));
}

// Eye depth that window depth d denotes (+infinity for the far plane of an
// infinite projection). The caller passes 1 - d as well: near the far plane
// of a standard-Z projection it is the small quantity everything hinges
// on, and a caller that knows it exactly (a unorm code c gives
// (2^b - 1 - c) / (2^b - 1)) must not lose it to the subtraction.
DB_FN real eye_depth_from_window_depth(real near, real far, uint convention, real d, real one_minus_d) {
  bool reversed = (convention & DB_CONVENTION_REVERSED) != 0u;
  if ((convention & DB_CONVENTION_ORTHOGRAPHIC) != 0u) {
    return reversed ? far * one_minus_d + near * d : near * one_minus_d + far * d;
  }
  if ((convention & DB_CONVENTION_INFINITE) != 0u) {
    return reversed ? near / d : near / one_minus_d;
  }
  if (reversed) {
    return (near * far) / (near * one_minus_d + far * d);
  }
  return (near * far) / (far * one_minus_d + near * d);
}

// NDC depth coefficients (A, B) with ndc_z = A + B / z (A + B * z when
// orthographic), for the convention's clip-depth range. These are the entries a projection matrix carries and
// the constants the engine shader notes read from it.
DB_FN vec2 ndc_depth_coefficients(real near, real far, uint convention) {
  bool reversed = (convention & DB_CONVENTION_REVERSED) != 0u;
  real a;
  real b;
  if ((convention & DB_CONVENTION_ORTHOGRAPHIC) != 0u) {
    real span = far - near;
    a = reversed ? far / span : -near / span;
    b = reversed ? real(-1.0f) / span : real(1.0f) / span;
  } else if ((convention & DB_CONVENTION_INFINITE) != 0u) {
    a = reversed ? real(0.0f) : real(1.0f);
    b = reversed ? near : -near;
  } else {
    real span = far - near;
    a = reversed ? -near / span : far / span;
    b = reversed ? (near * far) / span : -(near * far) / span;
  }
  if ((convention & DB_CONVENTION_CLIP_MINUS_ONE) != 0u) {
    a = a * 2.0f - 1.0f;
    b = b * 2.0f;
  }
  return vec2(a, b);
}
