#include "bench/sampler.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/gtc/quaternion.hpp>

#include "bench/formulas.h"

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
  kFrameRotation = 1008,  // three uniforms: 1008..1013
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

}  // namespace

Sampler::Sampler(std::uint64_t seed, Domain domain) : seed_(seed), domain_(std::move(domain)) {}

std::uint32_t Sampler::Bits(std::uint64_t index, std::uint32_t stream) const {
  return f32::random_bits(static_cast<std::uint32_t>(seed_), static_cast<std::uint32_t>(seed_ >> 32),
                          static_cast<std::uint32_t>(index), static_cast<std::uint32_t>(index >> 32),
                          stream);
}

double Sampler::Unit(std::uint64_t index, std::uint32_t stream) const {
  // 27 + 26 bits from two consecutive streams.
  std::uint64_t hi = Bits(index, stream) >> 5;
  std::uint64_t lo = Bits(index, stream + 1) >> 6;
  return static_cast<double>((hi << 26) | lo) * 0x1.0p-53;
}

Frame Sampler::FrameAt(std::uint64_t frame_index) const {
  const Domain& d = domain_;
  const std::uint64_t i = frame_index;
  Frame f;
  f.index = frame_index;
  f.fov_y_degrees = d.fov_degrees.min + Unit(i, kFrameFov) * (d.fov_degrees.max - d.fov_degrees.min);
  f.tan_half_fov_y = std::tan(f.fov_y_degrees * std::numbers::pi / 360.0);
  f.aspect = LogUniform(Unit(i, kFrameAspect), d.aspect);
  f.near = LogUniform(Unit(i, kFrameNear), d.near);
  if (!d.finite_far) {
    f.far = INFINITY;
    f.depth_limit = f.near * Domain::kInfiniteDepthSpan;
  } else {
    f.far = d.far ? LogUniform(Unit(i, kFrameFar), *d.far)
                  : f.near * LogUniform(Unit(i, kFrameFar), d.ratio);
    f.depth_limit = f.far;
  }
  f.eye_depth_min = f.near;
  f.eye_depth_max = f.depth_limit;
  f.depth_restricted = d.eye_depth.has_value();
  if (d.eye_depth) {
    f.eye_depth_min = std::clamp(d.eye_depth->min, f.near, f.depth_limit);
    f.eye_depth_max = std::clamp(d.eye_depth->max, f.eye_depth_min, f.depth_limit);
  }
  f.log_eye_depth_span = std::log(f.eye_depth_max / f.eye_depth_min);

  // A uniformly random orientation (Shoemake's construction from three
  // uniforms).
  double u1 = Unit(i, kFrameRotation), u2 = Unit(i, kFrameRotation + 2),
         u3 = Unit(i, kFrameRotation + 4);
  double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
  double t2 = 2.0 * std::numbers::pi * u2, t3 = 2.0 * std::numbers::pi * u3;
  glm::dquat q(b * std::cos(t3), a * std::sin(t2), a * std::cos(t2), b * std::sin(t3));
  f.rotation = glm::mat3_cast(glm::normalize(q));

  // Camera position: a uniform direction at the sampled distance, each
  // component rounded to float32 as an engine stores it.
  const Range& dist = d.camera_distance;
  double distance;
  if (dist.fixed()) {
    distance = dist.min;
  } else if (dist.min == 0.0) {
    distance = Unit(i, kFrameDistance + 2) < 0.25 ? 0.0
                                                   : LogUniform(Unit(i, kFrameDistance),
                                                                dist.max * 1e-6, dist.max);
  } else {
    distance = LogUniform(Unit(i, kFrameDistance), dist);
  }
  double cz = 2.0 * Unit(i, kFrameDirection) - 1.0;
  double phi = 2.0 * std::numbers::pi * Unit(i, kFrameDirection + 2);
  double rxy = std::sqrt(std::max(0.0, 1.0 - cz * cz));
  glm::dvec3 direction(rxy * std::cos(phi), rxy * std::sin(phi), cz);
  for (int k = 0; k < 3; ++k) {
    f.camera_position[k] = static_cast<double>(static_cast<float>(direction[k] * distance));
  }

  const Resolution& res =
      d.resolutions[(static_cast<std::uint64_t>(Bits(i, kFrameResolution)) * d.resolutions.size()) >> 32];
  f.width = res.width;
  f.height = res.height;
  f.volume_depth = LogUniform(Unit(i, kFrameVolume), f.near, f.depth_limit);
  return f;
}

PixelSample Sampler::SampleAt(std::uint64_t index, const Frame& frame) const {
  PixelSample s;
  s.index = index;

  // Depth: mostly log-uniform eye depth, with the bands and stored values
  // where reconstructions break drawn on purpose.
  double pick = Unit(index, kPickStream);
  double u = Unit(index, kDepthStream);
  const double lo = frame.eye_depth_min, hi = frame.eye_depth_max;
  if (pick < 0.05) {
    static constexpr DepthPick kEdges[4] = {DepthPick::kStoredZero, DepthPick::kStoredOne,
                                            DepthPick::kStoredAfterZero, DepthPick::kStoredBeforeOne};
    s.pick = kEdges[std::min(3, static_cast<int>(pick / 0.05 * 4.0))];
  } else if (pick < 0.15) {  // near band: the first doubling of depth
    s.eye_depth = std::min(hi, lo * std::exp2(u));
  } else if (pick < 0.25) {  // far band: the last doubling
    s.eye_depth = std::max(lo, hi * std::exp2(-u));
  } else {
    s.eye_depth = std::min(hi, lo * std::exp(u * frame.log_eye_depth_span));
  }

  // Pixel: mostly uniform over the render target, with its exact corners
  // and edges drawn on purpose.
  double kind = Unit(index, kPixelKindStream);
  auto scaled = [&](std::uint32_t stream, std::uint32_t n) {
    return static_cast<std::uint32_t>((static_cast<std::uint64_t>(Bits(index, stream)) * n) >> 32);
  };
  const std::uint32_t w = frame.width, h = frame.height;
  if (kind < 0.04) {
    int corner = std::min(3, static_cast<int>(kind / 0.04 * 4.0));
    s.x = (corner & 1) ? w - 1 : 0;
    s.y = (corner & 2) ? h - 1 : 0;
  } else if (kind < 0.08) {
    int edge = std::min(3, static_cast<int>((kind - 0.04) / 0.04 * 4.0));
    s.x = edge < 2 ? (edge == 0 ? 0 : w - 1) : scaled(kPixelXStream, w);
    s.y = edge < 2 ? scaled(kPixelYStream, h) : (edge == 2 ? 0 : h - 1);
  } else {
    s.x = scaled(kPixelXStream, w);
    s.y = scaled(kPixelYStream, h);
  }
  return s;
}

}  // namespace depthbench
