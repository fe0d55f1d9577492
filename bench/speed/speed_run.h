// The measurements of `depthbench speed`, without any formatting: GPU pass
// timings over every selected cell, resolution and regime; the static
// instruction mix of every selected variant; the CPU backend's cost per
// cell; and the trade against accuracy results.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "bench/base/status.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/domain.h"
#include "bench/results/results.h"
#include "bench/speed/cpu_cost.h"
#include "bench/speed/gpu_pass_timer.h"
#include "bench/speed/speed_results.h"

namespace depthbench {

struct SpeedOptions {
  std::vector<Cell> cells;
  // The catalogue of `cells` (it outlives the results); null: the built-in one.
  const Catalogue* catalogue = nullptr;
  std::vector<Resolution> resolutions{{1920, 1080}, {3840, 2160}};
  std::uint32_t alu_taps = 16;  // reconstructions per pixel in the ALU-bound regime
  std::uint32_t warmup = 2;     // warm-up passes per measurement (at least; see gpu_pass_timer.h)
  std::uint32_t repetitions = 10;
  // Bytes of each buffer of the bandwidth probe (GpuPassTimer::
  // MeasureBandwidth), timed with the same warm-up and repetitions.
  std::uint64_t bandwidth_bytes = GpuPassTimer::kBandwidthProbeBytes;
  // A cell whose format the device cannot sample: refused (true), or left
  // out and listed in SpeedResults::skipped (false).
  bool refuse_unsupported = false;
  CpuCostOptions cpu;
  // Called before each measurement: (measurements done, of how many, which).
  std::function<void(std::size_t, std::size_t, const std::string&)> progress;
  // Called once, after the first depth image's measurements: the seconds
  // the GPU timings are expected to take in all, at the rate so far.
  std::function<void(double)> estimate;
  // Seconds the GPU timings may take (0: no limit): no depth image is
  // started whose measurements would, at the rate so far, end past it; the
  // cells left out are listed in SpeedResults::skipped.
  double budget_seconds = 0.0;
};

// Ok, or InvalidArgument naming the violated constraint.
Status ValidateSpeedOptions(const SpeedOptions& options);

// What a timing on this device means, for the output and the JSON.
std::string DeviceNote(const VulkanDeviceProperties& device);
std::string DeviceTypeName(VkPhysicalDeviceType type);

// Every selected cell at every resolution in both regimes, ranked.
Expected<std::vector<GpuTiming>> TimeGpuPasses(GpuPassTimer& timer, const SpeedOptions& options,
                                               std::vector<std::string>& skipped);

// The instruction mix of each variant's reconstruction function, from the
// compiled SPIR-V of its speed pass (shader_dir/speed/<variant>.comp).
Expected<std::vector<StaticCost>> MeasureStaticCosts(const std::filesystem::path& shader_dir,
                                                     std::span<const Cell> cells);

// The device's memory bandwidth (GpuPassTimer::MeasureBandwidth) as the
// results keep it.
Expected<BandwidthProbe> ProbeBandwidth(GpuPassTimer& timer, const SpeedOptions& options);

// The shader stages' rates (GpuPassTimer::MeasureStages) as the results
// keep them.
Expected<StageProbe> ProbeStages(GpuPassTimer& timer, const SpeedOptions& options);

// Everything but the trade, on `timer`'s device; run info filled in; the
// memory-bound floors from the bandwidth probe and the stages' rates, or,
// where a probe could not run, a line in SpeedResults::skipped saying why.
Expected<SpeedResults> RunSpeed(GpuPassTimer& timer, const std::filesystem::path& shader_dir,
                                const SpeedOptions& options);

// Adds the trade at the largest measured resolution, from accuracy results
// (`source` says where they came from).
Status AddTrade(SpeedResults& speed, const Results& accuracy, const std::string& source);

}  // namespace depthbench
