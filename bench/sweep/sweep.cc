#include "bench/sweep/sweep.h"

#include <array>
#include <chrono>
#include <future>
#include <memory>

#include "bench/base/build_info.h"
#include "bench/base/environment.h"
#include "bench/base/interrupt.h"
#include "bench/base/thread_pool.h"
#include "bench/pipeline/batch.h"
#include "bench/pipeline/captured.h"
#include "bench/pipeline/sampler.h"
#include "bench/sweep/judging_stage.h"
#include "bench/sweep/sweep_plan.h"

namespace depthbench {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

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

RunInfo DescribeRun(const SweepOptions& options, const std::vector<Cell>& cells, std::span<Backend* const> backends) {
  RunInfo run;
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
  for (Backend* backend : backends) {
    BackendRecord& record = run.backends.emplace_back();
    record.name = backend->name();
    record.device = backend->device();
    record.program = backend->program();
  }
  return run;
}

// The loop of a planned sweep: builds each batch and hands it to every
// judging stage, in turn, or where the plan overlaps them, building the
// next batch while the stages take the last one (two batches in turn, the
// stages on a thread of their own with a small pool for their uploads).
class SweepLoop {
 public:
  SweepLoop(const SweepPlan& plan, const SweepOptions& options, const BatchBuilder& builder, Backend* renderer,
            std::span<const std::unique_ptr<JudgingStage>> stages, Tally& encodings, RunInfo& run)
      : plan_(plan),
        options_(options),
        builder_(builder),
        renderer_(renderer),
        stages_(stages),
        encodings_(encodings),
        run_(run),
        pool_(plan.build_threads) {
    if (plan.overlap) stage_pool_ = std::make_unique<ThreadPool>(plan.stage_threads);
    progress_.samples_total = plan.end_sample - plan.first_sample;
    std::size_t cells = 0;
    for (const auto& stage : stages) cells += stage->cells().accumulators().size();
    reconstructions_per_sample_ = cells;
  }

  // Runs every batch (stopping between two on SIGINT or SIGTERM: what was
  // judged stays, base/interrupt.h), then flushes every count into the
  // statistics.
  Expected<SweepProgress> Run(std::chrono::steady_clock::time_point started) {
    started_ = started;
    run_.stages.setup = SecondsSince(started);
    std::size_t turn = 0;
    for (std::uint64_t first = plan_.first_sample; first < plan_.end_sample && !Interrupted();
         first += plan_.batch_size, turn = plan_.overlap ? turn ^ 1 : 0) {
      const auto count =
          static_cast<std::uint32_t>(std::min<std::uint64_t>(plan_.batch_size, plan_.end_sample - first));
      Batch& batch = batches_[turn];
      DeviceJudgeInputs& device = device_inputs_[turn];
      DB_RETURN_IF_ERROR(Build(first, count, batch, device));
      if (!plan_.overlap) {
        DB_RETURN_IF_ERROR(JudgeBatch(batch, device, pool_));
        continue;
      }
      DB_RETURN_IF_ERROR(FinishJudging());
      judging_ =
          std::async(std::launch::async, [this, &batch, &device] { return JudgeBatch(batch, device, *stage_pool_); });
    }
    DB_RETURN_IF_ERROR(FinishJudging());
    DB_RETURN_IF_ERROR(FlushAll());
    return progress_;
  }

 private:
  Status Build(std::uint64_t first, std::uint32_t count, Batch& batch, DeviceJudgeInputs& device) {
    const auto building = std::chrono::steady_clock::now();
    builder_.Build(first, count, batch, pool_, plan_.built_for, &device);
    if (renderer_ != nullptr) DB_RETURN_IF_ERROR(AdoptRenderedDepths(*renderer_, builder_, batch, pool_));
    run_.stages.build += SecondsSince(building);
    return Status::Ok();
  }

  // The encodings' errors are recorded by the first stage.
  std::span<CellAccumulator> EncodingsFor(std::size_t stage) {
    return stage == 0 ? encodings_.accumulators() : std::span<CellAccumulator>();
  }

