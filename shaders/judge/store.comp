#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
// Production and storage on the device (bench/device_judge/device_judge.h):
// the float32 each pipeline produces from a sample's eye depth and its
// frame's float32 constants (encode.cc's Float32PipelineFloats), and every
// depth slot's texels, made from its pipeline's float as the format stores
// it and as a texture fetch returns it (encode.cc's StoreFloats), written
// straight into the buffer the reconstruction pass reads. The host then
// uploads per sample its eye depth, not a float per pipeline nor a texel
// per depth slot.
//
// Every step is integer arithmetic on the bits, or float64 arithmetic that
// is exact or rounded once (a product), so that each texel equals the
// host's, bit for bit (tests/device_judge_test.cc): no conversion between
// float widths is left to the device, whose rounding of them Vulkan does
// not fix and whose handling of float32 subnormals differs (bindings.glsl).
//
// Workgroup row y takes pipeline y: each invocation makes the pipeline's
// float of its sample (phase 0, where depths are produced in float32) or
// reads the one the host uploaded (phase 1: exact production, which stays
// with the host), then writes the texel of each of the pipeline's depth
// slots, so that the float is made and read once for them all. The slots'
// whole slices are written, the lead and the padding as zeros. A
// stored-value pick's texel comes from the table the host made for the
// frame (the picks are a few per cent of the samples, and their values
// depend on the format alone, or on the frame's far plane).
#include "../../shared/compat.h"
#include "../../shared/params.h"
#include "../../shared/judge.h"

layout(local_size_x = 64) in;

#define DB_STORE_PASS
#include "bindings.glsl"

// The float32 nearest to a double, ties to even, as bits: from the
// double's bits, subnormal results and overflow to infinity included (a
// NaN becomes the quiet NaN 0x7fc00000).
uint float_bits_of(double x) {
  uint64_t bits = doubleBitsToUint64(x);
  uint sign = uint(bits >> 63) << 31u;
  int exponent = int((bits >> 52) & 0x7fful);
  uint64_t fraction = bits & 0xffffffffffffful;
  if (exponent == 0x7ff) {
    return fraction != 0ul ? 0x7fc00000u : sign | 0x7f800000u;
  }
  if (exponent == 0) {
    return sign;  // zero, or a double subnormal: far below float32's least
  }
  // A normal float keeps 23 of the 52 fraction bits (the exponent's bias
  // goes from 1023 to 127); a subnormal one keeps the significand's bits
  // from 2^-149 up.
  int unbiased = exponent - 1023;
  uint64_t kept;
  int drop;
  uint64_t significand;
  if (unbiased >= -126) {
    if (unbiased > 127) {
      return sign | 0x7f800000u;
    }
    significand = fraction;
    drop = 29;
    kept = (uint64_t(unbiased + 127) << 23) | (fraction >> 29);
  } else {
    significand = fraction | 0x10000000000000ul;  // the implicit bit
    drop = -97 - unbiased;                        // value / 2^-149 = significand * 2^(unbiased + 97)
    if (drop > 54) {
      return sign;  // below half the least subnormal
    }
    kept = significand >> uint(drop);
  }
  uint64_t dropped = significand & ((1ul << uint(drop)) - 1ul);
  uint64_t halfway = 1ul << uint(drop - 1);
  if (dropped > halfway || (dropped == halfway && (kept & 1ul) != 0ul)) {
    kept += 1ul;  // a carry moves to the next binade, or to infinity
  }
  return sign | uint(kept);
}

// Float32 arithmetic on float32 values held as doubles: the operation in
// float64, then rounded once to float32. That is the float32 result: 53
// bits are at least twice 24 and two, so the second rounding never
// differs from a direct one (a product is even exact in float64).
double f32(double x) { return float_value(float_bits_of(x)); }
double f32_mul(double a, double b) {
  precise double r = a * b;
  return f32(r);
}
double f32_add(double a, double b) {
  precise double r = a + b;
  return f32(r);
}
double f32_div(double a, double b) {
  precise double r = a / b;
  return f32(r);
}

// Float32PipelineFloats for pipeline `pipeline`'s encoding and sample i.
uint pipeline_float(uint pipeline, uint i) {
  uint encoding = run_layout[pass.cells + pipeline_first_slot(pipeline)];
  uint stores = db_encoding_stores(encoding);
  uint convention = db_encoding_convention(encoding);
  uint hardware = db_encoding_hardware(encoding);
  double z = f32(eye_depths[i]);
  uint fc = frame_of(i) * DB_JUDGE_FRAME_WORDS;
  if (stores == DB_JUDGE_STORES_WINDOW_DEPTH) {
    double a = float_value(frame_constants[fc + 2u + 2u * hardware]);
    double b = float_value(frame_constants[fc + 3u + 2u * hardware]);
    double window = f32_div(f32_add(f32_mul(a, z), b), z);
    if ((convention & DB_CONVENTION_CLIP_MINUS_ONE) != 0u) {
      window = f32_add(f32_mul(window, 0.5lf), 0.5lf);
    }
    return float_bits_of(window);
  }
  if (stores == DB_JUDGE_STORES_LINEAR) {
    return float_bits_of(f32_div(z, float_value(frame_constants[fc + 1u])));
  }
  return float_bits_of(-z);
}

