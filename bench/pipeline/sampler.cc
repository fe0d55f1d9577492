#include "bench/pipeline/sampler.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/gtc/quaternion.hpp>

#include "bench/numerics/formulas.h"

namespace depthbench {
namespace {

// Random streams. Frame values are drawn with the frame index as counter,
// sample values with the sample index; the two never share a stream number.
enum Stream : std::uint32_t {
  kPickStream = 0,
  kDepthStream = 1,  // and 2 (53-bit uniform)
  kPixelKindStream = 3,
  kPixelXStream = 4,
  kPixelYStream = 5,
  kFrameFov = 1000,
  kFrameAspect = 1002,
  kFrameNear = 1004,
  kFrameFar = 1006,
  kFrameRotation = 1008,   // three uniforms: 1008..1013
  kFrameDirection = 1014,  // two uniforms: 1014..1017
  kFrameDistance = 1018,   // and 1020 (origin or not)
  kFrameResolution = 1022,
  kFrameVolume = 1024,
};

double LogUniform(double u, const Range& range) {
  if (range.fixed()) return range.min;
  return std::exp(std::log(range.min) + u * (std::log(range.max) - std::log(range.min)));
}

double LogUniform(double u, double lo, double hi) { return LogUniform(u, Range{lo, hi}); }

// x rounded to the nearest float32. Out of line on purpose: GCC 12 at -O3
// vectorised the camera loop below and dropped the float round trip for two
// of its three components, so cameras were not float32 values (found by the
// fuzzer's reproducer files, which check it).
[[gnu::noinline]] double RoundToFloat32(double x) {
  volatile float rounded = static_cast<float>(x);
  return rounded;
}

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

double Sampler::Unit(std::uint32_t state, std::uint32_t stream) {
  // 27 + 26 bits from two consecutive streams.
  std::uint64_t hi = Bits(state, stream) >> 5;
  std::uint64_t lo = Bits(state, stream + 1) >> 6;
  return static_cast<double>((hi << 26) | lo) * 0x1.0p-53;
}

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
  return u;
}

SampleUnits Sampler::SampleUnitsAt(std::uint64_t index) const {
  SampleUnits u;
  const std::uint32_t state = State(index);
  u.pick = Unit(state, kPickStream);
  u.depth = Unit(state, kDepthStream);
  u.pixel_kind = Unit(state, kPixelKindStream);
  u.x = Bits(state, kPixelXStream) * 0x1.0p-32;
  u.y = Bits(state, kPixelYStream) * 0x1.0p-32;
  return u;
}

Frame Sampler::FrameAt(std::uint64_t frame_index) const {
  return FrameFromUnits(domain_, FrameUnitsAt(frame_index), frame_index);
}

PixelSample Sampler::SampleAt(std::uint64_t index, const Frame& frame) const {
  return SampleFromUnits(SampleUnitsAt(index), frame, index);
}

void CompleteFrame(Frame& f, const std::optional<Range>& eye_depth) {
  f.tan_half_fov_y = std::tan(f.fov_y_degrees * std::numbers::pi / 360.0);
  f.depth_limit = f.finite() ? f.far : f.near * Domain::kInfiniteDepthSpan;
  f.eye_depth_min = f.near;
  f.eye_depth_max = f.depth_limit;
  f.depth_restricted = eye_depth.has_value();
  if (eye_depth) {
    f.eye_depth_min = std::clamp(eye_depth->min, f.near, f.depth_limit);
    f.eye_depth_max = std::clamp(eye_depth->max, f.eye_depth_min, f.depth_limit);
  }
  f.log_eye_depth_span = std::log(f.eye_depth_max / f.eye_depth_min);
}

Frame FrameFromUnits(const Domain& d, const FrameUnits& u, std::uint64_t frame_index) {
  Frame f;
  f.index = frame_index;
  f.fov_y_degrees = d.fov_degrees.min + u.fov * (d.fov_degrees.max - d.fov_degrees.min);
  f.aspect = LogUniform(u.aspect, d.aspect);
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
    f.camera_position[k] = RoundToFloat32(direction[k] * distance);
  }

  const std::size_t pick =
      std::min(d.resolutions.size() - 1, static_cast<std::size_t>(std::floor(u.resolution * d.resolutions.size())));
  f.width = d.resolutions[pick].width;
  f.height = d.resolutions[pick].height;
  f.volume_depth = LogUniform(u.volume, f.near, f.depth_limit);
  return f;
}

PixelSample SampleFromUnits(const SampleUnits& u, const Frame& frame, std::uint64_t index) {
  PixelSample s;
  s.index = index;

  // Depth: three quarters log-uniform eye depth (the natural distribution),
  // the rest drawn on purpose where reconstructions break: stored values at
  // the ends of the format, the first and the last doubling of depth.
  const double pick = u.pick;
  const double lo = frame.eye_depth_min, hi = frame.eye_depth_max;
  if (pick < 0.05) {
    static constexpr DepthPick kEdges[4] = {DepthPick::kStoredZero, DepthPick::kStoredOne, DepthPick::kStoredAfterZero,
                                            DepthPick::kStoredBeforeOne};
    static constexpr Coverage kKinds[4] = {Coverage::kStoredZero, Coverage::kStoredOne, Coverage::kStoredAfterZero,
                                           Coverage::kStoredBeforeOne};
    const int edge = std::min(3, static_cast<int>(pick / 0.05 * 4.0));
    s.pick = kEdges[edge];
    s.coverage = kKinds[edge];
  } else if (pick < 0.15) {  // near band: the first doubling of depth
    s.eye_depth = std::min(hi, lo * std::exp2(u.depth));
    s.coverage = Coverage::kNearDoubling;
  } else if (pick < 0.25) {  // far band: the last doubling
    s.eye_depth = std::max(lo, hi * std::exp2(-u.depth));
    s.coverage = Coverage::kFarDoubling;
  } else {
    s.eye_depth = std::min(hi, lo * std::exp(u.depth * frame.log_eye_depth_span));
  }

  // Pixel: mostly uniform over the render target (natural), with its exact
  // corners and edges drawn on purpose.
  const double kind = u.pixel_kind;
  auto scaled = [](double unit, std::uint32_t n) {
    return std::min(n - 1, static_cast<std::uint32_t>(std::floor(unit * n)));
  };
  const std::uint32_t w = frame.width, h = frame.height;
  const bool natural_depth = s.coverage == Coverage::kNatural;
  if (kind < 0.04) {
    int corner = std::min(3, static_cast<int>(kind / 0.04 * 4.0));
    s.x = (corner & 1) ? w - 1 : 0;
    s.y = (corner & 2) ? h - 1 : 0;
    if (natural_depth) s.coverage = Coverage::kCornerPixel;
  } else if (kind < 0.08) {
    int edge = std::min(3, static_cast<int>((kind - 0.04) / 0.04 * 4.0));
    s.x = edge < 2 ? (edge == 0 ? 0 : w - 1) : scaled(u.x, w);
    s.y = edge < 2 ? scaled(u.y, h) : (edge == 2 ? 0 : h - 1);
    if (natural_depth) s.coverage = Coverage::kEdgePixel;
  } else {
    s.x = scaled(u.x, w);
    s.y = scaled(u.y, h);
  }
  return s;
}

}  // namespace depthbench
