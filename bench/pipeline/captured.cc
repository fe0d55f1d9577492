#include "bench/pipeline/captured.h"

#include <cmath>

#include <fmt/format.h>

namespace depthbench {

CapturedSource::CapturedSource(const Domain& domain)
    : pixels_(domain.capture), production_(domain.production), constants_(domain.constants) {
  // Every unit at 0.5: the domain's ranges are points (CaptureDomain), so
  // only the volume's depth reads it, which puts the light-volume surface
  // at the geometric middle of the depth range.
  FrameUnits units;
  units.fov = units.aspect = units.near = units.far = units.volume = 0.5;
  frame_ = FrameFromUnits(domain, units, 0);
  frame_.rotation = glm::dmat3(1.0);
  frame_.camera_position = domain.camera_distance.max > 0.0 ? pixels_->camera_position : glm::dvec3(0.0);
  frame_.width = pixels_->width;
  frame_.height = pixels_->height;
  for (std::uint32_t p = 0; p < pixels_->eye_depth.size(); ++p) {
    const double z = pixels_->eye_depth[p];
    if (z >= frame_.eye_depth_min && z <= frame_.eye_depth_max) kept_.push_back(p);
  }
}

Frame CapturedSource::FrameAt(std::uint64_t frame_index) const {
  Frame f = frame_;
  f.index = frame_index;
  return f;
}

PixelSample CapturedSource::SampleAt(std::uint64_t index, const Frame&) const {
  const std::uint32_t pixel = kept_[index];
  PixelSample s;
  s.index = index;
  s.x = pixel % pixels_->width;
  s.y = pixel / pixels_->width;
  s.pick = DepthPick::kEyeDepth;
  s.eye_depth = pixels_->eye_depth[pixel];
  s.coverage = Coverage::kNatural;
  return s;
}

double DeepestPixel(const CapturedPixels& pixels) {
  double deepest = 0.0;
  for (double z : pixels.eye_depth) {
    if (z > deepest) deepest = z;  // NaN (background) compares false
  }
  return deepest;
}

std::unique_ptr<const SampleSource> SourceFor(std::uint64_t seed, const Domain& domain) {
  if (domain.capture) return std::make_unique<const CapturedSource>(domain);
  return std::make_unique<const Sampler>(seed, domain);
}

std::uint64_t SamplesFor(std::uint64_t requested, const SampleSource& source) {
  const auto* captured = dynamic_cast<const CapturedSource*>(&source);
  return captured ? captured->sample_count() : requested;
}

Expected<Domain> CaptureDomain(Domain d, std::shared_ptr<const CapturedPixels> pixels) {
  const auto unfixed = [&](const char* what) {
    return InvalidArgument(
        fmt::format("{}: a captured frame needs its projection's {} fixed (give the frame's projection matrix)",
                    pixels->source, what));
  };
  if (!d.eye_fov && (!d.fov_degrees.fixed() || !d.aspect.fixed())) return unfixed("field of view");
  if (!d.near.fixed()) return unfixed("near plane");
  if (d.finite_far && !(d.far ? d.far->fixed() : d.ratio.fixed())) return unfixed("far plane");
  if (pixels->width == 0 || pixels->height == 0 ||
      pixels->eye_depth.size() != static_cast<std::size_t>(pixels->width) * pixels->height) {
    return InvalidArgument(fmt::format("{}: the capture has no pixels", pixels->source));
  }
  d.resolutions = {Resolution{pixels->width, pixels->height}};
  const double distance = glm::length(pixels->camera_position);
  d.camera_distance = Range{distance, distance};
  d.jitter = 0.0;  // a capture's jitter, if any, is in its matrix
  d.capture = std::move(pixels);
  if (CapturedSource(d).sample_count() == 0) {
    return InvalidArgument(fmt::format("{}: none of its {} drawn pixels lies between the near and far planes",
                                       d.capture->source, d.capture->eye_depth.size() - d.capture->background));
  }
  return d;
}

}  // namespace depthbench
