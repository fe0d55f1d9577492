#include "bench/speed/cpu_cost.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "bench/backends/cpu/cpu_backend.h"
#include "bench/base/interrupt.h"
#include "bench/base/thread_pool.h"
#include "bench/pipeline/encode.h"
#include "bench/pipeline/shader_constants.h"
#include "bench/speed/depth_image.h"

namespace depthbench {
namespace {

constexpr Resolution kCpuResolution{1920, 1080};

// Seconds of `runs` runs of cell `k` of the prepared backend.
Expected<double> TimeRuns(Backend& backend, const Batch& batch, std::uint32_t k, std::uint32_t runs,
                          std::vector<float>& scratch) {
  const std::uint32_t which[] = {k};
  const auto start = std::chrono::steady_clock::now();
  for (std::uint32_t r = 0; r < runs; ++r) {
    Expected<std::span<const float>> out = backend.Run(batch, which, scratch);
    if (!out.ok()) return out.status();
  }
  const auto stop = std::chrono::steady_clock::now();
  return std::chrono::duration<double, std::nano>(stop - start).count();
}

}  // namespace

CpuCostInput MakeCpuCostInput(std::span<const Cell> cells, std::uint32_t samples) {
  CpuCostInput input;
  input.layout = MakeRunLayout(cells);
  const Frame frame = SpeedFrame(kCpuResolution);
  const std::uint32_t first_row = kCpuResolution.height / 2;
  const std::uint32_t rows = std::min(kCpuResolution.height - first_row, (samples + frame.width - 1) / frame.width);
  samples = std::min(samples, rows * frame.width);

  Batch& batch = input.batch;
  batch.first_index = 0;
  batch.count = samples;
  batch.first_offset = 0;
  // Every frame slot holds the one frame's constants.
  const std::size_t frames = (samples + kSamplesPerFrame - 1) / kSamplesPerFrame;
  const hp::FrameParams exact = BuildFrameParams(frame);
  batch.frame_params.assign(frames, RoundToFloat(exact));
  batch.depth_params.resize(frames * kHardwareConventionCount);
  for (std::size_t f = 0; f < frames; ++f) {
    for (int c = 0; c < kHardwareConventionCount; ++c) {
      batch.depth_params[f * kHardwareConventionCount + c] =
          RoundToFloat(BuildDepthParams(frame, exact, static_cast<Convention>(c)));
    }
  }
  batch.pixels.resize(samples);
  for (std::uint32_t i = 0; i < samples; ++i) {
    batch.pixels[i] = (i % frame.width) | ((first_row + i / frame.width) << 16);
  }
  batch.depth_slots = static_cast<std::uint32_t>(input.layout.encodings.size());
  batch.depths.resize(input.layout.encodings.size() * std::size_t{samples});
  for (std::size_t s = 0; s < input.layout.encodings.size(); ++s) {
    const Encoding encoding = input.layout.encodings[s];
    const std::vector<std::uint32_t> codes = EncodeDepthRows(encoding, frame, first_row, rows);
    for (std::uint32_t i = 0; i < samples; ++i) batch.depths[s * samples + i] = FetchTexel(encoding.format, codes[i]);
  }
  return input;
}

Expected<std::vector<CpuCost>> MeasureCpuCosts(std::span<const Cell> cells, const CpuCostOptions& options) {
  if (cells.empty()) return InvalidArgument("no cells to time on the CPU");
  if (options.samples == 0 || options.repetitions == 0) {
    return InvalidArgument("CPU timing needs at least one sample and one repetition");
  }
  for (const Cell& cell : cells) {
    if (!Reads(cell.variant_info(), cell.convention, cell.format)) {
      return InvalidArgument(fmt::format("{} does not read {} under the {} convention; no CPU path to time",
                                         cell.variant_info().name, Info(cell.format).name, Info(cell.convention).name));
    }
  }
  const CpuCostInput input = MakeCpuCostInput(cells, options.samples);
  std::unique_ptr<Backend> backend = MakeCpuBackend();
  DB_RETURN_IF_ERROR(backend->Prepare(input.layout.cells));
  std::vector<float> scratch;
  std::vector<CpuCost> costs;
  for (std::uint32_t k = 0; k < input.layout.cells.size(); ++k) {
    // Warm-up and calibration: one run, then as many per repetition as
    // make it last min_repetition_ns.
    DB_ASSIGN_OR_RETURN(const double once, TimeRuns(*backend, input.batch, k, 1, scratch));
    const auto runs =
        static_cast<std::uint32_t>(std::clamp(std::ceil(options.min_repetition_ns / std::max(once, 1.0)), 1.0, 1e6));
    std::vector<double> per_reconstruction;
    for (std::uint32_t r = 0; r < options.repetitions; ++r) {
      // A repetition lasts about min_repetition_ns: a signal stops the run
      // between two of them.
      if (Interrupted()) return InterruptedError("no speed results written");
      DB_ASSIGN_OR_RETURN(const double ns, TimeRuns(*backend, input.batch, k, runs, scratch));
      per_reconstruction.push_back(ns / (static_cast<double>(runs) * input.batch.count));
    }
    DB_ASSIGN_OR_RETURN(const TimingSummary summary, SummarizeTimings(per_reconstruction));
    costs.push_back({input.layout.cells[k].cell, summary, runs, input.batch.count});
  }
  return costs;
}

}  // namespace depthbench
