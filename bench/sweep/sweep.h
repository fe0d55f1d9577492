// Sweep: the run loop. Draws the samples of a shard in batches, runs every
// cell on every backend, judges the outputs against the reference, and
// streams the errors into fixed-size statistics, so memory stays flat
// however many samples run.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "bench/backends/backend.h"
#include "bench/base/isa.h"
#include "bench/base/thread_pool.h"
#include "bench/device_judge/device_judge.h"
#include "bench/pipeline/batch.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/domain.h"
#include "bench/results/results.h"

namespace depthbench {

struct SweepProgress {
  std::uint64_t samples_done = 0;
  std::uint64_t samples_total = 0;
  std::uint64_t reconstructions_done = 0;
  double seconds = 0.0;
  double fraction() const;
  // "4.20M/10.00M samples, 61.3M reconstructions/s"
  std::string Describe() const;
};

// Where a backend's outputs are judged: on the host (every backend), or on
// the device a Vulkan backend ran them on (bench/device_judge/), or by
// device kind: on the device for a GPU, on the host for a CPU device
// (lavapipe), where the host's vector loops are the faster judge.
enum class JudgeSite { kAuto, kHost, kDevice };

// Default batch sizes, the fastest measured. On the host, a batch's
// arrays and the accumulators they reach stay in cache. With the judge on
// an H200 (reports/device-judge/h200.txt, section 11), where the host
// builds one batch while the device judges the last, 262144 beat 131072
// in each of four interleaved pairs (6.48 against 4.55 G
// reconstructions/s, 4.76 against 4.22, 4.45 against 3.82, and 3.34
// against 2.68 on the wide domain) for at most 18 MiB more at the peak;
// 524288 was no faster and took 290 MiB. Each batch pays a fixed cost
// (the backend's and the judge's queueing, the maxima read back), and
// both stages' per-batch work took less time in larger batches.
inline constexpr std::uint32_t kHostBatch = 16384;
inline constexpr std::uint32_t kDeviceJudgeBatch = 262144;

struct SweepOptions {
  std::uint64_t seed = 1;
  std::uint64_t samples = 1'000'000;  // of the whole sweep (all shards)
  Shard shard;
  Domain domain;
  std::vector<Cell> cells;  // empty: every cell the domain allows
  // Samples per batch; 0 picks by where the judge runs: kHostBatch, or
  // kDeviceJudgeBatch when a GPU judges.
  std::uint32_t batch_size = 0;
  unsigned threads = 0;    // 0: one per hardware thread
  Isa isa = Isa::kWidest;  // of the hot loops (bench/base/isa.h): the same results whatever it is
  // When every camera lies in one distance band, that band is made from the
  // joint bands at the end rather than recorded per sample: the same
  // figures, less work (false: record it, as tests do to compare).
  bool derive_lone_distance_band = true;
  // Samples after which the 32-bit counters are moved into the statistics
  // (at most 2^31, well before they could overflow; tests lower it to
  // make the flush happen mid-run).
  std::uint64_t flush_every = std::uint64_t{1} << 31;
  // kDevice fails for a backend that cannot judge on its device.
  JudgeSite judge = JudgeSite::kAuto;
  // How a judge on a device works (tests pick each way).
  DeviceJudgeTuning device_tuning;
  // Where every backend judges on its device: whether the devices draw
  // the samples too, where they can (BatchFor::kDeviceDraws), or the host
  // draws them. The same samples either way.
  bool device_draws = true;
  std::function<void(const SweepProgress&)> progress;  // called after every batch
};

// The cells of `cells` that the domain can exercise (finite-far cells need
// finite frames, infinite-far cells need the domain to allow them).
std::vector<Cell> CellsForDomain(std::span<const Cell> cells, const Domain& domain);

// The backend whose rendered depths every backend reconstructs from: the
// first that renders its own (Backend::renders_depths), under the raster
// production model; null otherwise.
Backend* DepthRenderer(ProductionModel production, std::span<Backend* const> backends);
// Renders the batch's depths on `renderer` and adopts them into the batch
// (BatchBuilder::AdoptStoredDepths).
Status AdoptRenderedDepths(Backend& renderer, const BatchBuilder& builder, Batch& batch, ThreadPool& pool);

// Runs the sweep on each backend (prepared by this call) and returns the
// results, one CellResult per (cell, backend).
Expected<Results> RunSweep(const SweepOptions& options, std::span<Backend* const> backends);

}  // namespace depthbench
