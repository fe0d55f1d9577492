// The sampler: random projections, camera poses, pixels and depths, each a
// pure function of (seed, index). Samples come in frames of
// kSamplesPerFrame consecutive indices that share one projection and pose,
// as the pixels of a real frame do; frame f holds samples
// [f * kSamplesPerFrame, (f + 1) * kSamplesPerFrame). Any split of the index
// range (shards, batches, threads) therefore draws exactly the same samples.
//
// The random bits come from shared/random.h, so a GPU can draw them too.
#pragma once

#include <cstdint>
#include <optional>

#include <glm/glm.hpp>

#include "bench/pipeline/bands.h"
#include "bench/pipeline/domain.h"
#include "bench/pipeline/draw.h"

namespace depthbench {

inline constexpr std::uint32_t kSamplesPerFrame = 64;

// One frame's exact parameters. They are the definition of the scene: the
// reference evaluates them in double-double, the backends receive float32
// constants computed from them (shader_constants.h).
struct Frame {
  std::uint64_t index = 0;
  // An orthographic frame: tan_half_fov_y and aspect * tan_half_fov_y are
  // then the view volume's half height and half width in view units (the
  // half extents at every depth, where a perspective lens gives them at
  // unit eye depth), centre_x and centre_y its centre's offset, and
  // fov_y_degrees is 0.
  bool orthographic = false;
  double fov_y_degrees = 0.0;
  double tan_half_fov_y = 0.0;  // the exact lens parameter (tan computed once, then taken as exact)
  double aspect = 0.0;
  // An off-centre lens (a VR eye, TAA jitter): the view ray through NDC
  // (0, 0) is (centre_x, centre_y, -1), and NDC (x, y) sees
  // (x * tan_x + centre_x, y * tan_y + centre_y, -1) with tan_x = aspect *
  // tan_half_fov_y. Zero for a symmetric frustum.
  double centre_x = 0.0;
  double centre_y = 0.0;
  double near = 0.0;
  // Far plane of the finite-far conventions (+infinity when the domain has
  // infinite far planes only; finite-far cells then do not apply).
  double far = 0.0;
  // Largest eye depth sampled: far, or near * Domain::kInfiniteDepthSpan.
  double depth_limit = 0.0;
  double eye_depth_min = 0.0;  // eye-depth range samples are drawn from
  double eye_depth_max = 0.0;
  double log2_eye_depth_span = 0.0;  // log2(eye_depth_max / eye_depth_min)
  bool depth_restricted = false;     // the domain names an eye-depth range of interest
  glm::dvec3 camera_position{0.0};   // float32-representable components
  glm::dmat3 rotation{1.0};          // columns: the camera's x, y, z axes in world space
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  double volume_depth = 0.0;  // eye depth of the light-volume surface (volume_ray)

  bool finite() const { return far < INFINITY; }
  double ratio() const { return far / near; }
  double camera_distance() const { return glm::length(camera_position); }
};

// How a sample chose its depth.
enum class DepthPick : std::uint8_t {
  kEyeDepth,         // an eye depth (log-uniform, or in the near or far band)
  kStoredZero,       // the stored value 0, whatever it denotes
  kStoredOne,        // the stored value 1 (the far plane for linear formats)
  kStoredAfterZero,  // the smallest stored value above 0
  kStoredBeforeOne,  // the largest stored value below 1
};

struct PixelSample {
  std::uint64_t index = 0;
  std::uint32_t x = 0;
  std::uint32_t y = 0;
  DepthPick pick = DepthPick::kEyeDepth;
  double eye_depth = 0.0;  // for kEyeDepth
  // Drawn from the domain's natural distribution (log-uniform eye depth,
  // uniform pixel), or on purpose for coverage (bands.h).
  Coverage coverage = Coverage::kNatural;
};

// Where a batch's frames and samples come from: the random sampler, or an
// explicit list (fuzz cases, reproducer files, a search's candidates).
// Sample `index` belongs to frame index / kSamplesPerFrame.
class SampleSource {
 public:
  virtual ~SampleSource() = default;
  virtual Frame FrameAt(std::uint64_t frame_index) const = 0;
  virtual PixelSample SampleAt(std::uint64_t index, const Frame& frame) const = 0;
  // How the pipeline produces its samples' stored depth.
  virtual ProductionModel production() const { return ProductionModel::kFloat32; }
  // How the shaders' per-frame constants are computed.
  virtual ConstantsModel constants() const { return ConstantsModel::kExact; }
  // The seed a device draws this source's samples from, as SampleAt draws
  // them (shared/draw.h), where it can; nullopt where it cannot (a list).
  virtual std::optional<std::uint64_t> device_draw_seed() const { return std::nullopt; }
};

// A point of the domain in unit coordinates: every random choice the
// sampler makes, each in [0, 1). The sampler draws them from (seed, index);
// a search moves them directly and so never leaves the domain.
struct FrameUnits {
  double fov = 0, aspect = 0, near = 0, far = 0;
  double rotation[3] = {0, 0, 0};
  double direction[2] = {0, 0};
  double distance = 0, at_origin = 0;  // at_origin < 0.25 puts the camera at the origin (when the range allows)
  double resolution = 0, volume = 0;
  // TAA jitter in x and y (used when the domain has jitter). Last, and
  // not among the units a search or fuzz case moves (fuzz_case.h).
  double jitter[2] = {0, 0};
};
struct SampleUnits {
  double pick = 0, depth = 0;
  double pixel_kind = 0, x = 0, y = 0;
};
Frame FrameFromUnits(const Domain& domain, const FrameUnits& units, std::uint64_t frame_index);
// The sample these units draw in `frame` (shared/draw.h).
PixelSample SampleFromUnits(const SampleUnits& units, const Frame& frame, std::uint64_t index);
// What the draw of a sample and of its ray needs of its frame.
draw::DrawFrame DrawFrameOf(const Frame& frame);
// Fills the fields that follow from the others (tan_half_fov_y, depth
// limits and the eye-depth range), as the sampler does; `eye_depth` is the
// domain's range of interest, if any.
void CompleteFrame(Frame& frame, const std::optional<Range>& eye_depth);

// The camera-distance band of every frame the sampler draws from this
// range, when they all share one (nullopt when they may not): a fixed
// distance not within a float32 rounding of a band's edge, or the origin.
std::optional<int> OnlyDistanceBand(const Range& camera_distance);

class Sampler : public SampleSource {
 public:
  Sampler(std::uint64_t seed, Domain domain);

  Frame FrameAt(std::uint64_t frame_index) const override;
  PixelSample SampleAt(std::uint64_t index, const Frame& frame) const override;
  ProductionModel production() const override { return domain_.production; }
  ConstantsModel constants() const override { return domain_.constants; }
  std::optional<std::uint64_t> device_draw_seed() const override { return seed_; }
  FrameUnits FrameUnitsAt(std::uint64_t frame_index) const;
  SampleUnits SampleUnitsAt(std::uint64_t index) const;

  std::uint64_t seed() const { return seed_; }
  const Domain& domain() const { return domain_; }

 private:
  // The mixing state of a sample (or frame) index, from which each of its
  // streams is one more round (shared/random.h).
  std::uint32_t State(std::uint64_t index) const;
  static std::uint32_t Bits(std::uint32_t state, std::uint32_t stream);
  static double Unit(std::uint32_t state, std::uint32_t stream);  // [0, 1), 53 bits

  std::uint64_t seed_;
  Domain domain_;
};

}  // namespace depthbench
