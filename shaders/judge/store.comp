#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
// Storage on the device (bench/device_judge/device_judge.h): every depth
// slot's texels, made from its pipeline's float32 as the format stores it
// and as a texture fetch returns it (encode.cc's StoreFloats), written
// straight into the buffer the reconstruction pass reads. The host then
// uploads the pipelines' floats alone (the reference reads them anyway),
// not a texel per depth slot and sample.
//
// Every step is integer arithmetic on the bits, or float64 arithmetic that
// is exact or rounded once (a product), so that each texel equals the
// host's, bit for bit (tests/device_judge_test.cc): no conversion between
// float widths is left to the device, whose rounding of them Vulkan does
// not fix and whose handling of float32 subnormals differs (bindings.glsl).
//
// Phase 0: workgroup row y writes depth slot y's whole slice (the lead and
// the padding as zeros), all but the stored-value picks. Phase 1:
// invocation k writes the k-th pick of every slot, from the texels the
// host made for it (the picks are a few per cent of the samples, and their
// values depend on the format alone, or on the frame's far plane).
#include "../../shared/compat.h"
#include "../../shared/judge.h"

layout(local_size_x = 64) in;

#define DB_TEXELS_WRITABLE
#include "bindings.glsl"

// The float32 nearest to a double in [2^-126, 1] (a unorm fetch), ties to
// even, from the double's bits.
uint float_bits_of_unit(double x) {
  uvec2 words = unpackDouble2x32(x);  // x: low word, y: high word
  uint64_t bits = (uint64_t(words.y) << 32) | uint64_t(words.x);
  if (bits == 0ul) {
    return 0u;
  }
  // 52 fraction bits to 23: 29 to drop; the exponent moves from a bias of
  // 1023 to 127.
  uint64_t exponent = (bits >> 52) - 1023ul + 127ul;
  uint64_t kept = (exponent << 23) | ((bits >> 29) & 0x7ffffful);
  uint64_t dropped = bits & 0x1ffffffful;
  const uint64_t halfway = 0x10000000ul;
  if (dropped > halfway || (dropped == halfway && (kept & 1ul) != 0ul)) {
    kept += 1ul;  // a carry into the exponent is the next binade's first float
  }
  return uint(kept);
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
  uint texel = run_layout[pass.cells + pass.depth_slots + slot];  // DB_JUDGE_TEXEL_*
  uint kind = texel & 0xffu;
  if (kind == DB_JUDGE_TEXEL_FLOAT32) {
    return value_bits;
  }
  if (kind == DB_JUDGE_TEXEL_FLOAT16) {
    return half_fetch_bits(half_code(value_bits));
  }
  // 1 / (2^16 - 1) and 1 / (2^24 - 1), rounded to float64 (encode.cc's
  // `inverse`), from their bits.
  bool wide = (texel >> 8u) == 24u;
  double scale = wide ? 16777215.0lf : 65535.0lf;
  double inverse = wide ? packDouble2x32(uvec2(0x10000010u, 0x3e700000u))
                        : packDouble2x32(uvec2(0x00100010u, 0x3ef00010u));
  precise double fetched = double(unorm_code(value_bits, scale)) * inverse;
  return float_bits_of_unit(fetched);
}

void main() {
  uint slot = gl_WorkGroupID.y;
  if (pass.phase != 0u) {
    uint k = gl_GlobalInvocationID.x;
    if (k < pass.edges) {
      texel_bits[slot * pass.slice_length + pass.lead + edge_samples[k]] = edge_texel_bits[slot * pass.edges + k];
    }
    return;
  }
  uint element = gl_GlobalInvocationID.x;
  if (element >= pass.slice_length) {
    return;
  }
  uint at = slot * pass.slice_length + element;
  if (element < pass.lead || element >= pass.lead + pass.count) {
    texel_bits[at] = 0u;
    return;
  }
  uint i = element - pass.lead;
  if ((coverage[i] & 0x100u) != 0u) {
    return;  // a stored-value pick: phase 1 writes it
  }
  uint pipeline = run_layout[pass.cells + slot] >> 16u;
  texel_bits[at] = fetched_bits(slot, pipeline_float_bits[pipeline * pass.count + i]);
}
