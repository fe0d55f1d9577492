#include "bench/reference.h"

#include <cfloat>
#include <cmath>

#include "bench/bands.h"
#include "bench/encode.h"
#include "bench/formulas.h"

namespace depthbench {
namespace {

// Relative slack on the frustum's planes: stored values at the planes
// themselves decode to within a few float32 steps of them.
constexpr double kPlaneSlack = 0x1p-20;

}  // namespace

glm::dvec3 PixelRay(const Frame& frame, std::uint32_t x, std::uint32_t y) {
  using L = long double;
  const L tan_y = frame.tan_half_fov_y;
  const L tan_x = static_cast<L>(frame.aspect) * tan_y;
  const ld::vec4 resolution(frame.width, frame.height, 1.0L / frame.width, 1.0L / frame.height);
  const ld::vec2 ndc = ld::ndc_from_uv(ld::uv_from_pixel(static_cast<L>(x), static_cast<L>(y), resolution));
  const ld::vec3 view(ndc.x * tan_x, ndc.y * tan_y, -1.0L);
  const glm::dmat3& r = frame.rotation;
  glm::dvec3 ray;
  for (int row = 0; row < 3; ++row) {
    ray[row] = static_cast<double>(r[0][row] * view.x + r[1][row] * view.y + r[2][row] * view.z);
  }
  return ray;
}

SampleFacts FactsOf(const Frame& frame, const PixelSample& sample, const glm::dvec3& ray) {
  SampleFacts facts;
  facts.pick = sample.pick;
  facts.eye_depth = sample.eye_depth;
  facts.ray_length_sq = glm::dot(ray, ray);
  if (sample.pick == DepthPick::kEyeDepth) {
    facts.inverse_distance_sq = 1.0 / (sample.eye_depth * sample.eye_depth * facts.ray_length_sq);
    facts.depth_band = static_cast<std::uint8_t>(DepthBand(sample.eye_depth / frame.near));
  }
  return facts;
}

ReferenceSample ReferenceFor(const Frame& frame, const SampleFacts& sample, Encoding encoding,
                             std::uint32_t code, double& storage_square) {
  const long double denoted = DecodeEyeDepth(encoding, frame, code);
  // Stored-value picks have no scene point of their own: the truth is what
  // the stored value denotes, and their storage error is zero.
  const long double truth = sample.pick == DepthPick::kEyeDepth ? sample.eye_depth : denoted;

  const bool eye_pick = sample.pick == DepthPick::kEyeDepth;

  ReferenceSample r;
  r.true_depth = static_cast<double>(truth);
  r.denoted_depth = std::isfinite(denoted) ? static_cast<double>(denoted) : DBL_MAX;
  const ConventionInfo& convention = Info(encoding.convention);
  const bool infinite_far = convention.hardware && (convention.bits & f32::DB_CONVENTION_INFINITE) != 0u;
  int depth_band = sample.depth_band;
  if (!eye_pick) {
    const double depth_over_near = r.true_depth / frame.near;
    depth_band = DepthBand(std::isfinite(depth_over_near) ? depth_over_near : DBL_MAX);
  }
  r.joint_band = static_cast<std::uint8_t>(
      JointBand(infinite_far ? kInfiniteRatioBand : RatioBand(frame.ratio()), depth_band));
  storage_square = 0.0;
  if (!(truth > 0.0L) || !std::isfinite(truth)) {
    r.status = ReferenceStatus::kDegenerate;
    return r;
  }
  const double far = infinite_far ? INFINITY : frame.depth_limit;
  if (r.true_depth < frame.near * (1.0 - kPlaneSlack) || r.true_depth > far * (1.0 + kPlaneSlack)) {
    r.status = ReferenceStatus::kOutside;
    return r;
  }
  r.status = ReferenceStatus::kJudged;
  r.inverse_distance_sq =
      eye_pick ? sample.inverse_distance_sq : 1.0 / (r.true_depth * r.true_depth * sample.ray_length_sq);
  // The difference of the two depths is taken in long double (they may be
  // close); its ratio to the distance needs no more than double. Both
  // points lie on the same ray, so the relative error of the position is
  // the relative error of the depth.
  const double difference = static_cast<double>(denoted - truth);
  storage_square = difference * difference * r.inverse_distance_sq * sample.ray_length_sq;
  return r;
}

}  // namespace depthbench
