#include "bench/sweep/judging_stage.h"

#include <algorithm>
#include <mutex>
#include <numeric>

#include <fmt/format.h>

#include "bench/device_judge/device_judge.h"
#include "bench/pipeline/judge.h"

namespace depthbench {

Tally::Tally(std::size_t count, bool record_distances) : accumulators_(count), stats_(count) {
  if (!record_distances) {
    for (CellAccumulator& a : accumulators_) a.SkipDistanceBands();
  }
}

void Tally::FlushDue(std::uint64_t limit) {
  for (std::size_t k = 0; k < accumulators_.size(); ++k) {
    if (accumulators_[k].pending() >= limit) accumulators_[k].FlushInto(stats_[k]);
  }
}

void Tally::FlushAll(ThreadPool& pool) {
  pool.ParallelFor(accumulators_.size(), [&](std::size_t lo, std::size_t hi, unsigned) {
    for (std::size_t k = lo; k < hi; ++k) accumulators_[k].FlushInto(stats_[k]);
  });
}

std::vector<CellStats> Tally::TakeStats(std::optional<int> only_band) {
  if (only_band) {
    for (CellStats& s : stats_) {
      if (!s.joint.empty()) s.distance[*only_band] = s.DistanceBandOf();
    }
  }
  return std::move(stats_);
}

namespace {

// The first error any worker reports.
class FirstError {
 public:
  void Set(const Status& s) {
    std::lock_guard lock(mutex_);
    if (status_.ok()) status_ = s;
  }
  Status Get() {
    std::lock_guard lock(mutex_);
    return status_;
  }

 private:
  std::mutex mutex_;
  Status status_;
};

// Judged on the host's cores: the backend's positions come back to host
// memory and are judged a depth slot at a time, since the cells that read
// one encoding share its reference (read once, while in cache).
class HostJudgingStage final : public JudgingStage {
 public:
  HostJudgingStage(Backend& backend, const RunLayout& layout, bool record_distances, Isa isa)
      : JudgingStage(backend, layout.cells.size(), record_distances),
        isa_(isa),
        cells_of_slot_(layout.encodings.size()),
        slot_order_(layout.encodings.size()),
        every_cell_(layout.cells.size()) {
    for (std::uint32_t c = 0; c < layout.cells.size(); ++c) cells_of_slot_[layout.cells[c].depth_slot].push_back(c);
    // The slots with the most cells first: the threads take them in this
    // order, and the small ones at the end even out the finish.
    std::iota(slot_order_.begin(), slot_order_.end(), 0u);
    std::stable_sort(slot_order_.begin(), slot_order_.end(), [&](std::uint32_t a, std::uint32_t b) {
      return cells_of_slot_[a].size() > cells_of_slot_[b].size();
    });
    std::iota(every_cell_.begin(), every_cell_.end(), 0u);
  }

  StageTraits traits() const override {
    return {JudgeSite::kHost, backend().device().kind == DeviceKind::kGpu, backend().MaxBatchSamples()};
  }

  // A backend that runs on several threads at once runs a depth slot's
  // cells on the thread that judges them; another runs every cell first.
  Status Judge(const Batch& batch, const DeviceJudgeInputs& /*device*/, std::span<CellAccumulator> encodings,
               ThreadPool& pool) override {
    if (scratch_.size() < pool.size()) scratch_.resize(pool.size());
    const Status judged =
        backend().concurrent() ? RunAndJudgeBySlot(batch, encodings, pool) : RunThenJudge(batch, encodings, pool);
    return judged.WithContext("running the " + backend().name() + " backend");
  }

 private:
  Status RunAndJudgeBySlot(const Batch& batch, std::span<CellAccumulator> encodings, ThreadPool& pool) {
    FirstError error;
    pool.ParallelFor(slot_order_.size(), [&](std::size_t lo, std::size_t hi, unsigned worker) {
      for (std::size_t next = lo; next < hi; ++next) {
        const std::uint32_t slot = slot_order_[next];
        const std::span<const std::uint32_t> which = cells_of_slot_[slot];
        auto out = backend().Run(batch, which, scratch_[worker]);
        Status read = out.ok() ? CheckSize(*out, batch, which.size()) : out.status();
        if (!read.ok()) {
          error.Set(read);
          return;
        }
        JudgeCellsOfSlot(batch, slot, encodings,
                         [&](std::size_t k, std::uint32_t) { return Positions(*out, batch, k); });
      }
    });
    return error.Get();
  }

