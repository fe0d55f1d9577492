// DeviceJudge: the texels' storage, the reference and the judge run where
// a Vulkan backend's outputs already are, reached through the backend's
// DeviceResidentRuns (Backend::device_resident, vulkan_backend.h): the
// judge stages the backend's run and queues its own passes around the
// backend's reconstruction pass.
//
// The host judge (bench/pipeline/judge.h) reads every position back and
// bins it on the host's cores, against a reference the host computed; on a
// GPU that readback and those cores are what the device waits for. Here the
// reconstruction pass leaves its positions in device memory and the host
// uploads only what the device starts from: per frame its planes, float32
// constants, what the draw of its samples needs, and what each depth slot
// stores for the stored-value picks; per sample, unless the device draws
// the samples itself (BatchFor::kDeviceDraws), the ray, the eye depth and
// the coverage kind; and per pipeline and sample the float it produced,
// where depths are produced exactly. Up to four passes run on the device:
//   - shaders/judge/sample.comp (where the device draws), queued first,
//     draws every sample from (seed, index) as the host's sampler would
//     (shared/draw.h) and writes its pixel into the buffer the
//     reconstruction pass reads, and its eye depth, coverage and ray;
//   - shaders/judge/store.comp, queued before the reconstruction pass
//     (between the backend's Stage and QueueStaged),
//     stores every pipeline float in each depth slot's format and writes
//     what a fetch returns into the buffer that pass reads its texels from,
//     so that no texel per slot and sample crosses the bus;
//   - shaders/judge/reference.comp decodes, in double-double, the depth
//     each stored value and each pipeline float denotes, and computes the
//     reference of every (depth slot, sample): true and denoted depth,
//     inverse squared distance, squared storage and production errors,
//     band and status;
//   - shaders/judge/judge.comp counts every error into histograms that
//     stay on the device: each cell's total, shader and absolute errors,
//     and each encoding's storage and production errors.
// The host reads back only each batch's maxima (a few kilobytes) and, when
// a flush is due, the histograms.
//
// What it records equals the host judge's, bin for bin, count for count,
// maximum and worst index included: the shaders repeat the host's float64
// and double-double operations in order and unfused, and the judge reads
// bins from the same bits (tests/device_judge_test.cc holds the reference
// and the statistics equal). That needs the device's float64 add,
// multiply, divide and fma to round as IEEE 754 says, which Vulkan does not
// promise; docs/device-judge.md says what a device that differs would
// change. The frames stay with the host.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "bench/backends/backend.h"
#include "bench/base/status.h"
#include "bench/base/thread_pool.h"
#include "bench/pipeline/batch.h"
#include "bench/pipeline/stats.h"

namespace depthbench {

// Where the judge adds each sample's bins. kWorkgroupTable: first into a
// table in each workgroup's shared memory, then the table's totals into
// the device's counters (far fewer global atomic additions on bins that
// neighbouring samples share); kDeviceCounters: straight into the
// device's counters. kAuto: the table on a GPU, the counters on a CPU
// device, where the table is slower (reports/device-judge/lavapipe.txt,
// section 2). Either gives the same counts.
enum class JudgeBinMerge : std::uint8_t { kAuto, kWorkgroupTable, kDeviceCounters };

// Where the positions are judged. kSeparate: the backend's reconstruction
// pass writes them to device memory and judge.comp reads them back;
// kFused: one program per variant (shaders/judge/fused.comp, around the
// variant's function as the backend compiles it) reconstructs each sample
// and judges it in the same invocation, so no position goes through
// memory. kAuto: fused on a GPU where every variant of the run compiles
// into that program (an HLSL function does not), else separate (on a CPU
// device the separate passes are faster).
enum class JudgeFusion : std::uint8_t { kAuto, kFused, kSeparate };

// How the judge works on its device; any choice records the same figures
// (tests run each way).
struct DeviceJudgeTuning {
  JudgeBinMerge bins = JudgeBinMerge::kAuto;
  JudgeFusion fusion = JudgeFusion::kAuto;
  // How many candidates for the index of its maximum each accumulator
  // lists per batch (shaders/judge/judge.comp); one with more is judged
  // again whole. 0: every accumulator is.
  std::uint32_t candidates_per_row = 4096;
};

class DeviceJudge {
 public:
  // A judge on the device of `backend`, a backend with device-resident
  // runs (a Vulkan backend's) prepared for the compute form with the cells
  // of `layout`, for depths produced by `production` (kFloat32 or kExact).
  // Unavailable, saying why, for another backend, form or production, or
  // a device without float64 arithmetic and 64-bit atomics. `record_distances`: whether natural
  // samples also go to their camera-distance band
  // (CellAccumulator::records_distances).
  static Expected<std::unique_ptr<DeviceJudge>> Create(Backend& backend, const RunLayout& layout,
                                                       ProductionModel production, bool record_distances,
                                                       DeviceJudgeTuning tuning = {});
  ~DeviceJudge();
  DeviceJudge(const DeviceJudge&) = delete;
  DeviceJudge& operator=(const DeviceJudge&) = delete;