  // Every stage judges the batch; the counts flush where due; progress is
  // reported. `pool`: the sweep's, or where it overlaps the build, the
  // stages' own.
  Status JudgeBatch(const Batch& batch, const DeviceJudgeInputs& device, ThreadPool& pool) {
    const auto judging_started = std::chrono::steady_clock::now();
    for (std::size_t s = 0; s < stages_.size(); ++s) {
      DB_RETURN_IF_ERROR(stages_[s]->Judge(batch, device, EncodingsFor(s), pool));
    }
    // Counts kept on a device join the stage's accumulators when those
    // are due, and then flush with them.
    for (std::size_t s = 0; s < stages_.size(); ++s) {
      if (stages_[s]->cells().accumulators()[0].pending() >= plan_.flush_every) {
        DB_RETURN_IF_ERROR(stages_[s]->Flush(EncodingsFor(s)));
      }
    }
    run_.stages.judging += SecondsSince(judging_started);
    for (const auto& stage : stages_) stage->cells().FlushDue(plan_.flush_every);
    encodings_.FlushDue(plan_.flush_every);
    progress_.samples_done += batch.count;
    progress_.reconstructions_done += std::uint64_t{batch.count} * reconstructions_per_sample_;
    progress_.seconds = SecondsSince(started_);
    if (options_.progress) options_.progress(progress_);
    return Status::Ok();
  }

  // Waits for the judging of the batch before, where it runs beside the build.
  Status FinishJudging() {
    if (!judging_.valid()) return Status::Ok();
    const auto waiting = std::chrono::steady_clock::now();
    Status judged = judging_.get();
    run_.stages.build_waited += SecondsSince(waiting);
    return judged;
  }

  // The last flush, which counts as judging: the stages' counts kept on
  // devices (which finishes their last batch), then every accumulator's
  // into the statistics.
  Status FlushAll() {
    const auto last_flush = std::chrono::steady_clock::now();
    for (std::size_t s = 0; s < stages_.size(); ++s) DB_RETURN_IF_ERROR(stages_[s]->Flush(EncodingsFor(s)));
    encodings_.FlushAll(pool_);
    for (const auto& stage : stages_) stage->cells().FlushAll(pool_);
    run_.stages.judging += SecondsSince(last_flush);
    return Status::Ok();
  }

  const SweepPlan& plan_;
  const SweepOptions& options_;
  const BatchBuilder& builder_;
  Backend* renderer_;
  std::span<const std::unique_ptr<JudgingStage>> stages_;
  Tally& encodings_;
  RunInfo& run_;
  ThreadPool pool_;
  std::unique_ptr<ThreadPool> stage_pool_;
  std::array<Batch, 2> batches_;  // (the second only where the stages overlap)
  std::future<Status> judging_;   // the stages' work on the batch before, while it runs
  // What a judge on the device reads beside each batch.
  std::array<DeviceJudgeInputs, 2> device_inputs_;
  SweepProgress progress_;
  std::size_t reconstructions_per_sample_ = 0;
  std::chrono::steady_clock::time_point started_;
};

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
  builder.AdoptStoredDepths(batch, rendered->codes, rendered->fetched, rendered->drawn, pool);
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
    if (c.hardware && domain.depth_convention && *domain.depth_convention != c.id) continue;
    // An orthographic domain runs the orthographic conventions' cells, a
    // perspective one the others.
    if (c.orthographic() != domain.orthographic.has_value()) continue;
    out.push_back(cell);
  }
  return out;
}

