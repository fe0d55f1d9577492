// Google Benchmark micro-benchmarks of each variant's CPU path: the CPU
// backend running one cell over a batch of the speed scene's samples
// (cpu_cost.h), on one thread. items_per_second is reconstructions per
// second; the ns_per_reconstruction counter is its inverse.
//
//   build/bench/speed/depthbench_cpu_microbench --benchmark_repetitions=5
#include <memory>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "bench/backends/cpu/cpu_backend.h"
#include "bench/pipeline/cells.h"
#include "bench/speed/cpu_cost.h"

namespace depthbench {
namespace {

constexpr std::uint32_t kSamples = 4096;

// The cell each variant is benchmarked at: reversed Z in D32F for the
// hardware-depth variants (what engines choose today), the variant's only
// format otherwise.
Cell BenchmarkCell(Variant variant) {
  const std::vector<Cell> cells = AllCells();
  for (const Cell& cell : cells) {
    if (cell.variant == variant && cell.convention == Convention::kReversed && cell.format == Format::kD32Sfloat) {
      return cell;
    }
  }
  for (const Cell& cell : cells) {
    if (cell.variant == variant && cell.format != Format::kR16Sfloat && cell.format != Format::kR16Unorm) return cell;
  }
  return cells.front();
}

void BM_CpuBackendCell(benchmark::State& state, Cell cell) {
  const Cell cells[] = {cell};
  const CpuCostInput input = MakeCpuCostInput(cells, kSamples);
  std::unique_ptr<Backend> backend = MakeCpuBackend();
  if (Status prepared = backend->Prepare(input.layout.cells); !prepared.ok()) {
    state.SkipWithError(prepared.message().c_str());
    return;
  }
  std::vector<float> scratch;
  const std::uint32_t which[] = {0};
  for (auto _ : state) {
    Expected<std::span<const float>> out = backend->Run(input.batch, which, scratch);
    if (!out.ok()) {
      state.SkipWithError(out.status().message().c_str());
      return;
    }
    benchmark::DoNotOptimize(out->data());
    benchmark::ClobberMemory();
  }
  const double reconstructions = static_cast<double>(state.iterations()) * input.batch.count;
  state.SetItemsProcessed(static_cast<std::int64_t>(reconstructions));
  state.counters["ns_per_reconstruction"] =
      benchmark::Counter(reconstructions, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// Explicit registration, one benchmark per variant (a static library would
// drop self-registering objects, and the catalog is the list).
void RegisterAll() {
  for (const VariantInfo& variant : AllVariants()) {
    const Cell cell = BenchmarkCell(variant.id);
    benchmark::RegisterBenchmark(("cpu/" + cell.Name()).c_str(), BM_CpuBackendCell, cell)
        ->Unit(benchmark::kMicrosecond);
  }
}

}  // namespace
}  // namespace depthbench

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  depthbench::RegisterAll();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
