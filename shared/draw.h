// The sampler's draw of one sample (bench/pipeline/sampler.h): its random
// units, its depth pick and eye depth, its pixel, and the world-space ray
// through the pixel's centre. Written in float64 arithmetic that C++ and
// GLSL compute alike, bit for bit, so that a device draws the very samples
// the host would (shaders/judge/sample.comp; tests/draw_test.cc and
// tests/device_judge_test.cc hold the two equal):
//   - only +, -, *, / on doubles, each rounded once (IEEE 754 says how;
//     DB_PRECISE keeps a GLSL compiler from fusing a product into an add,
//     and C++ is built with -ffp-contract=off), floor, min and max, and
//     conversions between doubles and integers below 2^53;
//   - no library exp: glibc's cannot be repeated on a device, so the eye
//     depth's power of two is a polynomial here (draw_exp2);
//   - constants that are not small integers or halves come from their
//     bits (DB_DOUBLE_BITS), so no compiler parses a decimal.
// The draw needs to be repeatable, not correctly rounded: draw_exp2 is
// within a few units in the last place of 2^x and the ray within a few of
// the exact one (tests/draw_test.cc bounds both), far below the float32
// errors the bench measures.
// No include guard: see compat.h. Needs random.h.

// What the sample's random streams give, each in [0, 1): the pick and the
// depth with 53 random bits (two 32-bit draws), the pixel kind too, the
// pixel's x and y with 32.
struct DrawUnits {
  double pick;
  double depth;
  double pixel_kind;
  double x;
  double y;
};

// What the draw needs of its frame.
struct DrawFrame {
  double eye_depth_min;  // the eye depths samples are drawn from
  double eye_depth_max;
  double log2_eye_depth_span;  // log2(eye_depth_max / eye_depth_min)
  double tan_x;                // aspect * tan(fov_y / 2): half the frustum's width at unit eye depth
  double tan_y;                // tan(fov_y / 2): half its height
  uint width;
  uint height;
  dmat3 rotation;   // columns: the camera's x, y, z axes in world space
  double centre_x;  // an off-centre lens: the view ray through NDC (0, 0) is (centre_x, centre_y, -1)
  double centre_y;
};

// One drawn sample. `pick` numbers DepthPick (sampler.h), `coverage`
// Coverage (bands.h); the eye depth is 0 for a stored-value pick.
struct DrawnSample {
  uint x;
  uint y;
  uint pick;
  uint coverage;
  double eye_depth;
};

DB_CONST_UINT(DB_DRAW_PICK_STREAM, 0u)
DB_CONST_UINT(DB_DRAW_DEPTH_STREAM, 1u)       // and 2
DB_CONST_UINT(DB_DRAW_PIXEL_KIND_STREAM, 3u)  // and 4
DB_CONST_UINT(DB_DRAW_PIXEL_X_STREAM, 4u)
DB_CONST_UINT(DB_DRAW_PIXEL_Y_STREAM, 5u)
DB_CONST_UINT(DB_COVERAGE_STORED_ZERO, 1u)  // then the other three stored values
DB_CONST_UINT(DB_COVERAGE_NEAR_DOUBLING, 5u)
DB_CONST_UINT(DB_COVERAGE_FAR_DOUBLING, 6u)
DB_CONST_UINT(DB_COVERAGE_CORNER_PIXEL, 7u)
DB_CONST_UINT(DB_COVERAGE_EDGE_PIXEL, 8u)

// A uniform double in [0, 1) from 27 + 26 bits of two consecutive streams.
DB_FN double draw_unit(uint state, uint stream) {
  double high = double(random_bits_from_state(state, stream) >> 5u);
  double low = double(random_bits_from_state(state, stream + 1u) >> 6u);
  DB_PRECISE double joined = high * 67108864.0 + low;  // 2^26: exact, below 2^53
  return joined * DB_DOUBLE_BITS(0x3ca00000u, 0u);     // 2^-53
}

