// CPU cost: nanoseconds per reconstruction of the CPU backend's path (the
// shared/ formulas in eight float32 SIMD lanes, bench/backends/cpu/cpu_backend.cc), on
// one thread, over the pixels of the depth image the GPU passes read
// (depth_image.h): ordinary depths, as a frame holds them. The backend is driven through its public interface, so
// what is timed is exactly what `depthbench run` executes per cell.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "bench/backends/backend.h"
#include "bench/base/status.h"
#include "bench/pipeline/batch.h"
#include "bench/pipeline/cells.h"
#include "bench/speed/timing_stats.h"

namespace depthbench {

// The backend inputs of `samples` consecutive pixels (raster order, from
// the middle row down) of the 1920x1080 speed image of every encoding
// `cells` read, and the layout that says where each cell's inputs are.
// Only what the backends read is filled in (no reference).
struct CpuCostInput {
  RunLayout layout;
  Batch batch;
};
CpuCostInput MakeCpuCostInput(std::span<const Cell> cells, std::uint32_t samples);

struct CpuCost {
  Cell cell;
  TimingSummary ns_per_reconstruction;
  std::uint32_t runs_per_repetition = 0;  // backend runs timed together
  std::uint32_t samples_per_run = 0;
};

struct CpuCostOptions {
  std::uint32_t samples = 4096;  // per backend run: fits in L1/L2 with its outputs
  std::uint32_t repetitions = 15;
  double min_repetition_ns = 2e6;  // each repetition runs the cell at least this long
};

// One CpuCost per cell, in the order given. InvalidArgument when a cell
// does not exist or the options are empty.
Expected<std::vector<CpuCost>> MeasureCpuCosts(std::span<const Cell> cells, const CpuCostOptions& options);

}  // namespace depthbench
