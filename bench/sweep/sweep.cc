#include "bench/sweep/sweep.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <future>
#include <memory>
#include <mutex>
#include <numeric>

#include <fmt/format.h>

#include "bench/base/build_info.h"
#include "bench/base/environment.h"
#include "bench/base/interrupt.h"
#include "bench/base/text_table.h"
#include "bench/base/thread_pool.h"
#include "bench/device_judge/device_judge.h"
#include "bench/pipeline/batch.h"
#include "bench/pipeline/judge.h"
#include "bench/pipeline/sampler.h"

namespace depthbench {

double SweepProgress::fraction() const {
  return samples_total == 0 ? 1.0 : static_cast<double>(samples_done) / static_cast<double>(samples_total);
}

std::string SweepProgress::Describe() const {
  return fmt::format("{}/{} samples, {} reconstructions/s", ShortCount(static_cast<double>(samples_done)),
                     ShortCount(static_cast<double>(samples_total)),
                     ShortCount(static_cast<double>(reconstructions_done) / std::max(seconds, 1e-9)));
}
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

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

// Storage and production statistics live per encoding; each cell reports
// its encoding's.
void CopyEncodingMetrics(const CellStats& from, CellStats& to) {
  const auto copy = [](const std::map<int, BandStats>& bands, std::map<int, BandStats>& into) {
    for (const auto& [band, stats] : bands) {
      for (Metric m : {Metric::kStorage, Metric::kProduction}) {
        into[band].metrics[static_cast<int>(m)] = stats.metrics[static_cast<int>(m)];
      }
    }
  };
  copy(from.joint, to.joint);
  copy(from.distance, to.distance);
  copy(from.coverage, to.coverage);
}

// The judge on the device of `backend`, where `site` asks for one; null
// where the outputs are judged on the host.
Expected<std::unique_ptr<DeviceJudge>> DeviceJudgeFor(JudgeSite site, Backend& backend, const RunLayout& layout,
                                                      bool record_distances, ProductionModel production,
                                                      DeviceJudgeTuning tuning) {
  if (site == JudgeSite::kHost) return std::unique_ptr<DeviceJudge>();
  const bool gpu = backend.device().kind == "gpu";
  if (site == JudgeSite::kAuto && (!gpu || PassKindOf(production) != PassKind::kCompute)) {
    return std::unique_ptr<DeviceJudge>();
  }
  Expected<std::unique_ptr<DeviceJudge>> judge =
      DeviceJudge::Create(backend, layout, production, record_distances, tuning);
  if (!judge.ok() && site == JudgeSite::kAuto) return std::unique_ptr<DeviceJudge>();
  return judge;
}

}  // namespace

Backend* DepthRenderer(ProductionModel production, std::span<Backend* const> backends) {
  if (PassKindOf(production) != PassKind::kRaster) return nullptr;
  for (Backend* backend : backends) {
    if (backend->renders_depths()) return backend;
  }
  return nullptr;
}

Status AdoptRenderedDepths(Backend& renderer, const BatchBuilder& builder, Batch& batch, ThreadPool& pool) {
  auto rendered = renderer.RenderDepths(batch);
  if (!rendered.ok()) return rendered.status().WithContext("rendering depths on the " + renderer.name() + " backend");
  builder.AdoptStoredDepths(batch, rendered->codes, rendered->fetched, pool);
  return Status::Ok();
}

std::vector<Cell> CellsForDomain(std::span<const Cell> cells, const Domain& domain) {
  std::vector<Cell> out;
  for (const Cell& cell : cells) {
    const ConventionInfo& c = Info(cell.convention);
    const DepthInput stores = Info(cell.format).stores;
    bool needs_finite = (c.hardware && (c.bits & f32::DB_CONVENTION_INFINITE) == 0u) || stores == DepthInput::kLinear;
    bool needs_infinite = c.hardware && (c.bits & f32::DB_CONVENTION_INFINITE) != 0u;
    if (needs_finite && !domain.finite_far) continue;
    if (needs_infinite && !domain.infinite_far) continue;
    out.push_back(cell);
  }
  return out;
}

