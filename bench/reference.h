// Reference: for each sample, the true scene point and the point that the
// stored depth value denotes, from the frame's exact parameters.
//
// Everything that can cancel is evaluated in double-double through the
// hp:: instantiation of shared/ (pixel centre, NDC, the depth decode, the
// ray); the final camera-relative points are rounded to double, 29 bits below
// float32's rounding. Points are kept relative to the camera: the judge
// subtracts the (float32-exact) camera position from a backend's world
// position in double, which is exact, so no large world coordinate ever
// enters the reference's own rounding.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "bench/cells.h"
#include "bench/formulas.h"
#include "bench/sampler.h"

namespace depthbench {

struct ReferenceSample {
  glm::dvec3 truth{0.0};    // true point - camera position
  glm::dvec3 denoted{0.0};  // point the stored value denotes - camera position
  // 1 / |truth|^2; 0 marks a degenerate sample (the true point at the camera
  // or at infinity, e.g. stored 1 under standard Z with an infinite far
  // plane), which is counted but not judged.
  double inverse_distance_sq = 0.0;
  double storage_square = 0.0;  // (|denoted - truth| / |truth|)^2
  std::uint8_t joint_band = 0;
  std::uint8_t distance_band = 0;
};

class SampleReference {
 public:
  SampleReference(const Frame& frame, const PixelSample& sample);

  // The reference under an encoding that stored `code` for this sample.
  ReferenceSample For(Encoding encoding, std::uint32_t code) const;

  const hp::vec3& ray() const { return ray_; }

 private:
  const Frame& frame_;
  const PixelSample& sample_;
  hp::vec3 ray_;  // world-space ray at unit eye depth through the pixel centre
  int distance_band_;
};

}  // namespace depthbench
