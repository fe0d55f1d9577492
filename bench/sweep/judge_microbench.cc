// Google Benchmark of the host judge (bench/pipeline/judge.h): JudgeSlot
// and RecordEncodingErrors over one batch of the sweep's host size, every
// cell of a domain, on one thread, the CPU backend's outputs computed
// once beforehand. items_per_second is cell-samples judged per second
// (the CPU sweep's end-to-end rate is bounded by it, shared with the
// backend and the batch build). The argument picks the domain: 0 typical,
// 1 wide.
//
//   build/bench/depthbench_judge_microbench --benchmark_repetitions=5
#include <cstdint>
#include <vector>

#include <benchmark/benchmark.h>

#include "bench/backends/cpu/cpu_backend.h"
#include "bench/base/thread_pool.h"
#include "bench/pipeline/batch.h"
#include "bench/pipeline/domain.h"
#include "bench/pipeline/judge.h"
#include "bench/pipeline/sampler.h"
#include "bench/pipeline/stats.h"
#include "bench/sweep/sweep.h"

namespace depthbench {
namespace {

void BM_JudgeBatch(benchmark::State& state) {
  const Domain domain = state.range(0) == 0 ? TypicalDomain() : WideDomain();
  const RunLayout layout = MakeRunLayout(CellsForDomain(AllCells(), domain));
  const Sampler sampler(1, domain);
  const BatchBuilder builder(sampler, layout.encodings);
  ThreadPool pool(1);
  Batch batch;
  builder.Build(0, kHostBatch, batch, pool, BatchFor::kHostJudge);

  std::unique_ptr<Backend> cpu = MakeCpuBackend();
  if (!cpu->Prepare(layout.cells).ok()) {
    state.SkipWithError("the CPU backend refused the domain's cells");
    return;
  }
  // Every cell's outputs, grouped by the depth slot it reads.
  std::vector<std::vector<std::uint32_t>> cells_of_slot(layout.encodings.size());
  for (std::uint32_t c = 0; c < layout.cells.size(); ++c) cells_of_slot[layout.cells[c].depth_slot].push_back(c);
  std::vector<std::vector<float>> outputs(layout.encodings.size());
  for (std::size_t slot = 0; slot < cells_of_slot.size(); ++slot) {
    std::vector<float> scratch;
    auto out = cpu->Run(batch, cells_of_slot[slot], scratch);
    if (!out.ok()) {
      state.SkipWithError(std::string(out.status().message()).c_str());
      return;
    }
    outputs[slot].assign(out->begin(), out->end());
  }
  std::vector<CellAccumulator> cells(layout.cells.size());
  std::vector<CellAccumulator> encodings(layout.encodings.size());
  const std::size_t per_cell = std::size_t{batch.count} * 3;
  for (auto _ : state) {
    for (std::size_t slot = 0; slot < cells_of_slot.size(); ++slot) {
      std::vector<JudgedCell> judged;
      for (std::size_t k = 0; k < cells_of_slot[slot].size(); ++k) {
        judged.push_back(
            {std::span<const float>(outputs[slot]).subspan(per_cell * k, per_cell), &cells[cells_of_slot[slot][k]]});
      }
      JudgeSlot(batch, static_cast<std::uint32_t>(slot), judged);
      RecordEncodingErrors(batch, static_cast<std::uint32_t>(slot), encodings[slot]);
    }
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * batch.count *
                          static_cast<std::int64_t>(layout.cells.size()));
}

BENCHMARK(BM_JudgeBatch)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace depthbench

BENCHMARK_MAIN();
