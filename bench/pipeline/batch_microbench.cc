// Google Benchmark of the host's share of a sweep: BatchBuilder::Build over
// batches of the typical domain with every cell of the catalogue (40 depth
// slots; the default run's 106 cells have 28), for the host's judge
// (texels and reference included), for a judge on the device (what the
// host still does then: bench/device_judge/), for one that draws the
// samples too (the frames alone), and for the raster form judged on its
// device. items_per_second is samples built per second; times the cells it
// bounds the reconstructions per second a sweep can verify on any device.
// The argument is the number of threads.
//
//   build/bench/depthbench_batch_microbench --benchmark_repetitions=3
#include <cstdint>

#include <benchmark/benchmark.h>

#include "bench/base/thread_pool.h"
#include "bench/pipeline/batch.h"
#include "bench/pipeline/domain.h"
#include "bench/pipeline/sampler.h"

namespace depthbench {
namespace {

constexpr std::uint32_t kBatch = 131072;  // as in reports/device-judge/h200.txt, sections 7 to 9

void BM_BuildBatch(benchmark::State& state, BatchFor judge, ProductionModel production) {
  Domain domain = TypicalDomain();
  domain.production = production;
  const RunLayout layout = MakeRunLayout(AllCells());
  const Sampler sampler(1, domain);
  const BatchBuilder builder(sampler, layout.encodings);
  ThreadPool pool(static_cast<unsigned>(state.range(0)));
  Batch batch;
  DeviceJudgeInputs device;  // (as a sweep builds for a judge on the device)
  std::uint64_t first = 0;
  for (auto _ : state) {
    builder.Build(first, kBatch, batch, pool, judge, judge == BatchFor::kHostJudge ? nullptr : &device);
    benchmark::DoNotOptimize(batch.depths.data());
    first += kBatch;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * kBatch);
  state.counters["depth_slots"] = static_cast<double>(layout.encodings.size());
}

// Each at 1, 2, 4, 8 and 16 threads.
void Threads(benchmark::internal::Benchmark* b) {
  b->RangeMultiplier(2)->Range(1, 16)->UseRealTime()->Unit(benchmark::kMillisecond);
}
BENCHMARK_CAPTURE(BM_BuildBatch, for_host_judge, BatchFor::kHostJudge, ProductionModel::kFloat32)->Apply(Threads);
BENCHMARK_CAPTURE(BM_BuildBatch, for_device_judge, BatchFor::kDeviceJudge, ProductionModel::kFloat32)->Apply(Threads);
BENCHMARK_CAPTURE(BM_BuildBatch, for_device_draws, BatchFor::kDeviceDraws, ProductionModel::kFloat32)->Apply(Threads);
// The raster form judged on its device: the host still makes each sample's
// geometry and its model of every depth slot's texel.
BENCHMARK_CAPTURE(BM_BuildBatch, raster_for_device_judge, BatchFor::kDeviceJudge, ProductionModel::kRaster)
    ->Apply(Threads);

}  // namespace
}  // namespace depthbench

BENCHMARK_MAIN();
