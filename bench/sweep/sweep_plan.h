// SweepPlan: how a sweep will run, decided before it starts and checked
// whole: the batch size, where each backend is judged, what each batch must
// hold, whether building and judging overlap, and how the threads are
// shared out. It is a pure function of the options and of what each
// judging stage can do; the loop (sweep.cc) only follows it.
#pragma once

#include <cstdint>
#include <optional>
#include <span>

#include "bench/base/status.h"
#include "bench/pipeline/batch.h"
#include "bench/sweep/sweep_options.h"

namespace depthbench {

// What the plan needs to know of one backend's judging stage.
struct StageTraits {
  JudgeSite site = JudgeSite::kHost;             // where it judges: kHost or kDevice, never kAuto
  bool gpu = false;                              // its device is a GPU (DeviceKind::kGpu)
  std::uint64_t max_batch_samples = UINT64_MAX;  // its backend's and its judge's limit
};

struct SweepPlan {
  std::uint64_t first_sample = 0;  // the shard's samples [first_sample, end_sample)
  std::uint64_t end_sample = 0;
  std::uint32_t batch_size = 0;
  // What each batch holds: everything where any stage judges on the host;
  // otherwise what the devices start from (BatchFor).
  BatchFor built_for = BatchFor::kHostJudge;
  // Whether the host builds the next batch while the stages judge the last
  // (two batches in turn). Only where no stage needs the host's cores to
  // judge, that is where built_for is not kHostJudge.
  bool overlap = false;
  unsigned build_threads = 1;     // the sweep's pool: builds, host judging, final flush
  unsigned stage_threads = 0;     // the judging stage's own pool where it overlaps (its uploads); else 0
  std::uint64_t flush_every = 0;  // samples after which the 32-bit counters move into the statistics
  // The camera-distance band every sample lies in, made from the joint
  // bands at the end instead of being recorded per sample; none where the
  // distances span several bands or the options ask to record them.
  std::optional<int> only_distance_band;

  // Checks the plan's own constraints; the error names the one violated
  // ("Violated constraint: SweepPlan::...").
  Status Validate() const;
};

// The distance band a plan derives at the end rather than records (see
// SweepPlan::only_distance_band); the stages need it before the plan.
std::optional<int> LoneDistanceBand(const SweepOptions& options);

// Whether a backend on a device of this kind is judged on its device:
// kDevice asks for it; kAuto picks it for a GPU (a CPU device judges
// faster on the host's vector loops), in either form.
bool WantsDeviceJudge(JudgeSite site, bool gpu);

// The plan for validated `options` and the stages (one per backend, in
// order). `devices_can_draw`: whether the samples can be drawn on a device
// (BatchBuilder::DevicesCanDraw).
Expected<SweepPlan> PlanSweep(const SweepOptions& options, std::span<const StageTraits> stages, bool devices_can_draw);

}  // namespace depthbench
