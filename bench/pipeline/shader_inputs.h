// ShaderInputs: what a backend receives for a batch of samples, exactly the
// bytes a GPU uploads (float32 constants per frame, pixels, fetched depths)
// and nothing of the truth behind them. The judge's side of a batch
// (batch.h) adds the exact frames and the reference; a backend is handed
// only this part, so "backends never judge" is what the types say.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "bench/numerics/formulas.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/sampler.h"  // kSamplesPerFrame

namespace depthbench {

struct ShaderInputs {
  std::uint64_t first_index = 0;
  std::uint32_t count = 0;
  std::uint32_t first_offset = 0;  // first_index % kSamplesPerFrame

  std::vector<f32::FrameParams> frame_params;  // [frame]
  std::vector<f32::DepthParams> depth_params;  // [frame * kHardwareConventionCount + convention]
  std::vector<std::uint32_t> pixels;           // [sample]: x | y << 16
  // The run's depth slots (its encodings). Where the host stores the
  // texels, depths and codes hold depth_slots * count values; where a
  // device stores them itself (bench/device_judge/), both are empty.
  std::uint32_t depth_slots = 0;
  std::vector<float> depths;         // [depth slot * count + sample]: fetched values
  std::vector<std::uint32_t> codes;  // [depth slot * count + sample]: the texel bits fetched
  // The raster pipeline's geometry (empty unless the domain's production
  // is ProductionModel::kRaster): [sample].
  std::vector<f32::RasterSample> raster;

  std::uint32_t FrameOf(std::uint32_t sample) const { return (sample + first_offset) / kSamplesPerFrame; }
  std::size_t frame_count() const { return frame_params.size(); }
};

// Where one cell's inputs live in a batch.
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

}  // namespace depthbench
