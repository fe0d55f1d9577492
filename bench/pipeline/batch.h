// Batch: a contiguous range of samples made ready for the backends and the
// judge. The builder draws the samples, encodes every depth the run's cells
// read, packs the shader inputs (exactly the bytes a GPU uploads) and
// computes the reference for every (encoding, sample).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "bench/base/thread_pool.h"
#include "bench/numerics/formulas.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/reference.h"
#include "bench/pipeline/sampler.h"

namespace depthbench {

struct Batch {
  std::uint64_t first_index = 0;
  std::uint32_t count = 0;
  std::uint32_t first_offset = 0;  // first_index % kSamplesPerFrame

  // Backend inputs.
  std::vector<f32::FrameParams> frame_params;  // [frame]
  std::vector<f32::DepthParams> depth_params;  // [frame * kHardwareConventionCount + convention]
  std::vector<std::uint32_t> pixels;           // [sample]: x | y << 16
  std::vector<float> depths;                   // [depth slot * count + sample]: fetched values

  // Judge inputs, as arrays of components so that the judge reads them in
  // SIMD lanes.
  std::vector<Frame> frames;                 // [frame]: exact parameters
  std::vector<std::uint8_t> distance_bands;  // [frame]: DistanceBand of the camera
  std::vector<double> ray_x, ray_y, ray_z;   // [sample]: world-space ray at unit eye depth
  SampleArrays samples;                      // [sample]: the depth pick and what the reference needs
  ReferenceArrays reference;                 // [depth slot * count + sample]
  std::vector<std::uint32_t> codes;          // [depth slot * count + sample]: stored texel bits

  glm::dvec3 Ray(std::uint32_t sample) const { return {ray_x[sample], ray_y[sample], ray_z[sample]}; }

  std::uint32_t FrameOf(std::uint32_t sample) const { return (sample + first_offset) / kSamplesPerFrame; }
  std::size_t frame_count() const { return frames.size(); }
};

// Where one cell's inputs live in a Batch.
struct CellPlan {
  Cell cell;
  std::uint32_t depth_slot = 0;       // index of the cell's encoding among the run's encodings
  std::uint32_t convention_slot = 0;  // index into a frame's DepthParams (hardware conventions)
};

// Lays out the cells of a run: one depth slot per distinct encoding.
struct RunLayout {
  std::vector<CellPlan> cells;
  std::vector<Encoding> encodings;  // [depth slot]
};
RunLayout MakeRunLayout(std::span<const Cell> cells);

class BatchBuilder {
 public:
  // `isa`: what the decode and reference loops are compiled for (bench/base/isa.h).
  BatchBuilder(const SampleSource& sampler, std::vector<Encoding> encodings, Isa isa = Isa::kWidest);

  // Fills `batch` with samples [first, first + count).
  void Build(std::uint64_t first, std::uint32_t count, Batch& batch, ThreadPool& pool) const;

 private:
  const SampleSource& sampler_;
  std::vector<Encoding> encodings_;
  Isa isa_;
  // The formats of one convention share the pipeline's float (encode.h):
  // encodings_[s] reads pipeline value pipeline_of_slot_[s], which is
  // computed for encodings_[pipeline_slots_[k]].
  std::vector<std::uint32_t> pipeline_of_slot_;
  std::vector<std::uint32_t> pipeline_slots_;
  mutable std::vector<float> pipeline_floats_;  // [pipeline * count + sample], reused across batches
};

}  // namespace depthbench