  Status RunThenJudge(const Batch& batch, std::span<CellAccumulator> encodings, ThreadPool& pool) {
    auto out = backend().Run(batch, every_cell_, scratch_[0]);
    if (!out.ok()) return out.status();
    DB_RETURN_IF_ERROR(CheckSize(*out, batch, every_cell_.size()));
    pool.ParallelFor(slot_order_.size(), [&](std::size_t lo, std::size_t hi, unsigned) {
      for (std::size_t next = lo; next < hi; ++next) {
        JudgeCellsOfSlot(batch, slot_order_[next], encodings,
                         [&](std::size_t, std::uint32_t c) { return Positions(*out, batch, c); });
      }
    });
    return Status::Ok();
  }

  // A backend's outputs hold x, y and z of every sample for each cell asked
  // (a backend may return a longer buffer of its own).
  Status CheckSize(std::span<const float> out, const Batch& batch, std::size_t cells) const {
    const std::size_t expected = cells * 3 * std::size_t{batch.count};
    if (out.size() >= expected) return Status::Ok();
    return Internal(fmt::format("the {} backend returned {} values for {} cells of {} samples ({} needed)",
                                backend().name(), out.size(), cells, batch.count, expected));
  }

  static std::span<const float> Positions(std::span<const float> out, const Batch& batch, std::size_t k) {
    const std::size_t per_cell = std::size_t{batch.count} * 3;
    return out.subspan(per_cell * k, per_cell);
  }

  // Judges the cells of depth slot `slot`; `positions_of(k, c)` gives the
  // outputs of its k-th cell, cell c of the layout. The slot's encoding
  // errors are recorded with them where this stage records encodings.
  template <typename PositionsOf>
  void JudgeCellsOfSlot(const Batch& batch, std::uint32_t slot, std::span<CellAccumulator> encodings,
                        PositionsOf positions_of) {
    std::vector<JudgedCell> judged;
    std::span<CellAccumulator> acc = cells().accumulators();
    const std::vector<std::uint32_t>& which = cells_of_slot_[slot];
    for (std::size_t k = 0; k < which.size(); ++k) judged.push_back({positions_of(k, which[k]), &acc[which[k]]});
    depthbench::JudgeSlot(batch, slot, judged, isa_);
    if (!encodings.empty()) RecordEncodingErrors(batch, slot, encodings[slot], isa_);
  }

  Isa isa_;
  std::vector<std::vector<std::uint32_t>> cells_of_slot_;
  std::vector<std::uint32_t> slot_order_;
  std::vector<std::uint32_t> every_cell_;
  std::vector<std::vector<float>> scratch_;  // one per worker of the pool
};

// Judged on the device the backend ran on (bench/device_judge/): the
// counts stay there until a flush.
class DeviceJudgingStage final : public JudgingStage {
 public:
  DeviceJudgingStage(Backend& backend, std::size_t cell_count, bool record_distances,
                     std::unique_ptr<DeviceJudge> judge)
      : JudgingStage(backend, cell_count, record_distances), judge_(std::move(judge)) {}

  StageTraits traits() const override {
    return {JudgeSite::kDevice, backend().device().kind == DeviceKind::kGpu,
            std::min(backend().MaxBatchSamples(), judge_->MaxBatchSamples())};
  }

  Status Judge(const Batch& batch, const DeviceJudgeInputs& device, std::span<CellAccumulator> encodings,
               ThreadPool& pool) override {
    return judge_->Judge(batch, device, cells().accumulators(), encodings, pool)
        .WithContext("running and judging on the " + backend().name() + " backend");
  }

  Status Flush(std::span<CellAccumulator> encodings) override {
    return judge_->Flush(cells().accumulators(), encodings);
  }

  void AddTimes(StageSeconds& stages) const override {
    stages.device_waited += judge_->waited_seconds();
    for (const auto& [name, seconds] : judge_->pass_seconds()) stages.AddDevicePass(name, seconds);
    for (const auto& [name, seconds] : judge_->host_seconds()) stages.AddJudgeHostStep(name, seconds);
  }

 private:
  std::unique_ptr<DeviceJudge> judge_;
};

}  // namespace

Expected<std::unique_ptr<JudgingStage>> MakeJudgingStage(const SweepOptions& options, Backend& backend,
                                                         const RunLayout& layout, bool record_distances) {
  const ProductionModel production = options.domain.production;
  const bool gpu = backend.device().kind == DeviceKind::kGpu;
  if (WantsDeviceJudge(options.judge, gpu)) {
    Expected<std::unique_ptr<DeviceJudge>> judge =
        DeviceJudge::Create(backend, layout, production, record_distances, options.device_tuning);
    if (judge.ok()) {
      return std::unique_ptr<JudgingStage>(
          new DeviceJudgingStage(backend, layout.cells.size(), record_distances, std::move(judge).value()));
    }
    if (options.judge == JudgeSite::kDevice) {
      return judge.status().WithContext("judging on the " + backend.name() + " backend's device");
    }
  }
  return std::unique_ptr<JudgingStage>(new HostJudgingStage(backend, layout, record_distances, options.isa));
}

}  // namespace depthbench
