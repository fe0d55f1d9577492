#include "bench/batch.h"

#include <algorithm>

#include "bench/encode.h"
#include "bench/shader_constants.h"

namespace depthbench {

RunLayout MakeRunLayout(std::span<const Cell> cells) {
  RunLayout layout;
  for (const Cell& cell : cells) {
    auto it = std::find(layout.encodings.begin(), layout.encodings.end(), cell.encoding());
    auto slot = static_cast<std::uint32_t>(it - layout.encodings.begin());
    if (it == layout.encodings.end()) layout.encodings.push_back(cell.encoding());
    std::uint32_t convention_slot =
        Info(cell.convention).hardware ? static_cast<std::uint32_t>(cell.convention) : 0u;
    layout.cells.push_back({cell, slot, convention_slot});
  }
  return layout;
}

BatchBuilder::BatchBuilder(const Sampler& sampler, std::vector<Encoding> encodings)
    : sampler_(sampler), encodings_(std::move(encodings)) {}

void BatchBuilder::Build(std::uint64_t first, std::uint32_t count, Batch& batch, ThreadPool& pool) const {
  const std::size_t slots = encodings_.size();
  batch.first_index = first;
  batch.count = count;
  batch.first_offset = static_cast<std::uint32_t>(first % kSamplesPerFrame);
  const std::uint64_t first_frame = first / kSamplesPerFrame;
  const std::size_t frames =
      count == 0 ? 0 : static_cast<std::size_t>((first + count - 1) / kSamplesPerFrame - first_frame + 1);

  batch.frames.resize(frames);
  batch.frame_params.resize(frames);
  batch.depth_params.resize(frames * kHardwareConventionCount);
  pool.ParallelFor(frames, [&](std::size_t begin, std::size_t end, unsigned) {
    for (std::size_t f = begin; f < end; ++f) {
      Frame& frame = batch.frames[f];
      frame = sampler_.FrameAt(first_frame + f);
      hp::FrameParams exact = BuildFrameParams(frame);
      batch.frame_params[f] = RoundToFloat(exact);
      for (int c = 0; c < kHardwareConventionCount; ++c) {
        f32::DepthParams& out = batch.depth_params[f * kHardwareConventionCount + c];
        // Conventions with a finite far plane have no constants on frames
        // that have none (infinite-only domains); their cells do not run.
        bool needs_far = (Info(static_cast<Convention>(c)).bits & f32::DB_CONVENTION_INFINITE) == 0u;
        out = needs_far && !frame.finite() ? f32::DepthParams{}
                                           : RoundToFloat(BuildDepthParams(frame, exact, static_cast<Convention>(c)));
      }
    }
  });

  batch.pixels.resize(count);
  batch.depths.resize(slots * count);
  batch.codes.resize(slots * count);
  batch.reference.resize(slots * count);
  pool.ParallelFor(
      count,
      [&](std::size_t begin, std::size_t end, unsigned) {
        for (std::size_t i = begin; i < end; ++i) {
          const Frame& frame = batch.frames[batch.FrameOf(static_cast<std::uint32_t>(i))];
          const PixelSample sample = sampler_.SampleAt(first + i, frame);
          batch.pixels[i] = sample.x | (sample.y << 16);
          const SampleReference reference(frame, sample);
          for (std::size_t s = 0; s < slots; ++s) {
            const Encoding encoding = encodings_[s];
            StoredDepth stored = sample.pick == DepthPick::kEyeDepth
                                     ? EncodeEyeDepth(encoding, frame, sample.eye_depth)
                                     : EncodeEdge(encoding, frame, sample.pick);
            const std::size_t at = s * count + i;
            batch.depths[at] = stored.fetched;
            batch.codes[at] = stored.code;
            batch.reference[at] = reference.For(encoding, stored.code);
          }
        }
      },
      256);
}

}  // namespace depthbench
