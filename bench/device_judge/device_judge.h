// DeviceJudge: the judge run where a Vulkan backend's outputs already are.
//
// The host judge (bench/pipeline/judge.h) reads every position back and
// bins it on the host's cores; on a GPU that readback and those cores are
// what the device waits for. Here the reconstruction pass leaves its
// positions in device memory, the host uploads the batch's reference (per
// sample the ray and coverage kind; per depth slot and sample the true and
// the denoted depth, the inverse squared distance, the squared storage and
// production errors, the band and the status), and
// shaders/judge/judge.comp counts every error into histograms that stay on
// the device: each cell's total, shader and absolute errors, and each
// encoding's storage and production errors. The host reads
// back only each batch's maxima (a few kilobytes) and, when a flush is due,
// the histograms.
//
// What it records equals the host judge's, bin for bin, count for count,
// maximum and worst index included: the shader repeats the host's float64
// operations in order and unfused, and reads bins from the same bits
// (tests/device_judge_test.cc holds the two equal). The sampler, the
// encoding and the reference stay with the host.
#pragma once

#include <memory>
#include <span>

#include "bench/backends/backend.h"
#include "bench/base/status.h"
#include "bench/base/thread_pool.h"
#include "bench/pipeline/batch.h"
#include "bench/pipeline/stats.h"

namespace depthbench {

class DeviceJudge {
 public:
  // A judge on the device of `backend`, a Vulkan backend prepared for the
  // compute form with the cells of `layout`. Unavailable, saying why, for
  // another backend or form, or a device without float64 arithmetic and
  // 64-bit atomics. `record_distances`: whether natural samples also go to
  // their camera-distance band (CellAccumulator::records_distances).
  static Expected<std::unique_ptr<DeviceJudge>> Create(Backend& backend, const RunLayout& layout,
                                                       bool record_distances);
  ~DeviceJudge();
  DeviceJudge(const DeviceJudge&) = delete;
  DeviceJudge& operator=(const DeviceJudge&) = delete;

  // Runs every cell of the layout on `batch` and judges the outputs on the
  // device. Each batch's maxima go straight into `cells` (one accumulator
  // per cell, in layout order) and, unless it is empty, `encodings` (one
  // per depth slot: the storage and production errors, which the device
  // then records too); they also count the batch's samples. The counts
  // stay on the device until Flush. `pool` writes the uploads.
  Status Judge(const Batch& batch, std::span<CellAccumulator> cells, std::span<CellAccumulator> encodings,
               ThreadPool& pool);
  // The most samples one batch may have: the widest binding (the
  // reference of every depth slot) within the device's limit.
  std::uint64_t MaxBatchSamples() const;
  // Adds what the device counted since the last flush into the
  // accumulators (`encodings` as Judge was given them) and clears it there.
  // Due before any of them holds 2^31 samples.
  Status Flush(std::span<CellAccumulator> cells, std::span<CellAccumulator> encodings);

 private:
  struct State;
  explicit DeviceJudge(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

}  // namespace depthbench
