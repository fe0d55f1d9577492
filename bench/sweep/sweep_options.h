// SweepOptions: what a caller asks of a sweep. Validate() checks every
// field against its allowed range and names the one violated, as Ceres'
// options do; nothing is clamped silently.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "bench/base/isa.h"
#include "bench/base/status.h"
#include "bench/device_judge/device_judge.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/domain.h"
#include "bench/pipeline/sampler.h"
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

// Default batch sizes, the fastest measured: on the host, a batch's arrays
// and the accumulators they reach stay in cache; with the judge on a GPU,
// larger batches spread each batch's fixed cost (queueing, the maxima read
// back) over more samples (reports/device-judge/h200.txt, section 11).
inline constexpr std::uint32_t kHostBatch = 16384;
inline constexpr std::uint32_t kDeviceJudgeBatch = 262144;
// The batch sizes a caller may ask for: from one frame's samples to the
// most the device judge's buffers are laid out for.
inline constexpr std::uint32_t kMinBatch = 64;
inline constexpr std::uint32_t kMaxBatch = 1u << 22;
// A 32-bit bin counts 4.29e9 samples: the counters move into the
// statistics at least this often.
inline constexpr std::uint64_t kMaxFlushEvery = std::uint64_t{1} << 31;

struct SweepOptions {
  std::uint64_t seed = 1;
  std::uint64_t samples = 1'000'000;  // of the whole sweep (all shards)
  Shard shard;
  Domain domain;
  std::vector<Cell> cells;  // empty: every cell the domain allows
  // Samples per batch, 0 or in [kMinBatch, kMaxBatch]; 0 picks by where the
  // judge runs: kHostBatch, or kDeviceJudgeBatch when a GPU judges. A
  // backend or judge that takes less cuts it. Results do not depend on it.
  std::uint32_t batch_size = 0;
  unsigned threads = 0;    // 0: one per hardware thread
  Isa isa = Isa::kWidest;  // of the hot loops (bench/base/isa.h): the same results whatever it is
  // When every camera lies in one distance band, that band is made from the
  // joint bands at the end rather than recorded per sample: the same
  // figures, less work (false: record it, as tests do to compare).
  bool derive_lone_distance_band = true;
  // Samples after which the 32-bit counters are moved into the statistics,
  // in [1, kMaxFlushEvery] (tests lower it to make the flush happen
  // mid-run).
  std::uint64_t flush_every = kMaxFlushEvery;
  // kDevice fails for a backend that cannot judge on its device.
  JudgeSite judge = JudgeSite::kAuto;
  // How a judge on a device works (tests pick each way).
  DeviceJudgeTuning device_tuning;
  // Where every backend judges on its device: whether the devices draw
  // the samples too, where they can (BatchFor::kDeviceDraws), or the host
  // draws them. The same samples either way.
  bool device_draws = true;
  std::function<void(const SweepProgress&)> progress;  // called after every batch

  // Checks every field; the error names the violated constraint
  // ("Violated constraint: SweepOptions::flush_every in [1, 2^31]").
  Status Validate() const;
};

}  // namespace depthbench
