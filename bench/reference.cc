#include "bench/reference.h"

#include <cmath>

#include "bench/bands.h"
#include "bench/encode.h"
#include "bench/shader_constants.h"

namespace depthbench {
namespace {

using DD = DoubleDouble;

glm::dvec3 Scale(const hp::vec3& ray, DD depth) {
  return {(ray.x * depth).ToDouble(), (ray.y * depth).ToDouble(), (ray.z * depth).ToDouble()};
}

bool UsableDepth(DD z) { return z.hi() > 0.0 && std::isfinite(z.hi()); }

}  // namespace

SampleReference::SampleReference(const Frame& frame, const PixelSample& sample)
    : frame_(frame),
      sample_(sample),
      ray_(PixelRay(frame, sample.x, sample.y)),
      distance_band_(DistanceBand(frame.camera_distance())) {}

ReferenceSample SampleReference::For(Encoding encoding, std::uint32_t code) const {
  const DD denoted_depth = DecodeEyeDepth(encoding, frame_, code);
  // Stored-value picks have no scene point of their own: the truth is what
  // the stored value denotes, and their storage error is zero.
  const DD true_depth = sample_.pick == DepthPick::kEyeDepth ? DD(sample_.eye_depth) : denoted_depth;

  ReferenceSample r;
  r.distance_band = static_cast<std::uint8_t>(distance_band_);
  const bool infinite = (Info(encoding.convention).bits & f32::DB_CONVENTION_INFINITE) != 0u;
  const int ratio_band = infinite ? kInfiniteRatioBand : RatioBand(frame_.ratio());
  const double depth_over_near = true_depth.hi() / frame_.near;
  r.joint_band = static_cast<std::uint8_t>(
      JointBand(ratio_band, DepthBand(std::isfinite(depth_over_near) ? depth_over_near : 1e300)));
  if (!UsableDepth(true_depth)) return r;  // degenerate: inverse_distance_sq stays 0

  r.truth = Scale(ray_, true_depth);
  r.inverse_distance_sq = 1.0 / glm::dot(r.truth, r.truth);
  if (!std::isfinite(denoted_depth.hi())) {
    // Stored value that denotes infinity for a finite true point: every
    // error against it is infinite (avoid inf * 0 = NaN in the components).
    r.denoted = glm::dvec3(INFINITY);
    r.storage_square = INFINITY;
    return r;
  }
  r.denoted = Scale(ray_, denoted_depth);
  // Both points lie on the same ray, so the relative storage error is the
  // relative depth error, evaluated without rounding the points first.
  const double relative = ((denoted_depth - true_depth) / true_depth).ToDouble();
  r.storage_square = relative * relative;
  return r;
}

}  // namespace depthbench