Expected<Results> RunSweep(const SweepOptions& requested, std::span<Backend* const> backends) {
  DB_RETURN_IF_ERROR(requested.Validate());
  // A captured frame's pixels are the population: all of them, once each.
  SweepOptions options = requested;
  const std::unique_ptr<const SampleSource> source = SourceFor(options.seed, options.domain);
  options.samples = SamplesFor(options.samples, *source);
  if (options.samples == 0) {
    return InvalidArgument(fmt::format("{}: no drawn pixel lies in {}", options.domain.capture->source,
                                       options.domain.Describe()));
  }
  const std::vector<Cell> all = AllCells();
  const std::vector<Cell> cells = CellsForDomain(
      options.cells.empty() ? std::span<const Cell>(all) : std::span<const Cell>(options.cells), options.domain);
  if (cells.empty()) {
    return InvalidArgument(
        "none of the selected cells can run in this domain (finite-far conventions and linear formats need "
        "a finite far plane; infinite-far conventions need --ratio to allow inf; a projection matrix runs its own "
        "convention only; an orthographic domain runs the ortho-* conventions only)");
  }
  const RunLayout layout = MakeRunLayout(cells);
  for (Backend* backend : backends) {
    DB_RETURN_IF_ERROR(backend->Prepare(layout.cells, PassKindOf(options.domain.production))
                           .WithContext("preparing the " + backend->name() + " backend"));
  }

  const auto started = std::chrono::steady_clock::now();
  Results results;
  results.run = DescribeRun(options, cells, backends);
  const bool record_distances = !LoneDistanceBand(options).has_value();
  // The raster form's rendered texels are the stored values every backend
  // reconstructs from: beside other backends the host adopts them and
  // judges them all (a judge on the device renders its own).
  SweepOptions stage_options = options;
  if (PassKindOf(options.domain.production) == PassKind::kRaster && backends.size() > 1) {
    if (options.judge == JudgeSite::kDevice) {
      return InvalidArgument(
          "--judge device: the raster form is judged on its device only where it is the run's one backend; run "
          "the backends one at a time, or judge on the host");
    }
    stage_options.judge = JudgeSite::kHost;
  }
  std::vector<std::unique_ptr<JudgingStage>> stages(backends.size());
  std::vector<StageTraits> traits;
  for (std::size_t b = 0; b < backends.size(); ++b) {
    DB_RETURN_IF_ERROR(
        StoreInto(MakeJudgingStage(stage_options, *backends[b], layout, record_distances), stages[b]));
    traits.push_back(stages[b]->traits());
    if (traits.back().site == JudgeSite::kDevice) results.run.backends[b].judge = JudgedOn::kDevice;
  }
  const BatchBuilder builder(*source, layout.encodings, options.isa);
  SweepPlan plan;
  DB_RETURN_IF_ERROR(StoreInto(PlanSweep(options, traits, builder.DevicesCanDraw()), plan));

  // Storage and production errors belong to an encoding, whatever reads it
  // (one accumulator per depth slot), and are copied into its cells.
  Tally encodings(layout.encodings.size(), /*record_distances=*/true);
  // (A judge on the device renders the texels itself, as part of its run.)
  Backend* renderer =
      plan.built_for == BatchFor::kHostJudge ? DepthRenderer(options.domain.production, backends) : nullptr;
  SweepLoop loop(plan, options, builder, renderer, stages, encodings, results.run);
  SweepProgress progress;
  DB_RETURN_IF_ERROR(StoreInto(loop.Run(started), progress));

  const std::vector<CellStats> encoding_stats = encodings.TakeStats(std::nullopt);
  for (std::size_t b = 0; b < backends.size(); ++b) {
    std::vector<CellStats> stats = stages[b]->cells().TakeStats(plan.only_distance_band);
    for (std::size_t c = 0; c < layout.cells.size(); ++c) {
      CopyEncodingMetrics(encoding_stats[layout.cells[c].depth_slot], stats[c]);
      results.cells.push_back({layout.cells[c].cell, backends[b]->name(), std::move(stats[c])});
    }
    stages[b]->AddTimes(results.run.stages);
    results.run.backends[b].raster_agreement = backends[b]->raster_agreement();
  }
  RunInfo& run = results.run;
  run.seconds = SecondsSince(started);
  run.reconstructions = progress.reconstructions_done;
  run.samples_judged = progress.samples_done;
  run.partial = progress.samples_done < progress.samples_total;
  return results;
}

}  // namespace depthbench
