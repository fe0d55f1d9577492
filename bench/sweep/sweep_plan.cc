#include "bench/sweep/sweep_plan.h"

#include <algorithm>

#include <fmt/format.h>

#include "bench/base/thread_pool.h"

namespace depthbench {

Status SweepPlan::Validate() const {
  if (first_sample > end_sample) return ViolatedConstraint("SweepPlan::first_sample <= end_sample");
  if (batch_size < 1) return ViolatedConstraint("SweepPlan::batch_size >= 1");
  if (flush_every < 1 || flush_every > kMaxFlushEvery) return ViolatedConstraint("SweepPlan::flush_every in [1, 2^31]");
  if (build_threads < 1) return ViolatedConstraint("SweepPlan::build_threads >= 1");
  if (overlap != (built_for != BatchFor::kHostJudge)) {
    return ViolatedConstraint("SweepPlan::overlap == (built_for != kHostJudge): a host judge needs the build's cores");
  }
  if (overlap != (stage_threads > 0)) {
    return ViolatedConstraint("SweepPlan::stage_threads > 0 exactly where it overlaps");
  }
  return Status::Ok();
}

std::optional<int> LoneDistanceBand(const SweepOptions& options) {
  if (!options.derive_lone_distance_band) return std::nullopt;
  return OnlyDistanceBand(options.domain.camera_distance);
}

bool WantsDeviceJudge(JudgeSite site, bool gpu) {
  switch (site) {
    case JudgeSite::kHost: return false;
    case JudgeSite::kDevice: return true;
    case JudgeSite::kAuto: return gpu;
  }
  return false;
}

Expected<SweepPlan> PlanSweep(const SweepOptions& options, std::span<const StageTraits> stages, bool devices_can_draw) {
  if (stages.empty()) return InvalidArgument("no backend to run");
  SweepPlan plan;
  plan.first_sample = options.shard.Begin(options.samples);
  plan.end_sample = options.shard.End(options.samples);
  plan.flush_every = options.flush_every;
  plan.only_distance_band = LoneDistanceBand(options);

  // A batch no stage can take whole is cut to what the smallest takes.
  const bool gpu_judges = std::any_of(stages.begin(), stages.end(),
                                      [](const StageTraits& s) { return s.site == JudgeSite::kDevice && s.gpu; });
  std::uint64_t batch = options.batch_size != 0 ? options.batch_size : gpu_judges ? kDeviceJudgeBatch : kHostBatch;
  for (const StageTraits& stage : stages) batch = std::min(batch, stage.max_batch_samples);
  plan.batch_size = static_cast<std::uint32_t>(batch);

  // The host stores the texels and computes the reference only where it
  // judges. Where every stage judges on its device, the devices also draw
  // the samples when they can.
  const bool host_judges =
      std::any_of(stages.begin(), stages.end(), [](const StageTraits& s) { return s.site == JudgeSite::kHost; });
  plan.built_for = host_judges                                ? BatchFor::kHostJudge
                   : options.device_draws && devices_can_draw ? BatchFor::kDeviceDraws
                                                              : BatchFor::kDeviceJudge;

  // Where every stage judges on its device, the host builds the next batch
  // while the devices take the last one, and the threads are shared out: a
  // quarter (at most 4) to the judging stage's uploads, the rest to the
  // build, so that neither waits for a core (reports/device-judge/h200.txt,
  // section 7: 12 + 4 of 16 threads beat 16 + 4).
  plan.overlap = plan.built_for != BatchFor::kHostJudge;
  const unsigned threads = ThreadPool::ThreadCount(options.threads);
  plan.stage_threads = plan.overlap ? std::clamp(threads / 4, 1u, 4u) : 0u;
  plan.build_threads = std::max(1u, threads - plan.stage_threads);
  DB_RETURN_IF_ERROR(plan.Validate());
  return plan;
}

}  // namespace depthbench
