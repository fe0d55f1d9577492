// Encode: what a depth buffer or G-buffer channel holds for a scene point,
// rounded exactly as an ideal pipeline and the storage format round it, and
// what a stored value denotes.
//
// The pipeline model, the same for every format:
//   1. the exact value: window depth (hardware), eye depth / far (linear) or
//      view z (view-z);
//   2. the rasterizer/shader produces it as a float32, correctly rounded;
//      with GL-style clip depth the float32 is NDC depth in [-1, 1] and the
//      viewport transform 0.5 * ndc + 0.5 rounds once more;
//   3. the format converts that float: unorm round-to-nearest-even of
//      value * (2^b - 1), float16 round-to-nearest-even, float32 as is.
// A texture fetch returns the texel as float32: the correctly rounded value
// of the code (exact for float formats). Backends read the fetched float;
// the reference reads the exact value of the code.
#pragma once

#include <cstdint>

#include "bench/cells.h"
#include "bench/double_double.h"
#include "bench/sampler.h"

namespace depthbench {

struct StoredDepth {
  std::uint32_t code = 0;  // the texel bits: unorm integer, float16 or float32 bits
  float fetched = 0.0f;    // what a texture fetch returns for it
};

StoredDepth EncodeEyeDepth(Encoding encoding, const Frame& frame, double eye_depth);
StoredDepth EncodeEdge(Encoding encoding, const Frame& frame, DepthPick pick);

// Eye depth the code denotes, exact to double-double precision. Zero, a
// negative value or +infinity for codes that denote the camera or infinity.
DoubleDouble DecodeEyeDepth(Encoding encoding, const Frame& frame, std::uint32_t code);

// The exact value of a texel code, and the float32 a fetch returns for it.
DoubleDouble TexelValue(Format format, std::uint32_t code);
float FetchTexel(Format format, std::uint32_t code);

// Format conversions of step 3, exposed for tests.
std::uint32_t FloatToUnorm(float value, int bits);     // clamps to [0, 1] first
std::uint16_t FloatToHalf(float value);                 // round to nearest even
float HalfToFloat(std::uint16_t half);
// Counts how often the encoder needed MPFR to decide a rounding (tests).
std::uint64_t MpfrFallbackCount();

}  // namespace depthbench
