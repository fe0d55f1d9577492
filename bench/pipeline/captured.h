// A captured frame as a domain: the pixels of a depth buffer saved from a
// real frame, each an eye depth, become the population a sweep judges, in
// place of the sampler's log-uniform draw. The frame's lens, near and far
// planes are the domain's (a scene's projection matrix fixes them); its
// camera is where the capture says, its rotation the identity (the error
// of a reconstruction does not depend on which way a camera at a given
// place looks, only on where it is: docs/scenes.md).
//
// Reading the file and decoding its values is bench/capture/'s; this is
// what the sweep needs of the result.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "bench/base/status.h"
#include "bench/pipeline/domain.h"
#include "bench/pipeline/sampler.h"

namespace depthbench {

struct CapturedPixels {
  std::string source;  // the file it was read from
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  // Row by row from the top row (an image's order, and the sampler's pixel
  // y); NaN where the buffer holds its clear value (nothing was drawn).
  std::vector<double> eye_depth;
  glm::dvec3 camera_position{0.0};  // float32 components
  std::uint64_t background = 0;     // pixels that hold the clear value
  std::string description;          // what the file held, in words
};

// The capture's frame and its pixels that the domain keeps: every drawn
// pixel whose eye depth lies within the frustum and within the domain's
// eye-depth range of interest, if it names one. With the domain's camera
// distance 0 the camera is put at the origin (what a scene's "at the
// origin" question asks), otherwise where the capture says.
class CapturedSource : public SampleSource {
 public:
  // The domain must hold a capture (Domain::capture).
  explicit CapturedSource(const Domain& domain);

  Frame FrameAt(std::uint64_t frame_index) const override;
  PixelSample SampleAt(std::uint64_t index, const Frame& frame) const override;
  ProductionModel production() const override { return production_; }
  ConstantsModel constants() const override { return constants_; }

  std::uint64_t sample_count() const { return kept_.size(); }
  // The pixel sample `index` is, as an offset into CapturedPixels::eye_depth.
  std::uint32_t PixelOf(std::uint64_t index) const { return kept_[index]; }
  const CapturedPixels& pixels() const { return *pixels_; }

 private:
  std::shared_ptr<const CapturedPixels> pixels_;
  Frame frame_;
  std::vector<std::uint32_t> kept_;
  ProductionModel production_;
  ConstantsModel constants_;
};

// The eye depth of the capture's farthest drawn pixel (0 when none is).
double DeepestPixel(const CapturedPixels& pixels);

// Where a domain's samples come from: its capture's pixels, or the random
// sampler under `seed`.
std::unique_ptr<const SampleSource> SourceFor(std::uint64_t seed, const Domain& domain);
// The samples a run over the domain judges: a capture's pixels that it
// keeps, whatever `requested`; `requested` otherwise.
std::uint64_t SamplesFor(std::uint64_t requested, const SampleSource& source);

// The domain a capture makes of `base` (its lens, planes and models; a
// scene's projection has fixed them): one resolution, the capture's, and
// the camera's distance fixed at the capture's. Refused where the planes
// or the lens are not fixed, or where no pixel lies within the frustum.
Expected<Domain> CaptureDomain(Domain base, std::shared_ptr<const CapturedPixels> pixels);

}  // namespace depthbench