  // Draws the samples of `batch` where `device` says so (its draw seed:
  // BatchFor::kDeviceDraws), stores its texels (of the host's, only
  // `device`'s edge texels for the stored-value picks are read), runs
  // every cell of the layout on it and judges the outputs on the device.
  // It returns once the batch is queued there and the batch before it is
  // finished: the device runs one batch while the host writes the next
  // one's inputs. A finished batch's maxima go into `cells` (one
  // accumulator per cell, in layout order) and, unless it is empty,
  // `encodings` (one per depth slot: the storage and production errors,
  // which the device then records too), which also count its samples: the
  // accumulators of the last call must outlive the next call or Flush,
  // which finishes the last batch. The counts stay on the device until
  // Flush. `pool` writes the uploads.
  Status Judge(const Batch& batch, const DeviceJudgeInputs& device, std::span<CellAccumulator> cells,
               std::span<CellAccumulator> encodings, ThreadPool& pool);
  // The most samples one batch may have: the widest binding (the
  // reference of every depth slot) within the device's limit.
  std::uint64_t MaxBatchSamples() const;
  // Seconds spent waiting for the device to finish a batch's passes, since
  // this judge was made: with the host's time around Judge, it says which
  // side a batch waits for.
  double waited_seconds() const;
  // The device's seconds in each of its passes for the batches finished so
  // far, by name, in the order they run: "idle" (from one batch's end to
  // the next one's start: the device waiting for the host), "sample",
  // "store", "reconstruction" (the backend's pass, with any wait for the
  // judge's submission after it; where the judge is fused, "wait": that
  // wait alone), "reference", "judge" (phase 0: the histograms; fused,
  // "reconstruction+judge") and "maxima" (phase 1). Empty where the
  // device's queue writes no timestamps.
  std::vector<std::pair<std::string, double>> pass_seconds() const;
  // The host's seconds in each step of Judge, since this judge was made, in
  // order: "finish" (joining the batches the device finished, waits
  // included: waited_seconds), "upload" (the judge's inputs), "stage" (the
  // backend's staging of its run: its upload and, in the raster form, the
  // comparison of the run before's texels) and "queue" (recording and
  // submitting the passes). Where the device idles, one of these is what
  // it waits for.
  std::vector<std::pair<std::string, double>> host_seconds() const;
  // The reference the device computed for the last batch Judge was given,
  // in the host's layout (for tests and diagnosis; it finishes the batches
  // in flight).
  Expected<ReferenceArrays> LastReference() const;
  // The texels the storage pass wrote for the last batch (each depth
  // slot's fetched values, [depth slot * count + sample]), read from the
  // backend's buffer: valid until the backend's next run (for tests).
  Expected<std::vector<float>> LastTexels() const;
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
