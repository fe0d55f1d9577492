// JudgingStage: one backend's part of every batch. It runs the backend on
// the batch and records the errors of its outputs into the accumulators it
// owns, one per cell of the run's layout. The sweep's loop drives every
// backend through this one interface, whether its outputs are judged on the
// host's cores (HostJudgingStage) or on the device they were computed on
// (DeviceJudgingStage, over bench/device_judge/).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "bench/backends/backend.h"
#include "bench/base/isa.h"
#include "bench/base/status.h"
#include "bench/base/thread_pool.h"
#include "bench/pipeline/batch.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/stats.h"
#include "bench/results/results.h"
#include "bench/sweep/sweep_options.h"
#include "bench/sweep/sweep_plan.h"

namespace depthbench {

// The accumulators of a set of cells (or encodings) and the statistics
// they flush into.
class Tally {
 public:
  explicit Tally(std::size_t count, bool record_distances);
  std::span<CellAccumulator> accumulators() { return accumulators_; }
  // Moves every accumulator that holds at least `limit` samples into its
  // statistics.
  void FlushDue(std::uint64_t limit);
  // Moves every accumulator into its statistics, on the pool.
  void FlushAll(ThreadPool& pool);
  // The statistics, where every sample lies in distance band `only_band`
  // with that band made from the joint bands (SweepPlan::only_distance_band).
  std::vector<CellStats> TakeStats(std::optional<int> only_band);

 private:
  std::vector<CellAccumulator> accumulators_;
  std::vector<CellStats> stats_;
};

class JudgingStage {
 public:
  virtual ~JudgingStage() = default;
  JudgingStage(const JudgingStage&) = delete;
  JudgingStage& operator=(const JudgingStage&) = delete;

  Backend& backend() const { return backend_; }
  Tally& cells() { return cells_; }
  // What the plan needs to know (where it judges, its batch limit).
  virtual StageTraits traits() const = 0;

  // Runs the backend on every cell of the layout for `batch` and records
  // the errors. `device`: what a judge on the device reads beside the
  // batch. `encodings` is empty, or one accumulator per depth slot into
  // which this stage also records the storage and production errors (a
  // property of the batch, recorded by one stage only). A stage may return
  // before its device has finished; Flush finishes it.
  virtual Status Judge(const Batch& batch, const DeviceJudgeInputs& device, std::span<CellAccumulator> encodings,
                       ThreadPool& pool) = 0;
  // Brings every count the stage keeps outside its accumulators (a
  // device's) into them; `encodings` as Judge got them.
  virtual Status Flush(std::span<CellAccumulator> /*encodings*/) { return Status::Ok(); }
  // Adds the stage's own timings (a device's passes) to the run's.
  virtual void AddTimes(StageSeconds& /*stages*/) const {}

 protected:
  JudgingStage(Backend& backend, std::size_t cell_count, bool record_distances)
      : backend_(backend), cells_(cell_count, record_distances) {}

 private:
  Backend& backend_;
  Tally cells_;
};

// The stage for `backend`, prepared with the layout's cells: on its device
// where WantsDeviceJudge says so (kAuto falls back to the host where no
// judge can be made on the device; kDevice fails, saying why), else on
// the host. `record_distances`: whether natural samples also go to their
// camera-distance band.
Expected<std::unique_ptr<JudgingStage>> MakeJudgingStage(const SweepOptions& options, Backend& backend,
                                                         const RunLayout& layout, bool record_distances);

}  // namespace depthbench
