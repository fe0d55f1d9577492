#include "bench/pipeline/sampler.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/gtc/quaternion.hpp>

#include "bench/numerics/float32.h"
#include "bench/numerics/formulas.h"

namespace depthbench {
namespace {

// Random streams. Frame values are drawn with the frame index as counter,
// sample values (shared/draw.h's DB_DRAW_*_STREAM, 0 to 5) with the sample
// index; the two never share a stream number.
enum Stream : std::uint32_t {
  kFrameFov = 1000,
  kFrameAspect = 1002,
  kFrameNear = 1004,
  kFrameFar = 1006,
  kFrameRotation = 1008,   // three uniforms: 1008..1013
  kFrameDirection = 1014,  // two uniforms: 1014..1017
  kFrameDistance = 1018,   // and 1020 (origin or not)
  kFrameResolution = 1022,
  kFrameVolume = 1024,
  kFrameJitter = 1026,  // two uniforms: 1026..1029
};

double LogUniform(double u, const Range& range) {
  if (range.fixed()) return range.min;
  return std::exp(std::log(range.min) + u * (std::log(range.max) - std::log(range.min)));
}

double LogUniform(double u, double lo, double hi) { return LogUniform(u, Range{lo, hi}); }

}  // namespace

std::optional<int> OnlyDistanceBand(const Range& camera_distance) {
  if (camera_distance.max == 0.0) return 0;  // every camera at the origin
  // A frame's distance is that of its camera position rounded to float32:
  // within a few parts in 10^7 of the distance drawn. A range from 0 puts
  // cameras at the origin too.
  constexpr double kRounding = 1e-6;
  const double low = camera_distance.min == 0.0 ? 0.0 : camera_distance.min * (1.0 - kRounding);
  const int band = DistanceBand(low);
  if (band != DistanceBand(camera_distance.max * (1.0 + kRounding))) return std::nullopt;
  return band;
}

Sampler::Sampler(std::uint64_t seed, Domain domain) : seed_(seed), domain_(std::move(domain)) {}

std::uint32_t Sampler::State(std::uint64_t index) const {
  return f32::random_state(static_cast<std::uint32_t>(seed_), static_cast<std::uint32_t>(seed_ >> 32),
                           static_cast<std::uint32_t>(index), static_cast<std::uint32_t>(index >> 32));
}

std::uint32_t Sampler::Bits(std::uint32_t state, std::uint32_t stream) {
  return f32::random_bits_from_state(state, stream);
}

double Sampler::Unit(std::uint32_t state, std::uint32_t stream) { return draw::draw_unit(state, stream); }

FrameUnits Sampler::FrameUnitsAt(std::uint64_t i) const {
  FrameUnits u;
  const std::uint32_t state = State(i);
  u.fov = Unit(state, kFrameFov);
  u.aspect = Unit(state, kFrameAspect);
  u.near = Unit(state, kFrameNear);
  u.far = Unit(state, kFrameFar);
  for (int k = 0; k < 3; ++k) u.rotation[k] = Unit(state, kFrameRotation + 2 * k);
  for (int k = 0; k < 2; ++k) u.direction[k] = Unit(state, kFrameDirection + 2 * k);
  u.distance = Unit(state, kFrameDistance);
  u.at_origin = Unit(state, kFrameDistance + 2);
  u.resolution = Bits(state, kFrameResolution) * 0x1.0p-32;  // exact: the pick below is floor(bits * n / 2^32)
  u.volume = Unit(state, kFrameVolume);
  for (int k = 0; k < 2; ++k) u.jitter[k] = Unit(state, kFrameJitter + 2 * k);
  return u;
}

SampleUnits Sampler::SampleUnitsAt(std::uint64_t index) const {
  const draw::DrawUnits u = draw::draw_units(State(index));
  return {.pick = u.pick, .depth = u.depth, .pixel_kind = u.pixel_kind, .x = u.x, .y = u.y};
}

Frame Sampler::FrameAt(std::uint64_t frame_index) const {
  return FrameFromUnits(domain_, FrameUnitsAt(frame_index), frame_index);
}

PixelSample Sampler::SampleAt(std::uint64_t index, const Frame& frame) const {
  return SampleFromUnits(SampleUnitsAt(index), frame, index);
}

void CompleteFrame(Frame& f, const std::optional<Range>& eye_depth) {
  if (!f.orthographic) f.tan_half_fov_y = std::tan(f.fov_y_degrees * std::numbers::pi / 360.0);
  f.depth_limit = f.finite() ? f.far : f.near * Domain::kInfiniteDepthSpan;
  f.eye_depth_min = f.near;
  f.eye_depth_max = f.depth_limit;
  f.depth_restricted = eye_depth.has_value();
  if (eye_depth) {
    f.eye_depth_min = std::clamp(eye_depth->min, f.near, f.depth_limit);
    f.eye_depth_max = std::clamp(eye_depth->max, f.eye_depth_min, f.depth_limit);
  }
  f.log2_eye_depth_span = std::log2(f.eye_depth_max / f.eye_depth_min);
}

Frame FrameFromUnits(const Domain& d, const FrameUnits& u, std::uint64_t frame_index) {
  Frame f;
  f.index = frame_index;
  if (d.orthographic) {
    const ViewVolume& v = *d.orthographic;
    f.orthographic = true;
    f.tan_half_fov_y = (v.top - v.bottom) / 2.0;
    f.aspect = (v.right - v.left) / (v.top - v.bottom);
    f.centre_x = (v.right + v.left) / 2.0;
    f.centre_y = (v.top + v.bottom) / 2.0;
  } else if (d.eye_fov) {
    // The frustum's half extents and centre, in tangents at unit depth.
    const double half_x = (d.eye_fov->TanRight() - d.eye_fov->TanLeft()) / 2.0;
    const double half_y = (d.eye_fov->TanUp() - d.eye_fov->TanDown()) / 2.0;
    f.fov_y_degrees = 2.0 * std::atan(half_y) * 180.0 / std::numbers::pi;
    f.aspect = half_x / half_y;
    f.centre_x = (d.eye_fov->TanRight() + d.eye_fov->TanLeft()) / 2.0;
    f.centre_y = (d.eye_fov->TanUp() + d.eye_fov->TanDown()) / 2.0;
  } else {
    f.fov_y_degrees = d.fov_degrees.min + u.fov * (d.fov_degrees.max - d.fov_degrees.min);
    f.aspect = LogUniform(u.aspect, d.aspect);
  }
  f.near = LogUniform(u.near, d.near);
  if (!d.finite_far) {
    f.far = INFINITY;
  } else {
    f.far = d.far ? LogUniform(u.far, *d.far) : f.near * LogUniform(u.far, d.ratio);
  }
  CompleteFrame(f, d.eye_depth);

  // A uniformly random orientation (Shoemake's construction from three
  // uniforms).
  double a = std::sqrt(1.0 - u.rotation[0]), b = std::sqrt(u.rotation[0]);
  double t2 = 2.0 * std::numbers::pi * u.rotation[1], t3 = 2.0 * std::numbers::pi * u.rotation[2];
  glm::dquat q(b * std::cos(t3), a * std::sin(t2), a * std::cos(t2), b * std::sin(t3));
  f.rotation = glm::mat3_cast(glm::normalize(q));

  // Camera position: a uniform direction at the sampled distance, each
  // component rounded to float32 as an engine stores it.
  const Range& dist = d.camera_distance;
  double distance;
  if (dist.fixed()) {
    distance = dist.min;
  } else if (dist.min == 0.0) {
    distance = u.at_origin < 0.25 ? 0.0 : LogUniform(u.distance, dist.max * 1e-6, dist.max);
  } else {
    distance = LogUniform(u.distance, dist);
  }
  double cz = 2.0 * u.direction[0] - 1.0;
  double phi = 2.0 * std::numbers::pi * u.direction[1];
  double rxy = std::sqrt(std::max(0.0, 1.0 - cz * cz));
  glm::dvec3 direction(rxy * std::cos(phi), rxy * std::sin(phi), cz);
  for (int k = 0; k < 3; ++k) {
    f.camera_position[k] = NearestFloat32(direction[k] * distance);
  }

  const std::size_t pick =
      std::min(d.resolutions.size() - 1, static_cast<std::size_t>(std::floor(u.resolution * d.resolutions.size())));
  f.width = d.resolutions[pick].width;
  f.height = d.resolutions[pick].height;
  f.volume_depth = LogUniform(u.volume, f.near, f.depth_limit);
  if (d.jitter > 0.0) {
    // A shift of j pixels moves NDC by 2j / width, the view ray by that
    // times the half extent.
    const double tan_x = f.aspect * f.tan_half_fov_y;
    f.centre_x += (2.0 * u.jitter[0] - 1.0) * d.jitter * 2.0 / f.width * tan_x;
    f.centre_y += (2.0 * u.jitter[1] - 1.0) * d.jitter * 2.0 / f.height * f.tan_half_fov_y;
  }
  return f;
}

// shared/draw.h numbers picks and coverage kinds as sampler.h and bands.h do.
static_assert(static_cast<int>(DepthPick::kStoredZero) == 1 && static_cast<int>(DepthPick::kStoredBeforeOne) == 4);
static_assert(static_cast<unsigned>(Coverage::kStoredZero) == draw::DB_COVERAGE_STORED_ZERO &&
              static_cast<unsigned>(Coverage::kStoredBeforeOne) == draw::DB_COVERAGE_STORED_ZERO + 3 &&
              static_cast<unsigned>(Coverage::kNearDoubling) == draw::DB_COVERAGE_NEAR_DOUBLING &&
              static_cast<unsigned>(Coverage::kFarDoubling) == draw::DB_COVERAGE_FAR_DOUBLING &&
              static_cast<unsigned>(Coverage::kCornerPixel) == draw::DB_COVERAGE_CORNER_PIXEL &&
              static_cast<unsigned>(Coverage::kEdgePixel) == draw::DB_COVERAGE_EDGE_PIXEL);

draw::DrawFrame DrawFrameOf(const Frame& frame) {
  draw::DrawFrame f;
  f.eye_depth_min = frame.eye_depth_min;
  f.eye_depth_max = frame.eye_depth_max;
  f.log2_eye_depth_span = frame.log2_eye_depth_span;
  f.tan_x = frame.aspect * frame.tan_half_fov_y;
  f.tan_y = frame.tan_half_fov_y;
  f.width = frame.width;
  f.height = frame.height;
  f.rotation = frame.rotation;
  f.centre_x = frame.centre_x;
  f.centre_y = frame.centre_y;
  return f;
}

PixelSample SampleFromUnits(const SampleUnits& u, const Frame& frame, std::uint64_t index) {
  const draw::DrawnSample drawn = draw::draw_sample(
      {.pick = u.pick, .depth = u.depth, .pixel_kind = u.pixel_kind, .x = u.x, .y = u.y}, DrawFrameOf(frame));
  return {.index = index,
          .x = drawn.x,
          .y = drawn.y,
          .pick = static_cast<DepthPick>(drawn.pick),
          .eye_depth = drawn.eye_depth,
          .coverage = static_cast<Coverage>(drawn.coverage)};
}

}  // namespace depthbench