DB_FN DrawUnits draw_units(uint state) {
  DrawUnits u;
  u.pick = draw_unit(state, DB_DRAW_PICK_STREAM);
  u.depth = draw_unit(state, DB_DRAW_DEPTH_STREAM);
  u.pixel_kind = draw_unit(state, DB_DRAW_PIXEL_KIND_STREAM);
  u.x = double(random_bits_from_state(state, DB_DRAW_PIXEL_X_STREAM)) * DB_DOUBLE_BITS(0x3df00000u, 0u);  // 2^-32
  u.y = double(random_bits_from_state(state, DB_DRAW_PIXEL_Y_STREAM)) * DB_DOUBLE_BITS(0x3df00000u, 0u);
  return u;
}

// 2^x for x in [-1022, 1023]: 2^floor(x), exactly, times e^t for t =
// frac(x) * ln 2 in [0, ln 2), by its Taylor polynomial to degree 17
// (the first term left out is below 2^-57 of the sum) in Horner's form.
DB_FN double draw_exp2(double x) {
  double whole = floor(x);
  DB_PRECISE double t = (x - whole) * DB_DOUBLE_BITS(0x3fe62e42u, 0xfefa39efu);  // x - whole is exact
  DB_PRECISE double p = DB_DOUBLE_BITS(0x3ce952c7u, 0x7030ad4au);                // 1/17!
  p = p * t + DB_DOUBLE_BITS(0x3d2ae7f3u, 0xe733b81fu);                          // 1/16!
  p = p * t + DB_DOUBLE_BITS(0x3d6ae7f3u, 0xe733b81fu);
  p = p * t + DB_DOUBLE_BITS(0x3da93974u, 0xa8c07c9du);
  p = p * t + DB_DOUBLE_BITS(0x3de61246u, 0x13a86d09u);
  p = p * t + DB_DOUBLE_BITS(0x3e21eed8u, 0xeff8d898u);
  p = p * t + DB_DOUBLE_BITS(0x3e5ae645u, 0x67f544e4u);
  p = p * t + DB_DOUBLE_BITS(0x3e927e4fu, 0xb7789f5cu);
  p = p * t + DB_DOUBLE_BITS(0x3ec71de3u, 0xa556c734u);
  p = p * t + DB_DOUBLE_BITS(0x3efa01a0u, 0x1a01a01au);
  p = p * t + DB_DOUBLE_BITS(0x3f2a01a0u, 0x1a01a01au);
  p = p * t + DB_DOUBLE_BITS(0x3f56c16cu, 0x16c16c17u);
  p = p * t + DB_DOUBLE_BITS(0x3f811111u, 0x11111111u);
  p = p * t + DB_DOUBLE_BITS(0x3fa55555u, 0x55555555u);
  p = p * t + DB_DOUBLE_BITS(0x3fc55555u, 0x55555555u);  // 1/3!
  p = p * t + 0.5;
  p = p * t + 1.0;
  p = p * t + 1.0;
  return p * DB_DOUBLE_BITS(uint(int(whole) + 1023) << 20u, 0u);  // times 2^whole
}

// floor(unit * n), at most n - 1.
DB_FN uint draw_scaled(double unit, uint n) { return min(n - 1u, uint(floor(unit * double(n)))); }

