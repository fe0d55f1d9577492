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
//
// "Correctly rounded" is meant literally: step 2 evaluates the exact value
// in double-double, and where that lies too close to a float rounding
// boundary to decide, in MPFR.
#pragma once

#include <cstdint>

#include "bench/base/isa.h"
#include "bench/numerics/double_double.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/sampler.h"

namespace depthbench {

struct StoredDepth {
  std::uint32_t code = 0;  // the texel bits: unorm integer, float16 or float32 bits
  float fetched = 0.0f;    // what a texture fetch returns for it
};

// Steps 1 and 2: the float32 the pipeline produces for eye depth z. It
// depends only on the convention and on what the format stores, so the
// formats of one convention share it.
float PipelineFloat(Encoding encoding, const Frame& frame, double eye_depth);
// The same for n samples, four lanes at a time (far is 0 for an infinite
// far plane); every lane computes exactly what the scalar form does.
void PipelineFloats(Encoding encoding, const double* near, const double* far, const double* eye_depth, std::size_t n,
                    float* out);
// Step 3 and the fetch, for one value and for n.
StoredDepth StoreFloat(Format format, float value);
void StoreFloats(Format format, const float* values, std::size_t n, std::uint32_t* codes, float* fetched);

inline StoredDepth EncodeEyeDepth(Encoding encoding, const Frame& frame, double eye_depth) {
  return StoreFloat(encoding.format, PipelineFloat(encoding, frame, eye_depth));
}
StoredDepth EncodeEdge(Encoding encoding, const Frame& frame, DepthPick pick);

// Eye depth a stored texel denotes, in double-double through the
// cancellation-free decode of shared/depth_mapping.h (relative error below
// 2^-100; tests/reference_test.cc checks it against MPFR). Zero or
// +infinity for texels that denote the camera or infinity.
DoubleDouble DecodeEyeDepth(Encoding encoding, const Frame& frame, StoredDepth stored);
// The same for n texels, four lanes at a time (far is 0 for an infinite far
// plane), as the two parts of each double-double. Every lane computes
// exactly what the scalar form does.
// Compiled for each instruction set `isa` can name (bench/base/isa.h).
void DecodeEyeDepths(Encoding encoding, const double* near, const double* far, const std::uint32_t* codes,
                     const float* fetched, std::size_t n, double* hi, double* lo, Isa isa = Isa::kWidest);

// Format conversions, exposed for tests.
float FetchTexel(Format format, std::uint32_t code);
std::uint32_t FloatToUnorm(float value, int bits);  // clamps to [0, 1] first
std::uint16_t FloatToHalf(float value);             // round to nearest even
float HalfToFloat(std::uint16_t half);

// How often a value fell exactly on a tie between two floats, and how often
// of those MPFR had to settle it (for tests and notes).
struct EncodeFallbacks {
  std::uint64_t ties = 0;
  std::uint64_t mpfr = 0;
};
EncodeFallbacks EncodeFallbackCounts();

}  // namespace depthbench
