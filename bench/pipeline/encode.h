// Encode: what a depth buffer or G-buffer channel holds for a scene point,
// produced as the pipeline produces it and rounded exactly as the storage
// format rounds it, and what a stored value denotes.
//
// The pipeline, the same for every format:
//   1. the value: window depth (hardware), eye depth / far (linear) or view
//      z (view-z);
//   2. produced as a float32, by the domain's ProductionModel (domain.h):
//      kFloat32: as a GPU computes it from the float32 constants the
//        shaders receive too (A and B of ndc = A + B / z, the far plane):
//        z = float(eye depth); clip = A * z + B, ndc = clip / z (w = z),
//        each operation rounded to float32; GL-style clip depth then the
//        viewport transform 0.5 * ndc + 0.5 in float32; an orthographic
//        convention's ndc = B * z + A (w = 1, no divide);
//      kExact: the exact value correctly rounded (GL-style: exact NDC depth
//        rounded, then the viewport transform in float32);
//   3. the format converts that float: unorm round-to-nearest-even of
//      value * (2^b - 1), float16 round-to-nearest-even, float32 as is.
// A texture fetch returns the texel as float32: the correctly rounded value
// of the code (exact for float formats). Backends read the fetched float.
//
// What a value denotes (DecodeEyeDepths) is the eye depth that exact
// arithmetic gives for it under the same mapping: the float32 constants
// (kFloat32) or the exact frame (kExact). Decoding the pipeline's float
// gives the produced depth; decoding the fetched texel, the stored depth.
// Their differences from the truth and from each other are the production
// and the storage error (reference.h).
//
// "Correctly rounded" is meant literally: kExact evaluates the exact value
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

// The depth mapping of n samples, an array per parameter: the frame's exact
// planes (far 0 for an infinite far plane), and the float32 constants the
// shaders receive: A and B of ndc = A + B / z (hardware formats) or the far
// plane in `a` (linear formats); view z needs neither.
struct DepthMappings {
  const double* near = nullptr;
  const double* far = nullptr;
  const double* a = nullptr;
  const double* b = nullptr;
  DepthMappings At(std::size_t first) const { return {near + first, far + first, a + first, b + first}; }
};
// The float32 constants of one frame and encoding (shader_constants.h).
void FrameMapping(Encoding encoding, const Frame& frame, double& a, double& b);

// Steps 1 and 2: the float32 the pipeline produces for eye depth z. It
// depends only on the convention and on what the format stores, so the
// formats of one convention share it.
float PipelineFloat(Encoding encoding, ProductionModel model, const Frame& frame, double eye_depth);
// The same for n samples, four lanes at a time; every lane computes exactly
// what the scalar form does.
void PipelineFloats(Encoding encoding, ProductionModel model, const DepthMappings& mapping, const double* eye_depth,
                    std::size_t n, float* out);
// Step 3 and the fetch, for one value and for n.
StoredDepth StoreFloat(Format format, float value);
void StoreFloats(Format format, const float* values, std::size_t n, std::uint32_t* codes, float* fetched);

inline StoredDepth EncodeEyeDepth(Encoding encoding, ProductionModel model, const Frame& frame, double eye_depth) {
  return StoreFloat(encoding.format, PipelineFloat(encoding, model, frame, eye_depth));
}
StoredDepth EncodeEdge(Encoding encoding, const Frame& frame, DepthPick pick);

// Eye depth a float value (a fetched texel, or the pipeline's float)
// denotes, in double-double: under kExact through the cancellation-free
// decode of shared/depth_mapping.h (relative error below 2^-100;
// tests/reference_test.cc checks it against MPFR), under kFloat32 as
// B / (ndc - A) with the float constants ((ndc - A) / B when orthographic).
// Zero or +infinity for values that
// denote the camera or infinity.
DoubleDouble DecodeEyeDepth(Encoding encoding, ProductionModel model, const Frame& frame, float value);
// The same for n values, four lanes at a time, as the two parts of each
// double-double (the low parts only where lo is not null). Every lane
// computes exactly what the scalar form does.
// Compiled for each instruction set `isa` can name (bench/base/isa.h).
void DecodeEyeDepths(Encoding encoding, ProductionModel model, const DepthMappings& mapping, const float* values,
                     std::size_t n, double* hi, double* lo, Isa isa = Isa::kWidest);

// Format conversions, exposed for tests.
float FetchTexel(Format format, std::uint32_t code);
// How far apart two texel codes of a format lie in its values: the
// difference of unorm codes; for float codes, the representable values
// stepped over between them (ulps), across binades and through zero (+0
// and -0 are one value), saturating at 2^32 - 1.
std::uint32_t CodeDistance(Format format, std::uint32_t a, std::uint32_t b);
// CodeDistance's line, for loops over many codes of one format: the sign
// bit of a float format's codes (0 for unorm), and a code's place on the
// line on which consecutive values are consecutive integers (a float's
// magnitude bits, negated where it is negative; a unorm code itself).
std::uint32_t CodeSignBit(Format format);
inline std::int64_t CodeOnLine(std::uint32_t code, std::uint32_t sign_bit) {
  const auto magnitude = static_cast<std::int64_t>(code & (sign_bit - 1));
  return (code & sign_bit) != 0 ? -magnitude : magnitude;
}
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