// Depth: three quarters log-uniform eye depth (the natural distribution),
// the rest drawn on purpose where reconstructions break: stored values at
// the ends of the format, the first and the last doubling of depth.
// Pixel: mostly uniform over the render target (natural), with its exact
// corners and edges drawn on purpose. A sample is counted under its depth's
// coverage kind before its pixel's.
DB_FN DrawnSample draw_sample(DrawUnits u, DrawFrame f) {
  DrawnSample s;
  s.pick = 0u;
  s.coverage = 0u;
  s.eye_depth = 0.0;
  double lo = f.eye_depth_min;
  double hi = f.eye_depth_max;
  if (u.pick < DB_DOUBLE_BITS(0x3fa99999u, 0x9999999au)) {  // 0.05
    uint edge = min(3u, uint(u.pick / DB_DOUBLE_BITS(0x3fa99999u, 0x9999999au) * 4.0));
    s.pick = 1u + edge;
    s.coverage = DB_COVERAGE_STORED_ZERO + edge;
  } else if (u.pick < DB_DOUBLE_BITS(0x3fc33333u, 0x33333333u)) {  // 0.15: the first doubling
    s.eye_depth = min(hi, lo * draw_exp2(u.depth));
    s.coverage = DB_COVERAGE_NEAR_DOUBLING;
  } else if (u.pick < 0.25) {  // the last doubling
    s.eye_depth = max(lo, hi * draw_exp2(-u.depth));
    s.coverage = DB_COVERAGE_FAR_DOUBLING;
  } else {
    s.eye_depth = min(hi, lo * draw_exp2(u.depth * f.log2_eye_depth_span));
  }

  uint w = f.width;
  uint h = f.height;
  bool natural_depth = s.coverage == 0u;
  double four_percent = DB_DOUBLE_BITS(0x3fa47ae1u, 0x47ae147bu);  // 0.04
  if (u.pixel_kind < four_percent) {
    uint corner = min(3u, uint(u.pixel_kind / four_percent * 4.0));
    s.x = (corner & 1u) != 0u ? w - 1u : 0u;
    s.y = (corner & 2u) != 0u ? h - 1u : 0u;
    if (natural_depth) {
      s.coverage = DB_COVERAGE_CORNER_PIXEL;
    }
  } else if (u.pixel_kind < DB_DOUBLE_BITS(0x3fb47ae1u, 0x47ae147bu)) {  // 0.08
    uint edge = min(3u, uint((u.pixel_kind - four_percent) / four_percent * 4.0));
    s.x = edge < 2u ? (edge == 0u ? 0u : w - 1u) : draw_scaled(u.x, w);
    s.y = edge < 2u ? draw_scaled(u.y, h) : (edge == 2u ? 0u : h - 1u);
    if (natural_depth) {
      s.coverage = DB_COVERAGE_EDGE_PIXEL;
    }
  } else {
    s.x = draw_scaled(u.x, w);
    s.y = draw_scaled(u.y, h);
  }
  return s;
}

// The world-space point of pixel (x, y)'s centre at `w`, camera-relative:
// rotation * (ndc.x * tan_x + centre_x, ndc.y * tan_y + centre_y, -w), with
// the pixel's texture coordinate and NDC as screen.h's uv_from_pixel and
// ndc_from_uv take them. A centred lens adds zeros, and w = 1 multiplies
// exactly, which changes no bit.
DB_FN dvec3 draw_pixel_point(uint x, uint y, DrawFrame f, double w) {
  DB_PRECISE double u = (double(x) + 0.5) / double(f.width);
  DB_PRECISE double v = (double(y) + 0.5) / double(f.height);
  DB_PRECISE double view_x = (u * 2.0 - 1.0) * f.tan_x + f.centre_x;
  DB_PRECISE double view_y = (1.0 - v * 2.0) * f.tan_y + f.centre_y;
  dvec3 point = dvec3(0.0);
  for (int row = 0; row < 3; ++row) {
    DB_PRECISE double r = f.rotation[0][row] * view_x + f.rotation[1][row] * view_y;
    DB_PRECISE double depth_part = f.rotation[2][row] * w;
    point[row] = r - depth_part;
  }
  return point;
}

// The world-space ray through pixel (x, y)'s centre at unit eye depth
// (w = 1): the scene point at eye depth z is z times it. For an
// orthographic frame (tan_x and tan_y are then the view volume's half
// extents) the point at eye depth 0 is draw_pixel_point(x, y, f, 0.0), and
// z adds z times the view axis, -rotation[2].
DB_FN dvec3 draw_pixel_ray(uint x, uint y, DrawFrame f) { return draw_pixel_point(x, y, f, 1.0); }
