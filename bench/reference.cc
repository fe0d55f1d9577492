#include "bench/reference.h"

#include <cfloat>
#include <cmath>

#include "bench/bands.h"
#include "bench/formulas.h"

namespace depthbench {
namespace {

// Relative slack on the frustum's planes: stored values at the planes
// themselves decode to within a few float32 steps of them.
constexpr double kPlaneSlack = 0x1p-20;
// The largest float32, squared: distances beyond it overflow a world position.
constexpr double kLargestFloatSquared = static_cast<double>(FLT_MAX) * static_cast<double>(FLT_MAX);

}  // namespace

void ReferenceArrays::Resize(std::size_t n) {
  for (auto* v : {&true_depth, &denoted_depth, &inverse_distance_sq, &storage_square}) v->resize(n);
  joint_band.resize(n);
  status.resize(n);
}

ReferenceSample ReferenceArrays::Get(std::size_t at) const {
  return {true_depth[at], denoted_depth[at], inverse_distance_sq[at], joint_band[at], status[at]};
}

void SampleArrays::Resize(std::size_t n) {
  pick.resize(n);
  for (auto* v : {&eye_depth, &near, &far, &depth_limit, &interest_min, &interest_max, &ray_length_sq,
                  &inverse_distance_sq}) {
    v->resize(n);
  }
  depth_band.resize(n);
  ratio_band.resize(n);
}

void SampleArrays::Set(std::size_t i, const Frame& frame, const PixelSample& sample, const glm::dvec3& ray) {
  const bool eye = sample.pick == DepthPick::kEyeDepth;
  pick[i] = sample.pick;
  eye_depth[i] = eye ? sample.eye_depth : frame.near;
  near[i] = frame.near;
  far[i] = frame.finite() ? frame.far : 0.0;
  depth_limit[i] = frame.depth_limit;
  interest_min[i] = frame.depth_restricted ? frame.eye_depth_min : frame.near;
  interest_max[i] = frame.depth_restricted ? frame.eye_depth_max : INFINITY;
  ray_length_sq[i] = glm::dot(ray, ray);
  inverse_distance_sq[i] = 1.0 / (eye_depth[i] * eye_depth[i] * ray_length_sq[i]);
  depth_band[i] = static_cast<std::uint8_t>(DepthBand(eye_depth[i] / frame.near));
  ratio_band[i] = static_cast<std::uint8_t>(RatioBand(frame.ratio()));
}

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

void References(Encoding encoding, const SampleArrays& samples, std::size_t first, std::size_t n,
                const double* denoted_hi, const double* denoted_lo, ReferenceArrays& out, std::size_t out_first) {
  const ConventionInfo& convention = Info(encoding.convention);
  const bool infinite_far = convention.hardware && (convention.bits & f32::DB_CONVENTION_INFINITE) != 0u;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = first + k, o = out_first + k;
    // Stored-value picks have no scene point of their own: the truth is
    // what the stored value denotes, and their storage error is zero.
    const bool eye = samples.pick[i] == DepthPick::kEyeDepth;
    const DoubleDouble denoted = DoubleDouble::FromParts(denoted_hi[k], denoted_lo[k]);
    const DoubleDouble truth = eye ? DoubleDouble(samples.eye_depth[i]) : denoted;
    const double t = truth.hi();
    const double near = samples.near[i];
    // (Stored-value picks are rare: their band and distance are worked out
    // here, behind a branch that predicts well.)
    int depth_band = samples.depth_band[i];
    if (!eye) depth_band = DepthBand(t / near);
    out.true_depth[o] = t;
    out.denoted_depth[o] = std::isfinite(denoted.hi()) ? denoted.hi() : DBL_MAX;
    out.joint_band[o] = static_cast<std::uint8_t>(
        JointBand(infinite_far ? kInfiniteRatioBand : samples.ratio_band[i], depth_band));
    const double length_sq = samples.ray_length_sq[i];
    // A point float32 world coordinates cannot hold (an overflowing
    // reconstruction is then the right answer) is no more judged than one
    // at infinity.
    const bool degenerate = !(t > 0.0) || !(t * t * length_sq < kLargestFloatSquared);
    const double far = std::min(infinite_far ? INFINITY : samples.depth_limit[i], samples.interest_max[i]);
    const double nearest = std::max(near, samples.interest_min[i]);
    const bool outside = t < nearest * (1.0 - kPlaneSlack) || t > far * (1.0 + kPlaneSlack);
    const ReferenceStatus status =
        degenerate ? ReferenceStatus::kDegenerate : outside ? ReferenceStatus::kOutside : ReferenceStatus::kJudged;
    out.status[o] = status;
    double inverse_distance_sq = samples.inverse_distance_sq[i];
    if (!eye) inverse_distance_sq = 1.0 / (t * t * length_sq);
    if (status != ReferenceStatus::kJudged) inverse_distance_sq = 0.0;
    out.inverse_distance_sq[o] = inverse_distance_sq;
    // The difference of the two depths is taken in double-double (they may
    // be close); its ratio to the distance needs no more than double. Both
    // points lie on the same ray, so the relative error of the position is
    // the relative error of the depth.
    const double difference = (denoted - truth).hi();
    out.storage_square[o] = difference * difference * inverse_distance_sq * length_sq;
  }
}

}  // namespace depthbench