// encode.cc's unorm storing: the value clamped to [0, 1] (NaN to 0),
// scaled by 2^bits - 1 (exact in float64) and rounded to the nearest
// integer, ties to even, by adding and taking away 2^52. Returns the code.
uint unorm_code(uint value_bits, double scale) {
  double v = float_value(value_bits);
  double clamped = v > 0.0lf ? (v < 1.0lf ? v : 1.0lf) : 0.0lf;
  precise double scaled = clamped * scale;
  precise double rounded = (scaled + 4503599627370496.0lf) - 4503599627370496.0lf;  // 2^52
  return uint(rounded);
}

// encode.cc's FloatToHalf on the bits: ties to even, half subnormals, an
// overflow to infinity from 65520 up, NaN to the quiet 0x7e00.
uint half_code(uint value_bits) {
  uint sign = (value_bits >> 16u) & 0x8000u;
  uint magnitude = value_bits & 0x7fffffffu;
  if (magnitude > 0x7f800000u) {
    return 0x7e00u;
  }
  if (magnitude >= 0x477ff000u) {  // 65520
    return sign | 0x7c00u;
  }
  uint exponent = magnitude >> 23u;  // biased, float32's
  uint significand = (magnitude & 0x7fffffu) | (exponent != 0u ? 0x800000u : 0u);
  // Below 2^-14: multiples of 2^-24, the value times 2^24 rounded. Above:
  // ten fraction bits of the float's 23. Either way a shift by `drop` bits.
  uint kept;
  uint drop;
  if (exponent < 113u) {  // 2^-14 is float32 exponent 113
    if (exponent < 102u) {
      return sign;  // below 2^-25: rounds to zero
    }
    drop = 126u - exponent;  // value * 2^24 = significand * 2^(exponent - 126)
    kept = significand >> drop;
  } else {
    drop = 13u;
    kept = ((exponent - 112u) << 10u) | ((magnitude & 0x7fffffu) >> 13u);
  }
  uint dropped = significand & ((1u << drop) - 1u);
  uint halfway = 1u << (drop - 1u);
  if (dropped > halfway || (dropped == halfway && (kept & 1u) != 0u)) {
    kept += 1u;
  }
  return sign | kept;
}

// encode.cc's HalfToFloat: the float32 bits of a half, exactly.
uint half_fetch_bits(uint code) {
  uint sign = (code & 0x8000u) << 16u;
  uint exponent = (code >> 10u) & 0x1fu;
  uint fraction = code & 0x3ffu;
  if (exponent == 31u) {
    return sign | (fraction == 0u ? 0x7f800000u : 0x7fc00000u);
  }
  if (exponent != 0u) {
    return sign | ((exponent + 112u) << 23u) | (fraction << 13u);
  }
  if (fraction == 0u) {
    return sign;
  }
  // fraction * 2^-24, normal in float32.
  int top = findMSB(fraction);
  return sign | (uint(top + 103) << 23u) | ((fraction << uint(23 - top)) & 0x7fffffu);
}

// What a fetch of depth slot `slot`'s texel returns for a pipeline float,
// as bits.
uint fetched_bits(uint slot, uint value_bits) {
  uint texel = run_layout[pass.cells + pass.depth_slots + slot];
  uint kind = db_texel_kind(texel);
  if (kind == DB_JUDGE_TEXEL_FLOAT32) {
    return value_bits;
  }
  if (kind == DB_JUDGE_TEXEL_FLOAT16) {
    return half_fetch_bits(half_code(value_bits));
  }
  // 1 / (2^16 - 1) and 1 / (2^24 - 1), rounded to float64 (encode.cc's
  // `inverse`), from their bits.
  bool wide = db_texel_unorm_bits(texel) == 24u;
  double scale = wide ? 16777215.0lf : 65535.0lf;
  double inverse = wide ? packDouble2x32(uvec2(0x10000010u, 0x3e700000u))
                        : packDouble2x32(uvec2(0x00100010u, 0x3ef00010u));
  precise double fetched = double(unorm_code(value_bits, scale)) * inverse;
  return float_bits_of(fetched);
}

void main() {
  uint pipeline = gl_WorkGroupID.y;
  uint element = gl_GlobalInvocationID.x;
  if (element >= pass.slice_length) {
    return;
  }
  uint first_slot = pipeline_first_slot(pipeline);
  if (element < pass.lead || element >= pass.lead + pass.count) {
    for (uint slot = first_slot; slot != kNoDepthSlot; slot = pipeline_next_slot(slot)) {
      texel_bits[slot * pass.slice_length + element] = 0u;
    }
    return;
  }
  uint i = element - pass.lead;
  uint value;
  if (pass.phase == 0u) {
    value = pipeline_float(pipeline, i);
    pipeline_float_bits[pipeline * pass.count + i] = value;
  } else {
    value = pipeline_float_bits[pipeline * pass.count + i];
  }
  uint pick = db_coverage_pick(coverage[i]);
  for (uint slot = first_slot; slot != kNoDepthSlot; slot = pipeline_next_slot(slot)) {
    texel_bits[slot * pass.slice_length + element] =
        pick != 0u ? edge_texel_bits[(frame_of(i) * pass.depth_slots + slot) * 4u + pick - 1u]
                   : fetched_bits(slot, value);
  }
}
