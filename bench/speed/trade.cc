#include "bench/speed/trade.h"

#include <cmath>
#include <map>

#include <fmt/format.h>

namespace depthbench {

bool Dominates(const FrontCandidate& a, const FrontCandidate& b) {
  const double spread = std::max(a.spread, b.spread);
  const bool cheaper = b.cost - a.cost > spread;
  const bool costlier = a.cost - b.cost > spread;
  const bool more_accurate = b.bits_lost - a.bits_lost >= kResolvedBits;
  const bool less_accurate = a.bits_lost - b.bits_lost >= kResolvedBits;
  return !costlier && !less_accurate && (cheaper || more_accurate);
}

std::vector<bool> ParetoFront(std::span<const FrontCandidate> candidates) {
  std::vector<bool> front(candidates.size(), true);
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    for (std::size_t j = 0; j < candidates.size(); ++j) {
      if (i != j && Dominates(candidates[j], candidates[i])) {
        front[i] = false;
        break;
      }
    }
  }
  return front;
}

CellAccuracy AccuracyOf(const CellStats& stats) {
  const BandStats all = stats.All();
  CellAccuracy accuracy;
  accuracy.nonfinite = all.nan + all.inf;
  const std::uint64_t judged = all.judged();
  if (judged > 0 && static_cast<double>(accuracy.nonfinite) > kNonfiniteShareAtP999 * static_cast<double>(judged)) {
    accuracy.p999_bits_lost = accuracy.p999_bits_low = accuracy.p999_bits_high = kAllBitsLost;
  } else {
    const Summary summary = Summarize(all, Metric::kTotal);
    accuracy.p999_bits_lost = BitsLost(summary.p999);
    accuracy.p999_bits_low = BitsLost(summary.p999_interval.low);
    accuracy.p999_bits_high = BitsLost(summary.p999_interval.high);
  }
  return accuracy;
}

Expected<std::string> TradeBackend(const Results& accuracy) {
  // The plain backends only: a probed Vulkan backend measures what the
  // device's arithmetic would give under other rules, not what it gives.
  const std::string vulkan = BackendKindName(BackendKind::kVulkan), cpu = BackendKindName(BackendKind::kCpu);
  bool has_cpu = false;
  for (const CellResult& cell : accuracy.cells) {
    if (cell.backend == vulkan) return vulkan;
    has_cpu = has_cpu || cell.backend == cpu;
  }
  if (has_cpu) return cpu;
  return NotFound("the accuracy results hold no cell of the vulkan or cpu backend");
}

std::vector<TradeFront> BuildTrade(const SpeedResults& speed, const Results& accuracy, const std::string& backend,
                                   Resolution resolution, std::vector<std::string>& left_out) {
  std::map<std::pair<Convention, Format>, TradeFront> fronts;
  for (const GpuTiming& alu : speed.gpu) {
    if (alu.regime != Regime::kAlu || alu.resolution != resolution) continue;
    const Cell& cell = alu.cell;
    const CellResult* errors = accuracy.Find(cell, backend);
    const CpuCost* cpu = speed.FindCpu(cell);
    if (errors == nullptr) {
      left_out.push_back(fmt::format("{}: no accuracy result of the {} backend in the trade", cell.Name(), backend));
      continue;
    }
    TradePoint point;
    point.variant = cell.variant;
    point.gpu_ns_per_reconstruction = alu.ns_per_reconstruction();
    point.gpu_spread_ns = alu.spread_ns_per_pixel() / alu.taps;
    if (const GpuTiming* memory = speed.FindGpu(cell, resolution, Regime::kMemory)) {
      point.gpu_memory_ns_per_pixel = memory->ns_per_pixel();
    }
    // A variant from a shader file has no CPU cost: it is on the GPU side
    // of the trade alone.
    if (cpu != nullptr) {
      point.cpu_ns_per_reconstruction = cpu->ns_per_reconstruction.median;
      point.cpu_spread_ns = cpu->ns_per_reconstruction.spread();
    }
    const CellAccuracy cell_accuracy = AccuracyOf(errors->stats);
    point.p999_bits_lost = cell_accuracy.p999_bits_lost;
    point.nonfinite = cell_accuracy.nonfinite;
    TradeFront& front = fronts[{cell.convention, cell.format}];
    front.convention = cell.convention;
    front.format = cell.format;
    front.points.push_back(point);
  }
  std::vector<TradeFront> out;
  for (auto& [key, front] : fronts) {
    std::vector<FrontCandidate> gpu, cpu;
    std::vector<std::size_t> with_cpu;  // the points that have a CPU cost
    for (std::size_t i = 0; i < front.points.size(); ++i) {
      const TradePoint& p = front.points[i];
      gpu.push_back({p.gpu_ns_per_reconstruction, p.gpu_spread_ns, p.p999_bits_lost});
      if (!p.has_cpu_cost()) continue;
      cpu.push_back({p.cpu_ns_per_reconstruction, p.cpu_spread_ns, p.p999_bits_lost});
      with_cpu.push_back(i);
    }
    const std::vector<bool> on_gpu = ParetoFront(gpu), on_cpu = ParetoFront(cpu);
    for (std::size_t i = 0; i < front.points.size(); ++i) front.points[i].on_gpu_front = on_gpu[i];
    for (std::size_t k = 0; k < with_cpu.size(); ++k) front.points[with_cpu[k]].on_cpu_front = on_cpu[k];
    out.push_back(std::move(front));
  }
  return out;
}

}  // namespace depthbench
