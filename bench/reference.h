// Reference: for each sample, the true scene point and the point that the
// stored depth value denotes, from the frame's exact parameters.
//
// Both points lie on the pixel's ray through the camera, so the reference
// keeps, per sample, the world-space ray at unit eye depth, and per
// (encoding, sample) two eye depths: the true one and the denoted one.
// The ray and the decode run in long double through the ld:: instantiation
// of shared/ (pixel centre, NDC, the cancellation-free depth decode), so
// every figure is accurate to about 2^-60 before the final rounding to
// double; tests/reference_test.cc checks this against MPFR at far/near up to
// 1e12. The judge then forms camera-relative positions in double, where a
// float32 output minus the float32 camera position is exact.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "bench/cells.h"
#include "bench/sampler.h"

namespace depthbench {

enum class ReferenceStatus : std::uint8_t {
  kJudged,      // a finite point inside the frustum
  kDegenerate,  // the point is the camera or at infinity: nothing to measure
  kOutside,     // a finite point outside the frustum (nearer than near, or
                // beyond a finite far plane): only NaN/Inf outputs count
};

struct ReferenceSample {
  double true_depth = 0.0;     // eye depth of the true point
  double denoted_depth = 0.0;  // eye depth the stored value denotes (DBL_MAX for infinity)
  double inverse_distance_sq = 0.0;  // 1 / |true point - camera|^2 (0 unless judged)
  std::uint8_t joint_band = 0;
  ReferenceStatus status = ReferenceStatus::kDegenerate;
};

// World-space ray through the pixel centre at unit eye depth:
// R * (ndc.x * tan_x, ndc.y * tan_y, -1).
glm::dvec3 PixelRay(const Frame& frame, std::uint32_t x, std::uint32_t y);

// What the reference needs of one sample, whatever the encoding.
struct SampleFacts {
  DepthPick pick = DepthPick::kEyeDepth;
  double eye_depth = 0.0;       // for eye-depth picks
  double ray_length_sq = 0.0;   // |PixelRay|^2
  // For eye-depth picks, shared by every encoding: 1 / (eye depth * |ray|)^2
  // and the eye-depth band.
  double inverse_distance_sq = 0.0;
  std::uint8_t depth_band = 0;
};
SampleFacts FactsOf(const Frame& frame, const PixelSample& sample, const glm::dvec3& ray);

// The reference of a sample under an encoding that stored `code`, and the
// square of its relative storage error |denoted - true| / |true|.
ReferenceSample ReferenceFor(const Frame& frame, const SampleFacts& sample, Encoding encoding,
                             std::uint32_t code, double& storage_square);

}  // namespace depthbench
