// Reference: for each sample, the true scene point, the point the
// pipeline's float denotes (produced) and the point the fetched texel
// denotes (stored), the last two under the pipeline's own mapping
// (encode.h).
//
// Both points lie on the pixel's line: its ray through the camera, or in an
// orthographic frame the line along the view axis through the pixel's
// point at eye depth 0 (its offset). So the reference keeps, per sample, the
// world-space direction per unit of eye depth (the ray) and the offset's
// squared length (0 for a ray), and per (encoding, sample) two eye depths:
// the true one and the denoted one.
// The ray runs in long double (the ld:: instantiation of shared/: pixel
// centre and NDC) and the decode in double-double (hp4::, the
// cancellation-free depth mapping), so every figure is accurate to 2^-60 or
// better before the final rounding to double; tests/reference_test.cc
// checks this against MPFR at far/near up to 1e12. The judge then forms
// camera-relative positions in double, where a float32 output minus the
// float32 camera position is exact.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "bench/base/isa.h"
#include "bench/numerics/double_double.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/sampler.h"

namespace depthbench {

enum class ReferenceStatus : std::uint8_t {
  kJudged,      // a finite point inside the frustum
  kDegenerate,  // the point is the camera, at infinity, or beyond what float32
                // world coordinates can hold: nothing to measure
  kOutside,     // a finite point outside the frustum (nearer than near,
                // beyond a finite far plane) or outside the domain's eye-depth
                // range of interest: only NaN/Inf outputs count
  kUndrawn,     // the raster form's rasterizer left the sample's texel
                // unwritten: nothing of the sample's to judge
};

// The reference of one (encoding, sample).
struct ReferenceSample {
  double true_depth = 0.0;           // eye depth of the true point
  double denoted_depth = 0.0;        // eye depth the stored value denotes (DBL_MAX for infinity)
  double inverse_distance_sq = 0.0;  // 1 / |true point - camera|^2 (0 unless judged)
  std::uint8_t joint_band = 0;
  ReferenceStatus status = ReferenceStatus::kDegenerate;
  // Whether float32 world coordinates can hold the denoted point: when not
  // (the stored value denotes infinity or the camera, or lies beyond the
  // float range), no arithmetic could return it finitely, so a non-finite
  // output is expected, not a finding, and there is no shader error.
  bool stored_holdable = true;
};

// ReferenceSample fields, one array each (the judge reads them in SIMD
// lanes), plus the squares of the relative storage and production errors.
struct ReferenceArrays {
  std::vector<double> true_depth, denoted_depth, inverse_distance_sq, storage_square, production_square;
  std::vector<std::uint8_t> joint_band, stored_holdable;
  std::vector<ReferenceStatus> status;

  void Resize(std::size_t n);
  ReferenceSample Get(std::size_t at) const;
};

// What every sample of a frame repeats in SampleArrays: its planes, the
// eye depths the domain is about, and its far/near band.
struct FramePlanes {
  double near = 0.0, far = 0.0;                   // far 0 when infinite
  double depth_limit = 0.0;                       // the largest eye depth
  double interest_min = 0.0, interest_max = 0.0;  // near..inf when unrestricted
  std::uint8_t ratio_band = 0;
};
FramePlanes PlanesOf(const Frame& frame);

// Which of SampleArrays' fields a batch fills. kAll: every one. kDrawn:
// only what the sampler drew (pick, eye depth, coverage), for a judge on a
// device that derives the rest from the frame and the ray itself.
enum class SampleFields : std::uint8_t { kAll, kDrawn };

// What the reference needs of each sample, whatever the encoding.
struct SampleArrays {
  std::vector<DepthPick> pick;
  std::vector<double> eye_depth;                   // for eye-depth picks (near for the others)
  std::vector<double> near, far;                   // the frame's planes (far 0 when infinite)
  std::vector<double> depth_limit;                 // the frame's largest eye depth
  std::vector<double> interest_min, interest_max;  // eye depths the domain is about (near..inf when unrestricted)
  std::vector<double> ray_length_sq;               // |PixelRay|^2
  std::vector<double> offset_length_sq;            // |PixelOffset|^2 (0 in a perspective frame)
  std::vector<double> inverse_distance_sq;         // 1 / (|offset|^2 + (eye depth * |ray|)^2), for eye-depth picks
  std::vector<std::uint8_t> depth_band;            // of the eye depth, for eye-depth picks
  std::vector<std::uint8_t> ratio_band;            // the frame's far/near band
  std::vector<Coverage> coverage;                  // natural, or the coverage kind (bands.h)

  // Sizes the arrays `fields` fills to n samples, the others to none.
  void Resize(std::size_t n, SampleFields fields = SampleFields::kAll);
  // Fills entry i for a sample of `frame` whose ray is `ray` (and whose
  // offset has squared length `offset_length_sq`): every field, or what was
  // drawn only.
  void Set(std::size_t i, const Frame& frame, const PixelSample& sample, const glm::dvec3& ray,
           double offset_length_sq = 0.0);
  void SetDrawn(std::size_t i, const Frame& frame, const PixelSample& sample);
};

// The world-space ray through pixel (x, y)'s centre at unit eye depth,
// R * (ndc.x * tan_x, ndc.y * tan_y, -1), in float64 as a device draws it
// too (shared/draw.h's draw_pixel_ray); in an orthographic frame, the view
// axis -R[2], the same for every pixel.
glm::dvec3 PixelRay(const Frame& frame, std::uint32_t x, std::uint32_t y);
// The camera-relative world point of the pixel at eye depth 0: 0 in a
// perspective frame; R * (ndc.x * half width + centre x, ndc.y * half
// height + centre y, 0) in an orthographic one. The pixel's scene point at
// eye depth z is camera + PixelOffset + z * PixelRay.
glm::dvec3 PixelOffset(const Frame& frame, std::uint32_t x, std::uint32_t y);

// The references of samples [first, first + n) under an encoding whose
// stored values denote eye depths `denoted` and whose pipeline floats
// denote `produced` (DecodeEyeDepths, rounded to double; k-th entry for
// sample first + k),
// written to out at [out_first, out_first + n).
// Compiled for each instruction set `isa` can name (bench/base/isa.h).
void References(Encoding encoding, const SampleArrays& samples, std::size_t first, std::size_t n, const double* denoted,
                const double* produced, ReferenceArrays& out, std::size_t out_first, Isa isa = Isa::kWidest);

}  // namespace depthbench
