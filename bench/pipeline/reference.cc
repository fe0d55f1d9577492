#include "bench/pipeline/reference.h"

#include <cfloat>
#include <cmath>
#include <cstring>

#include "bench/numerics/formulas.h"
#include "bench/pipeline/bands.h"

namespace depthbench {
namespace {

// Relative slack on the frustum's planes: stored values at the planes
// themselves decode to within a few float32 steps of them.
constexpr double kPlaneSlack = 0x1p-20;
// The largest float32, squared: distances beyond it overflow a world position.
constexpr double kLargestFloatSquared = static_cast<double>(FLT_MAX) * static_cast<double>(FLT_MAX);

}  // namespace

void ReferenceArrays::Resize(std::size_t n) {
  for (auto* v : {&true_depth, &denoted_depth, &inverse_distance_sq, &storage_square, &production_square}) {
    v->resize(n);
  }
  joint_band.resize(n);
  stored_holdable.resize(n);
  status.resize(n);
}

ReferenceSample ReferenceArrays::Get(std::size_t at) const {
  return {true_depth[at], denoted_depth[at], inverse_distance_sq[at],
          joint_band[at], status[at],        stored_holdable[at] != 0};
}

FramePlanes PlanesOf(const Frame& frame) {
  return {.near = frame.near,
          .far = frame.finite() ? frame.far : 0.0,
          .depth_limit = frame.depth_limit,
          .interest_min = frame.depth_restricted ? frame.eye_depth_min : frame.near,
          .interest_max = frame.depth_restricted ? frame.eye_depth_max : INFINITY,
          .ratio_band = static_cast<std::uint8_t>(RatioBand(frame.ratio()))};
}

void SampleArrays::Resize(std::size_t n, SampleFields fields) {
  pick.resize(n);
  eye_depth.resize(n);
  coverage.resize(n);
  const std::size_t rest = fields == SampleFields::kAll ? n : 0;
  for (auto* v : {&near, &far, &depth_limit, &interest_min, &interest_max, &ray_length_sq, &offset_length_sq,
                  &inverse_distance_sq}) {
    v->resize(rest);
  }
  depth_band.resize(rest);
  ratio_band.resize(rest);
}

void SampleArrays::SetDrawn(std::size_t i, const Frame& frame, const PixelSample& sample) {
  pick[i] = sample.pick;
  eye_depth[i] = sample.pick == DepthPick::kEyeDepth ? sample.eye_depth : frame.near;
  coverage[i] = sample.coverage;
}

void SampleArrays::Set(std::size_t i, const Frame& frame, const PixelSample& sample, const glm::dvec3& ray,
                       double offset_sq) {
  SetDrawn(i, frame, sample);
  const FramePlanes planes = PlanesOf(frame);
  near[i] = planes.near;
  far[i] = planes.far;
  depth_limit[i] = planes.depth_limit;
  interest_min[i] = planes.interest_min;
  interest_max[i] = planes.interest_max;
  ray_length_sq[i] = glm::dot(ray, ray);
  offset_length_sq[i] = offset_sq;
  inverse_distance_sq[i] = 1.0 / (offset_sq + eye_depth[i] * eye_depth[i] * ray_length_sq[i]);
  depth_band[i] = static_cast<std::uint8_t>(DepthBand(eye_depth[i] / frame.near));
  ratio_band[i] = planes.ratio_band;
}

glm::dvec3 PixelRay(const Frame& frame, std::uint32_t x, std::uint32_t y) {
  return frame.orthographic ? -frame.rotation[2] : draw::draw_pixel_ray(x, y, DrawFrameOf(frame));
}

glm::dvec3 PixelOffset(const Frame& frame, std::uint32_t x, std::uint32_t y) {
  return frame.orthographic ? draw::draw_pixel_point(x, y, DrawFrameOf(frame), 0.0) : glm::dvec3(0.0);
}

namespace {

// The per-lane arithmetic of References, written once for one sample
// (D = double, I = int64_t) and for four SIMD lanes (Double4, Int4); each
// lane computes exactly what the scalar form does. Bands are left to the
// caller: they are integer work, and stored-value picks need a decade of
// their own.
template <class D, class I>
struct ReferenceLanes {
  D true_depth, denoted_depth, inverse_distance_sq, storage_square, production_square;
  I status;  // ReferenceStatus
  I stored_holdable;
};
template <class D, class I>
[[gnu::always_inline]] inline ReferenceLanes<D, I> ReferenceOf(D eye_pick, D eye_depth, D denoted_hi, D produced_hi,
                                                               D near, D depth_limit, D interest_min, D interest_max,
                                                               D ray_length_sq, D offset_length_sq,
                                                               D eye_inverse_distance_sq, bool infinite_far) {
  const auto eye = eye_pick != 0.0;
  // Stored-value picks have no scene point of their own: the truth is what
  // the stored value denotes, and their storage and production errors are
  // zero.
  const D zero = D{} * 0.0;
  const D t = eye ? eye_depth : denoted_hi;
  const D produced = eye ? produced_hi : denoted_hi;
  ReferenceLanes<D, I> out;
  out.true_depth = t;
  out.denoted_depth = (denoted_hi - denoted_hi) == 0.0 ? denoted_hi : zero + DBL_MAX;  // finite, or DBL_MAX
  // A point float32 world coordinates cannot hold (an overflowing
  // reconstruction is then the right answer) is no more judged than one at
  // infinity.
  // (Squared distances from the camera: the offset is 0 unless the frame
  // is orthographic, and adding it then changes no bit.)
  const auto holdable = (t > 0.0) & (offset_length_sq + t * t * ray_length_sq < kLargestFloatSquared);
  const D limit = infinite_far ? zero + INFINITY : depth_limit;
  const D far = interest_max < limit ? interest_max : limit;    // std::min(limit, interest_max)
  const D nearest = near < interest_min ? interest_min : near;  // std::max(near, interest_min)
  const auto outside = (t < nearest * (1.0 - kPlaneSlack)) | (t > far * (1.0 + kPlaneSlack));
  const I judged = I{} + static_cast<std::int64_t>(ReferenceStatus::kJudged);
  const I degenerate = I{} + static_cast<std::int64_t>(ReferenceStatus::kDegenerate);
  const I outside_status = I{} + static_cast<std::int64_t>(ReferenceStatus::kOutside);
  out.status = holdable ? (outside ? outside_status : judged) : degenerate;
  const D s = denoted_hi;
  const auto stored_holdable = (s > 0.0) & (offset_length_sq + s * s * ray_length_sq < kLargestFloatSquared);
  out.stored_holdable = stored_holdable ? I{} + 1 : I{};
  const D inverse = eye ? eye_inverse_distance_sq : 1.0 / (offset_length_sq + t * t * ray_length_sq);
  out.inverse_distance_sq = out.status == judged ? inverse : zero;
  // Both points lie on the pixel's line, so the error of the position is
  // the error of the depth times the ray's length. The differences need no
  // more than double: an error below 2^-53 of the depth reads as 0 bits
  // lost, and two equal decodes (a float format's texel is the pipeline's
  // float) differ by exactly 0.
  const D scale = out.inverse_distance_sq * ray_length_sq;  // 1 / t^2 where judged (perspective)
  const D storage = denoted_hi - produced, production = produced - t;
  out.storage_square = storage * storage * scale;
  out.production_square = production * production * scale;
  return out;
}

[[gnu::always_inline]] inline void ReferencesBody(Encoding encoding, const SampleArrays& samples, std::size_t first,
                                                  std::size_t n, const double* denoted_hi, const double* produced_hi,
                                                  ReferenceArrays& out, std::size_t out_first) {
  const ConventionInfo& convention = Info(encoding.convention);
  const bool infinite_far = convention.hardware && (convention.bits & f32::DB_CONVENTION_INFINITE) != 0u;
  // Plain pointers, read once: the stores below cannot then be taken for
  // changes to the vectors' own pointers.
  const DepthPick* pick = samples.pick.data() + first;
  const double *eye_depth = samples.eye_depth.data() + first, *near = samples.near.data() + first,
               *depth_limit = samples.depth_limit.data() + first, *interest_min = samples.interest_min.data() + first,
               *interest_max = samples.interest_max.data() + first,
               *ray_length_sq = samples.ray_length_sq.data() + first,
               *offset_length_sq = samples.offset_length_sq.data() + first,
               *eye_inverse_distance_sq = samples.inverse_distance_sq.data() + first;
  double *true_depth = out.true_depth.data() + out_first, *denoted_depth = out.denoted_depth.data() + out_first,
         *inverse_distance_sq = out.inverse_distance_sq.data() + out_first,
         *storage_square = out.storage_square.data() + out_first,
         *production_square = out.production_square.data() + out_first;
  ReferenceStatus* status = out.status.data() + out_first;
  std::uint8_t* stored_holdable = out.stored_holdable.data() + out_first;
  const auto store = [&](std::size_t k, const auto& lanes, auto put) {
    put(true_depth + k, lanes.true_depth);
    put(denoted_depth + k, lanes.denoted_depth);
    put(inverse_distance_sq + k, lanes.inverse_distance_sq);
    put(storage_square + k, lanes.storage_square);
    put(production_square + k, lanes.production_square);
  };
  std::size_t k = 0;
  for (; k + 4 <= n; k += 4) {
    const auto load = [&](const double* p) {
      Double4 d;
      std::memcpy(&d, p + k, sizeof(d));
      return d;
    };
    Double4 eye_pick;
    for (int lane = 0; lane < 4; ++lane) eye_pick[lane] = pick[k + lane] == DepthPick::kEyeDepth;
    const ReferenceLanes<Double4, Int4> lanes = ReferenceOf<Double4, Int4>(
        eye_pick, load(eye_depth), load(denoted_hi), load(produced_hi), load(near), load(depth_limit),
        load(interest_min), load(interest_max), load(ray_length_sq), load(offset_length_sq),
        load(eye_inverse_distance_sq), infinite_far);
    store(k, lanes, [](double* to, Double4 v) { std::memcpy(to, &v, sizeof(v)); });
    for (int lane = 0; lane < 4; ++lane) {
      status[k + lane] = static_cast<ReferenceStatus>(lanes.status[lane]);
      stored_holdable[k + lane] = static_cast<std::uint8_t>(lanes.stored_holdable[lane] != 0);
    }
  }
  for (; k < n; ++k) {  // the tail
    const ReferenceLanes<double, std::int64_t> one = ReferenceOf<double, std::int64_t>(
        pick[k] == DepthPick::kEyeDepth, eye_depth[k], denoted_hi[k], produced_hi[k], near[k], depth_limit[k],
        interest_min[k], interest_max[k], ray_length_sq[k], offset_length_sq[k], eye_inverse_distance_sq[k],
        infinite_far);
    store(k, one, [](double* to, double v) { *to = v; });
    status[k] = static_cast<ReferenceStatus>(one.status);
    stored_holdable[k] = static_cast<std::uint8_t>(one.stored_holdable != 0);
  }
  // Bands: stored-value picks (rare) take the decade of their denoted depth.
  const std::uint8_t *depth_band = samples.depth_band.data() + first, *ratio_band = samples.ratio_band.data() + first;
  std::uint8_t* joint_band = out.joint_band.data() + out_first;
  for (k = 0; k < n; ++k) {
    int depth = depth_band[k];
    if (pick[k] != DepthPick::kEyeDepth) depth = DepthBand(true_depth[k] / near[k]);
    joint_band[k] = static_cast<std::uint8_t>(JointBand(infinite_far ? kInfiniteRatioBand : ratio_band[k], depth));
  }
}

}  // namespace

void References(Encoding encoding, const SampleArrays& samples, std::size_t first, std::size_t n, const double* denoted,
                const double* produced, ReferenceArrays& out, std::size_t out_first, Isa isa) {
  RunWith(
      isa, [&](auto) __attribute__((always_inline)) {
        ReferencesBody(encoding, samples, first, n, denoted, produced, out, out_first);
      });
}

}  // namespace depthbench
