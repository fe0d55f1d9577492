// Batch: a contiguous range of samples made ready for the backends and the
// judge. The builder draws the samples, encodes every depth the run's cells
// read, packs the shader inputs (the part a backend sees, shader_inputs.h)
// and computes the reference for every (encoding, sample), which only the
// judge reads (unless the judge computes it on its device: BatchFor). What
// only a judge on a device reads comes apart, in DeviceJudgeInputs.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "bench/base/thread_pool.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/encode.h"
#include "bench/pipeline/reference.h"
#include "bench/pipeline/sampler.h"
#include "bench/pipeline/shader_inputs.h"

namespace depthbench {

// The shader inputs, and the truth behind them for the judge, as arrays of
// components so that the judge reads them in SIMD lanes.
struct Batch : ShaderInputs {
  std::vector<Frame> frames;                 // [frame]: exact parameters
  std::vector<std::uint8_t> distance_bands;  // [frame]: DistanceBand of the camera
  std::vector<double> ray_x, ray_y, ray_z;   // [sample]: world-space ray at unit eye depth
  // [sample]: the camera-relative point at eye depth 0 (reference.h
  // PixelOffset) when the frames are orthographic; empty when perspective.
  std::vector<double> offset_x, offset_y, offset_z;
  SampleArrays samples;                      // [sample]: the depth pick and what the reference needs
  ReferenceArrays reference;                 // [depth slot * count + sample]; empty where a device judges (BatchFor)
  // The float32 each pipeline produced (PipelineOfSlots), [pipeline *
  // count + sample].
  std::vector<float> pipeline_floats;

  glm::dvec3 Ray(std::uint32_t sample) const { return {ray_x[sample], ray_y[sample], ray_z[sample]}; }
  glm::dvec3 Offset(std::uint32_t sample) const {
    return offset_x.empty() ? glm::dvec3(0.0) : glm::dvec3(offset_x[sample], offset_y[sample], offset_z[sample]);
  }
};

// What a judge on the device (bench/device_judge/) reads of a batch beyond
// the Batch itself, whatever the batch was built for.
struct DeviceJudgeInputs {
  // What a fetch returns for each stored-value pick (a DepthPick other
  // than kEyeDepth) in each frame and depth slot, [(frame * depth slots +
  // slot) * 4 + pick - 1]: the judge stores the other texels itself.
  std::vector<float> edge_texels;
  // Where the device draws the samples (BatchFor::kDeviceDraws), the seed
  // it draws them from (SampleSource::device_draw_seed); the batch then
  // holds its frames alone. Nullopt where the batch holds its samples.
  std::optional<std::uint64_t> draw_seed;
};

// The pipeline whose float each depth slot stores, [depth slot]: the
// formats of one convention that store the same kind of value share one
// (encode.h). Pipelines are numbered in the order their first slot comes.
std::vector<std::uint32_t> PipelineOfSlots(std::span<const Encoding> encodings);

// Who a batch is built for. kHostJudge: everything, the stored texels
// and the reference included. kDeviceJudge: where every judge works on its
// device (bench/device_judge/), which produces the depths (in float32),
// stores the texels and computes the reference itself: the batch's stored
// depths (depths, codes) are not filled, its reference is empty, and so
// are its pipeline floats unless depths are produced exactly
// (ProductionModel), when its samples also hold only what was drawn
// (SampleFields::kDrawn). kDeviceDraws: as kDeviceJudge, and the device
// draws the samples too (shaders/judge/sample.comp): the batch holds its
// frames and their shader constants, and nothing per sample. It needs
// DevicesCanDraw() and a DeviceJudgeInputs to carry the seed; elsewhere it
// builds as kDeviceJudge.
enum class BatchFor : std::uint8_t { kHostJudge, kDeviceJudge, kDeviceDraws };

class BatchBuilder {
 public:
  // `isa`: what the decode and reference loops are compiled for
  // (bench/base/isa.h). Depth is produced as the source says (domain.h).
  BatchBuilder(const SampleSource& sampler, std::vector<Encoding> encodings, Isa isa = Isa::kWidest);

  // Whether a device can draw this builder's samples: their source says
  // it can (SampleSource::device_draw_seed: the random Sampler, not a
  // list) and their depths are produced in float32.
  bool DevicesCanDraw() const;

  // Fills `batch` with samples [first, first + count) and, where given,
  // `device` with what a judge on the device reads beside it.
  void Build(std::uint64_t first, std::uint32_t count, Batch& batch, ThreadPool& pool,
             BatchFor judge = BatchFor::kHostJudge, DeviceJudgeInputs* device = nullptr) const;

  // The raster pipeline on a device: replaces the stored texels of the
  // samples that have geometry by the ones the device rendered (codes and
  // fetched floats, [depth slot * count + sample]) and computes their
  // references again. The production part stays the host's model's, so the
  // storage part then holds the device's own rounding and interpolation.
  // `batch` must be the last one Build filled. Where `drawn` (laid out as
  // codes; empty: all) is 0 the rasterizer left the texel as cleared, and
  // the sample is not judged in that slot (ReferenceStatus::kUndrawn).
  void AdoptStoredDepths(Batch& batch, std::span<const std::uint32_t> codes, std::span<const float> fetched,
                         std::span<const std::uint8_t> drawn, ThreadPool& pool) const;

 private:
  static constexpr std::size_t kChunk = 1024;  // samples per job of the encode and reference loops
  DepthMappings MappingOf(const Batch& batch, std::size_t pipeline) const;
  // Decodes slot `slot`'s stored values of samples [lo, lo + n) and
  // computes their references.
  void ReferenceChunk(Batch& batch, std::size_t slot, std::size_t lo, std::size_t n) const;

  const SampleSource& sampler_;
  std::vector<Encoding> encodings_;
  ProductionModel model_;
  Isa isa_;
  // The formats of one convention share the pipeline's float (encode.h):
  // encodings_[s] reads pipeline value pipeline_of_slot_[s], which is
  // computed for encodings_[pipeline_slots_[k]].
  std::vector<std::uint32_t> pipeline_of_slot_;
  std::vector<std::uint32_t> pipeline_slots_;
  // Reused across batches, [pipeline * count + sample]: the float32
  // constants of the pipelines' mappings (encode.h) and the depth each
  // pipeline's float denotes (the produced depth).
  mutable std::vector<double> mapping_a_, mapping_b_, produced_;
  // The samples that pick a stored value, [chunk * kChunk + k] for k below
  // pick_counts_[chunk] (for the host judge).
  mutable std::vector<std::uint32_t> pick_samples_, pick_counts_;
  // What each frame and depth slot stores for each stored-value pick, laid
  // out as DeviceJudgeInputs::edge_texels.
  mutable std::vector<StoredDepth> edges_;
};

}  // namespace depthbench