Expected<Results> RunSweep(const SweepOptions& options, std::span<Backend* const> backends) {
  DB_RETURN_IF_ERROR(options.domain.Validate());
  if (backends.empty()) return InvalidArgument("no backend to run");
  // A 32-bit bin can count 4.29e9 samples; flush well before.
  const std::uint64_t flush_every = std::clamp<std::uint64_t>(options.flush_every, 1, std::uint64_t{1} << 31);
  if (!ProcessorRuns(options.isa)) return Unavailable("this processor does not run the requested instruction set");
  const std::vector<Cell> all = AllCells();
  const std::vector<Cell> cells = CellsForDomain(
      options.cells.empty() ? std::span<const Cell>(all) : std::span<const Cell>(options.cells), options.domain);
  if (cells.empty()) {
    return InvalidArgument(
        "none of the selected cells can run in this domain (finite-far conventions and linear formats need "
        "a finite far plane; infinite-far conventions need --ratio to allow inf)");
  }
  const RunLayout layout = MakeRunLayout(cells);
  for (Backend* backend : backends) {
    DB_RETURN_IF_ERROR(backend->Prepare(layout.cells, PassKindOf(options.domain.production))
                           .WithContext("preparing the " + backend->name() + " backend"));
  }

  const auto started = std::chrono::steady_clock::now();
  Results results;
  RunInfo& run = results.run;
  run.version = BuildVersion();
  run.commit = BuildCommit();
  run.started_at = CurrentTimeUtc();
  run.host = HostName();
  run.seed = options.seed;
  run.samples = options.samples;
  run.samples_per_frame = kSamplesPerFrame;
  run.shards = {options.shard};
  run.domain = options.domain;
  run.cells = cells;
  for (Backend* backend : backends) run.backends.push_back({backend->name(), backend->device(), backend->program()});

  const Sampler sampler(options.seed, options.domain);
  const BatchBuilder builder(sampler, layout.encodings, options.isa);
  const std::size_t cell_count = layout.cells.size();
  std::vector<CellAccumulator> accumulators(backends.size() * cell_count);
  std::vector<CellStats> stats(backends.size() * cell_count);
  // Cameras in one distance band (the origin, in the typical domain): the
  // band is the whole natural distribution, made once at the end.
  const std::optional<int> only_distance_band =
      options.derive_lone_distance_band ? OnlyDistanceBand(options.domain.camera_distance) : std::nullopt;
  if (only_distance_band) {
    for (CellAccumulator& a : accumulators) a.SkipDistanceBands();
  }
  // Storage and production errors belong to an encoding, whatever reads
  // it: one accumulator per depth slot, copied into its cells at the end.
  const std::size_t slot_count = layout.encodings.size();
  std::vector<CellAccumulator> storage_accumulators(slot_count);
  std::vector<CellStats> storage_stats(slot_count);
  // Backends whose outputs are judged on their device; the others' on the
  // host, below.
  std::vector<std::unique_ptr<DeviceJudge>> device_judges(backends.size());
  for (std::size_t b = 0; b < backends.size(); ++b) {
    DB_RETURN_IF_ERROR(StoreInto(DeviceJudgeFor(options.judge, *backends[b], layout, !only_distance_band,
                                                options.domain.production, options.device_tuning),
                                 device_judges[b])
                           .WithContext("judging on the " + backends[b]->name() + " backend's device"));
    if (device_judges[b] != nullptr) run.backends[b].judge = "device";
  }
  // A batch no backend can take whole is cut to what the smallest takes.
  bool gpu_judges = false;
  for (std::size_t b = 0; b < backends.size(); ++b) {
    gpu_judges = gpu_judges || (device_judges[b] != nullptr && backends[b]->device().kind == "gpu");
  }
  std::uint64_t batch_size = options.batch_size != 0 ? options.batch_size : gpu_judges ? kDeviceJudgeBatch : kHostBatch;
  for (const Backend* backend : backends) batch_size = std::min(batch_size, backend->MaxBatchSamples());
  for (const auto& judge : device_judges) {
    if (judge != nullptr) batch_size = std::min(batch_size, judge->MaxBatchSamples());
  }
  // The host stores the texels and computes the reference only where it judges.
  // Where every backend judges on its device, the devices also draw the
  // samples when they can (BatchBuilder::DevicesCanDraw).
  const bool host_judges = std::find(device_judges.begin(), device_judges.end(), nullptr) != device_judges.end();
  const BatchFor built_for = host_judges                                        ? BatchFor::kHostJudge
                             : options.device_draws && builder.DevicesCanDraw() ? BatchFor::kDeviceDraws
                                                                                : BatchFor::kDeviceJudge;
  // Where every backend judges on its device, the host builds the next
  // batch while the devices take the last one (below): the threads are
  // shared out between the two stages, a quarter (at most 4) to the
  // devices' copies, so that neither stage's threads wait for a core. On
  // an H200's 16 cores 12 + 4 ran 3.49 G/s against 3.05 for 16 + 4, one
  // run each (reports/device-judge/h200.txt, section 7).
  const bool overlap = built_for != BatchFor::kHostJudge;
  const unsigned threads = ThreadPool::ThreadCount(options.threads);
  const unsigned stage_threads = overlap ? std::clamp(threads / 4, 1u, 4u) : 0u;
  ThreadPool pool(std::max(1u, threads - stage_threads));
  const auto accumulators_of = [&](std::size_t b) {
    return std::span<CellAccumulator>(accumulators.data() + b * cell_count, cell_count);
  };
  // The first backend's run records the encodings' errors (below).
  const auto encodings_of = [&](std::size_t b) {
    return b == 0 ? std::span<CellAccumulator>(storage_accumulators) : std::span<CellAccumulator>();
  };
  // Device counts join the host's accumulators, which then flush as ever.
  const auto flush_devices = [&](bool due_only) -> Status {
    for (std::size_t b = 0; b < backends.size(); ++b) {
      if (device_judges[b] == nullptr) continue;
      if (due_only && accumulators[b * cell_count].pending() < flush_every) continue;
      DB_RETURN_IF_ERROR(device_judges[b]->Flush(accumulators_of(b), encodings_of(b)));
    }
    return Status::Ok();
  };
  std::vector<std::vector<float>> scratch(pool.size());
  std::vector<std::vector<std::uint32_t>> cells_of_slot(slot_count);
  for (std::uint32_t c = 0; c < cell_count; ++c) cells_of_slot[layout.cells[c].depth_slot].push_back(c);
  // Depth slots, those with the most cells first: the threads take them in
  // this order, and the small ones at the end even out the finish.
  std::vector<std::uint32_t> slot_order(slot_count);
  std::iota(slot_order.begin(), slot_order.end(), 0u);
  std::stable_sort(slot_order.begin(), slot_order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return cells_of_slot[a].size() > cells_of_slot[b].size(); });
  // The first backend that renders its own depths (a raster pipeline on
  // a device) produces the texels every backend reconstructs from.
  Backend* renderer = DepthRenderer(options.domain.production, backends);
  std::vector<std::uint32_t> every_cell(cell_count);
  std::iota(every_cell.begin(), every_cell.end(), 0u);

  const std::uint64_t begin = options.shard.Begin(options.samples);
  const std::uint64_t end = options.shard.End(options.samples);
  SweepProgress progress;
  progress.samples_total = end - begin;
  // What follows the build of a batch: every backend runs and is judged,
  // the accumulators flush where due, progress is reported. `stage_pool`
  // serves it: the sweep's pool, or where it overlaps the next build, a
  // pool of its own.
  const auto judge_batch = [&](const Batch& batch, ThreadPool& stage_pool) -> Status {
    const auto judging_started = std::chrono::steady_clock::now();
    const std::uint32_t count = batch.count;
    for (std::size_t b = 0; b < backends.size(); ++b) {
      Backend& backend = *backends[b];
      CellAccumulator* acc = accumulators.data() + b * cell_count;
      // The cells are judged a depth slot at a time: those that read the
      // same encoding share its reference. The slot's storage errors are
      // recorded once per batch, with the first backend's cells, while its
      // reference is in cache.
      auto judge = [&](std::size_t slot, auto positions_of) {
        std::vector<JudgedCell> judged;
        for (std::uint32_t c : cells_of_slot[slot]) judged.push_back({positions_of(c), &acc[c]});
        const auto depth_slot = static_cast<std::uint32_t>(slot);
        JudgeSlot(batch, depth_slot, judged, options.isa);
        if (b == 0) RecordEncodingErrors(batch, depth_slot, storage_accumulators[slot], options.isa);
      };
      const std::size_t per_cell = static_cast<std::size_t>(count) * 3;
      if (device_judges[b] != nullptr) {
        DB_RETURN_IF_ERROR(device_judges[b]
                               ->Judge(batch, accumulators_of(b), encodings_of(b), stage_pool)
                               .WithContext("running and judging on the " + backend.name() + " backend"));
      } else if (backend.concurrent()) {
        FirstError error;
        stage_pool.ParallelFor(slot_count, [&](std::size_t lo, std::size_t hi, unsigned worker) {
          for (std::size_t next = lo; next < hi; ++next) {
            const std::uint32_t slot = slot_order[next];
            auto out = backend.Run(batch, cells_of_slot[slot], scratch[worker]);
            if (!out.ok()) {
              error.Set(out.status());
              return;
            }
            const std::span<const float> positions = *out;
            std::size_t k = 0;
            judge(slot, [&](std::uint32_t) { return positions.subspan(per_cell * k++, per_cell); });
          }
        });
        DB_RETURN_IF_ERROR(error.Get().WithContext("running the " + backend.name() + " backend"));
      } else {
        auto out = backend.Run(batch, every_cell, scratch[0]);
        if (!out.ok()) return out.status().WithContext("running the " + backend.name() + " backend");
        const std::span<const float> positions = *out;
        stage_pool.ParallelFor(slot_count, [&](std::size_t lo, std::size_t hi, unsigned) {
          for (std::size_t next = lo; next < hi; ++next) {
            const std::uint32_t slot = slot_order[next];
            judge(slot, [&](std::uint32_t c) { return positions.subspan(c * per_cell, per_cell); });
          }
        });
      }
    }
    DB_RETURN_IF_ERROR(flush_devices(true));
    run.stages.judging += SecondsSince(judging_started);
    for (std::size_t k = 0; k < accumulators.size(); ++k) {
      if (accumulators[k].pending() >= flush_every) accumulators[k].FlushInto(stats[k]);
    }
    for (std::size_t e = 0; e < slot_count; ++e) {
      if (storage_accumulators[e].pending() >= flush_every) storage_accumulators[e].FlushInto(storage_stats[e]);
    }
    progress.samples_done += count;
    progress.reconstructions_done += static_cast<std::uint64_t>(count) * cell_count * backends.size();
    progress.seconds = SecondsSince(started);
    if (options.progress) options.progress(progress);
    return Status::Ok();
  };

  // Where every backend judges on its device, the host builds the next
  // batch while the devices take the last one: two batches in turn, and the
  // judging stage on a thread of its own with a small pool for its uploads
  // (they are copies into device memory; the build has most of the cores).
  // Otherwise the host's judge needs the pool, and the stages take turns.
  run.stages.setup = SecondsSince(started);
  std::unique_ptr<ThreadPool> stage_pool;
  if (overlap) stage_pool = std::make_unique<ThreadPool>(stage_threads);
  std::array<Batch, 2> batches;  // (the second only where the stages overlap)
  std::future<Status> judging;   // the stage of the batch before, while it runs
  const auto finish_judging = [&]() -> Status {
    if (!judging.valid()) return Status::Ok();
    const auto waiting = std::chrono::steady_clock::now();
    Status judged = judging.get();
    run.stages.build_waited += SecondsSince(waiting);
    return judged;
  };
  std::size_t turn = 0;
  // On SIGINT or SIGTERM the sweep stops between batches and returns what it
  // judged (base/interrupt.h); the caller marks it partial.
  for (std::uint64_t first = begin; first < end && !Interrupted(); first += batch_size, turn = overlap ? turn ^ 1 : 0) {
    const auto count = static_cast<std::uint32_t>(std::min<std::uint64_t>(batch_size, end - first));
    Batch& batch = batches[turn];
    const auto building = std::chrono::steady_clock::now();
    builder.Build(first, count, batch, pool, built_for);
    if (renderer != nullptr) {
      DB_RETURN_IF_ERROR(AdoptRenderedDepths(*renderer, builder, batch, pool));
    }
    run.stages.build += SecondsSince(building);
    if (!overlap) {
      DB_RETURN_IF_ERROR(judge_batch(batch, pool));
      continue;
    }
    DB_RETURN_IF_ERROR(finish_judging());
    judging =
        std::async(std::launch::async, [&judge_batch, &batch, &stage_pool] { return judge_batch(batch, *stage_pool); });
  }
  DB_RETURN_IF_ERROR(finish_judging());

  // The last flush, on the pool: each accumulator is its own. The
  // devices' is judging too: it finishes their last batch.
  const auto last_flush = std::chrono::steady_clock::now();
  DB_RETURN_IF_ERROR(flush_devices(false));
  run.stages.judging += SecondsSince(last_flush);
  pool.ParallelFor(slot_count + accumulators.size(), [&](std::size_t lo, std::size_t hi, unsigned) {
    for (std::size_t k = lo; k < hi; ++k) {
      if (k < slot_count) {
        storage_accumulators[k].FlushInto(storage_stats[k]);
      } else {
        accumulators[k - slot_count].FlushInto(stats[k - slot_count]);
      }
    }
  });
  if (only_distance_band) {
    for (CellStats& s : stats) {
      if (!s.joint.empty()) s.distance[*only_distance_band] = s.DistanceBandOf();
    }
  }
  for (std::size_t b = 0; b < backends.size(); ++b) {
    for (std::size_t c = 0; c < cell_count; ++c) {
      const std::size_t k = b * cell_count + c;
      CopyEncodingMetrics(storage_stats[layout.cells[c].depth_slot], stats[k]);
      results.cells.push_back({layout.cells[c].cell, backends[b]->name(), std::move(stats[k])});
    }
  }
  for (const auto& judge : device_judges) {
    if (judge == nullptr) continue;
    run.stages.device_waited += judge->waited_seconds();
    for (const auto& [name, seconds] : judge->pass_seconds()) run.stages.AddDevicePass(name, seconds);
  }
  run.seconds = SecondsSince(started);
  run.reconstructions = progress.reconstructions_done;
  run.samples_judged = progress.samples_done;
  run.partial = progress.samples_done < progress.samples_total;
  return results;
}

}  // namespace depthbench
