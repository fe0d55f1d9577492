#include "bench/speed/speed_run.h"

#include <algorithm>
#include <chrono>

#include <fmt/format.h>

#include "bench/backends/cpu/cpu_backend.h"
#include "bench/backends/vulkan/variant_program.h"
#include "bench/base/build_info.h"
#include "bench/base/environment.h"
#include "bench/base/interrupt.h"
#include "bench/base/thread_pool.h"
#include "bench/speed/depth_image.h"
#include "bench/speed/trade.h"

namespace depthbench {

Status ValidateSpeedOptions(const SpeedOptions& o) {
  if (o.cells.empty()) return ViolatedConstraint("SpeedOptions::cells is not empty");
  if (o.resolutions.empty()) return ViolatedConstraint("SpeedOptions::resolutions is not empty");
  if (o.alu_taps < 2 || o.alu_taps > GpuPassTimer::kMaxTaps) {
    return ViolatedConstraint(
        fmt::format("2 <= SpeedOptions::alu_taps <= {} (it is {}; one tap "
                    "is the memory-bound regime)",
                    GpuPassTimer::kMaxTaps, o.alu_taps));
  }
  if (o.warmup < 1) return ViolatedConstraint("SpeedOptions::warmup >= 1");
  // Quartiles of fewer than three values are the values themselves.
  if (o.repetitions < 3) {
    return ViolatedConstraint(
        fmt::format("SpeedOptions::repetitions >= 3 (it is {}); a spread "
                    "needs at least three",
                    o.repetitions));
  }
  if (o.cpu.repetitions < 3) return ViolatedConstraint("CpuCostOptions::repetitions >= 3");
  for (const Cell& cell : o.cells) {
    if (!Reads(cell.variant_info(), cell.convention, cell.format)) {
      return InvalidArgument(fmt::format("{} does not read {} under the {} convention: no such pass to time",
                                         cell.variant_info().name, Info(cell.format).name, Info(cell.convention).name));
    }
  }
  return Status::Ok();
}

std::string DeviceNote(const VulkanDeviceProperties& device) {
  if (device.type == VK_PHYSICAL_DEVICE_TYPE_CPU) {
    return fmt::format(
        "'{}' is a CPU implementation of Vulkan: its timings are of JIT-compiled CPU code on this machine's cores, "
        "not of a GPU, and its ranking need not hold on a real GPU (reports/speed/ holds a real GPU's figures)",
        device.name);
  }
  return fmt::format("GPU time from Vulkan timestamp queries on '{}' (timestampPeriod {} ns)", device.name,
                     device.limits.timestampPeriod);
}

Expected<std::vector<GpuTiming>> TimeGpuPasses(GpuPassTimer& timer, const SpeedOptions& options,
                                               std::vector<std::string>& skipped) {
  DB_RETURN_IF_ERROR(ValidateSpeedOptions(options));
  // Formats the device cannot sample are refused or left out first.
  std::vector<Cell> cells;
  for (const Cell& cell : options.cells) {
    Status supported = timer.CheckFormat(cell.format);
    if (supported.ok()) {
      cells.push_back(cell);
    } else if (options.refuse_unsupported) {
      return supported;
    } else {
      skipped.push_back(fmt::format("{}: {}", cell.Name(), supported.message()));
    }
  }
  const RunLayout layout = MakeRunLayout(cells);
  const std::size_t total = cells.size() * options.resolutions.size() * 2;
  std::size_t done = 0;
  ThreadPool pool;
  std::vector<GpuTiming> timings;
  const auto started = std::chrono::steady_clock::now();
  const auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  };
  std::size_t over_budget = 0;
  for (const Resolution& resolution : options.resolutions) {
    for (const Encoding& encoding : layout.encodings) {
      // The variants reading this image compete: they are timed together.
      std::vector<Cell> group;
      std::vector<VariantInfo> variants;
      for (const CellPlan& plan : layout.cells) {
        if (plan.cell.encoding() != encoding) continue;
        group.push_back(plan.cell);
        variants.push_back(plan.cell.variant_info());
      }
      const double per_measurement = done > 0 ? elapsed() / static_cast<double>(done) : 0.0;
      // The first depth image is always measured: the rate comes from it.
      const bool past_budget =
          options.budget_seconds > 0.0 && done > 0 &&
          (over_budget > 0 ||
           elapsed() + per_measurement * 2.0 * static_cast<double>(group.size()) > options.budget_seconds);
      if (past_budget) {
        over_budget += 2 * group.size();
        for (const Cell& cell : group) {
          skipped.push_back(fmt::format("{} at {}: over the --budget of {:g} s", cell.Name(),
                                        ResolutionName(resolution), options.budget_seconds));
        }
        continue;
      }
      DB_ASSIGN_OR_RETURN(const DepthImage image, MakeDepthImage(encoding, resolution, pool));
      DB_RETURN_IF_ERROR(timer.LoadImage(image));
      for (const Regime regime : {Regime::kMemory, Regime::kAlu}) {
        // A measurement takes up to a few seconds: a signal stops the run
        // between two of them.
        if (Interrupted()) return InterruptedError("no speed results written");
        const std::uint32_t taps = regime == Regime::kMemory ? 1 : options.alu_taps;
        if (options.progress) {
          options.progress(done, total,
                           fmt::format("{} {} {} {}", Info(encoding.convention).name, Info(encoding.format).name,
                                       ResolutionName(resolution), RegimeName(regime)));
        }
        DB_ASSIGN_OR_RETURN(const std::vector<PassTiming> passes,
                            timer.TimePasses(variants, taps, options.warmup, options.repetitions));
        for (std::size_t k = 0; k < group.size(); ++k) {
          GpuTiming timing;
          timing.cell = group[k];
          timing.resolution = resolution;
          timing.regime = regime;
          timing.taps = taps;
          DB_ASSIGN_OR_RETURN(timing.ns_per_pass, SummarizeTimings(passes[k].ns_per_pass));
          timing.repetitions_ns = passes[k].ns_per_pass;
          timing.passes_per_repetition = passes[k].passes_per_repetition;
          timing.warmup_passes = passes[k].warmup_passes;
          timings.push_back(std::move(timing));
          ++done;
        }
      }
      if (options.estimate && done == 2 * group.size()) {
        options.estimate(elapsed() / static_cast<double>(done) * static_cast<double>(total));
      }
    }
  }
  RankGpuTimings(timings);
  return timings;
}

Expected<std::vector<StaticCost>> MeasureStaticCosts(const std::filesystem::path& shader_dir,
                                                     std::span<const Cell> cells) {
  // The cells' variants, in catalog order.
  std::vector<VariantInfo> variants;
  for (const Cell& cell : cells) {
    const bool seen =
        std::any_of(variants.begin(), variants.end(), [&](const VariantInfo& v) { return v.id == cell.variant; });
    if (!seen) variants.push_back(cell.variant_info());
  }
  std::sort(variants.begin(), variants.end(), [](const VariantInfo& a, const VariantInfo& b) { return a.id < b.id; });
  std::vector<StaticCost> costs;
  for (const VariantInfo& variant : variants) {
    DB_ASSIGN_OR_RETURN(const std::vector<std::uint32_t> spirv,
                        CompileVariant(variant, VariantPass::kSpeed, shader_dir));
    const std::string function = VariantFunctionName(variant);
    Expected<InstructionMix> mix = CountInstructionMix(spirv, function);
    if (!mix.ok()) return mix.status().WithContext(VariantProgramName(variant, VariantPass::kSpeed, shader_dir));
    costs.push_back({variant.id, function, *mix});
  }
  return costs;
}

Expected<BandwidthProbe> ProbeBandwidth(GpuPassTimer& timer, const SpeedOptions& options) {
  DB_ASSIGN_OR_RETURN(const BandwidthTiming measured,
                      timer.MeasureBandwidth(options.bandwidth_bytes, options.warmup, options.repetitions));
  BandwidthProbe probe;
  probe.method = fmt::format(
      "a copy of {} MiB between two device-local storage buffers, 16 bytes per invocation "
      "(shaders/speed/bandwidth.comp), timed as the passes are",
      measured.bytes_read >> 20);
  probe.bytes_read = measured.bytes_read;
  probe.bytes_written = measured.bytes_written;
  DB_ASSIGN_OR_RETURN(probe.ns_per_pass, SummarizeTimings(measured.timing.ns_per_pass));
  probe.repetitions_ns = measured.timing.ns_per_pass;
  probe.passes_per_repetition = measured.timing.passes_per_repetition;
  probe.warmup_passes = measured.timing.warmup_passes;
  return probe;
}

namespace {

// The stage probe (GpuPassTimer::MeasureStages): a pixel an invocation,
// of the largest frame timed up to 1920x1080, each 1024 multiply-adds.
// On an H100 that ran its compute passes at 28% of the chip's peak rate of
// multiply-adds and its drawn stages at 34% of their four processors'
// (what else an invocation does, its counts, weighs on both): close
// enough for their ratio to follow the processors' count. More arithmetic
// would lengthen lavapipe's probe, some 0.3 s a pass already.
constexpr Resolution kMostStageProbe{1920, 1080};
constexpr std::uint32_t kStageProbeIterations = 256;

// The one of most pixels (the first of those).
Resolution LargestResolution(std::span<const Resolution> resolutions) {
  return *std::max_element(resolutions.begin(), resolutions.end(), [](const Resolution& a, const Resolution& b) {
    return std::uint64_t{a.width} * a.height < std::uint64_t{b.width} * b.height;
  });
}

}  // namespace

Expected<StageProbe> ProbeStages(GpuPassTimer& timer, const SpeedOptions& options) {
  Resolution size = LargestResolution(options.resolutions);
  if (std::uint64_t{size.width} * size.height > std::uint64_t{kMostStageProbe.width} * kMostStageProbe.height) {
    size = kMostStageProbe;
  }
  DB_ASSIGN_OR_RETURN(StageTimings measured,
                      timer.MeasureStages(size, kStageProbeIterations, options.warmup, options.repetitions));
  StageProbe probe;
  probe.method = fmt::format(
      "{}x{} invocations, each {} fused multiply-adds in 4 independent chains (shaders/speed/stage_probe.glsl): "
      "a compute dispatch, the vertex stage of as many points (rasterizer discard), the fragment stage of a "
      "full-screen triangle; timed as the passes are",
      measured.size.width, measured.size.height, measured.fma_per_invocation);
  probe.invocations = std::uint64_t{measured.size.width} * measured.size.height;
  probe.fma_per_invocation = measured.fma_per_invocation;
  probe.processors = measured.processors;
  probe.left_out = std::move(measured.left_out);
  for (StageTiming& stage : measured.stages) {
    if (stage.invocations != probe.invocations) {
      return Internal(fmt::format("the stage probe's {} stage ran {} invocations of {}", stage.stage, stage.invocations,
                                  probe.invocations));
    }
    StageRate rate;
    rate.stage = std::move(stage.stage);
    DB_ASSIGN_OR_RETURN(rate.ns_per_pass, SummarizeTimings(stage.timing.ns_per_pass));
    rate.repetitions_ns = std::move(stage.timing.ns_per_pass);
    rate.passes_per_repetition = stage.timing.passes_per_repetition;
    rate.warmup_passes = stage.timing.warmup_passes;
    rate.processors_used = stage.processors_used;
    probe.stages.push_back(std::move(rate));
  }
  return probe;
}

Expected<SpeedResults> RunSpeed(GpuPassTimer& timer, const std::filesystem::path& shader_dir,
                                const SpeedOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  SpeedResults results;
  results.catalogue = options.catalogue;
  SpeedRunInfo& run = results.run;
  run.version = BuildVersion();
  run.commit = BuildCommit();
  run.started_at = CurrentTimeUtc();
  run.host = HostName();
  const VulkanDeviceProperties& device = timer.device();
  run.device = DeviceInfoOf(device);
  run.device_type = DeviceTypeName(device.type);
  run.timestamp_period_ns = device.limits.timestampPeriod;
  run.timestamp_valid_bits = device.queue_timestamp_valid_bits;
  run.note = DeviceNote(device);
  run.warmup = options.warmup;
  run.repetitions = options.repetitions;
  run.alu_taps = options.alu_taps;
  run.resolutions = options.resolutions;
  run.trade_resolution = LargestResolution(options.resolutions);
  run.cpu_compiler = MakeCpuBackend()->device().compiler;

  DB_ASSIGN_OR_RETURN(results.static_costs, MeasureStaticCosts(shader_dir, options.cells));
  DB_ASSIGN_OR_RETURN(results.gpu, TimeGpuPasses(timer, options, results.skipped));
  if (!results.gpu.empty()) {
    if (Interrupted()) return InterruptedError("no speed results written");
    if (options.progress) options.progress(1, 1, "memory bandwidth");
    Expected<BandwidthProbe> probe = ProbeBandwidth(timer, options);
    if (probe.ok()) {
      results.bandwidth = std::move(probe).value();
      results.floors = MemoryFloors(*results.bandwidth, results.gpu);
    } else if (probe.status().code() == StatusCode::kInterrupted) {
      return probe.status();
    } else {
      // The timings stand without it; only the floors are missing.
      results.skipped.push_back("memory-bound floors: the bandwidth probe failed: " + probe.status().message());
    }
    if (Interrupted()) return InterruptedError("no speed results written");
    if (options.progress) options.progress(1, 1, "shader stages");
    Expected<StageProbe> stages = ProbeStages(timer, options);
    if (stages.ok()) {
      results.stages = std::move(stages).value();
    } else if (stages.status().code() == StatusCode::kInterrupted) {
      return stages.status();
    } else {
      results.skipped.push_back("shader stages: the stage probe failed: " + stages.status().message());
    }
  }
  if (options.progress) options.progress(1, 1, "CPU backend");
  // The CPU backend runs the built-in formulas alone.
  std::vector<Cell> cpu_cells;
  std::vector<Variant> not_timed;
  for (const Cell& cell : options.cells) {
    if (cell.variant_info().user == nullptr) {
      cpu_cells.push_back(cell);
    } else if (std::find(not_timed.begin(), not_timed.end(), cell.variant) == not_timed.end()) {
      not_timed.push_back(cell.variant);
      results.skipped.push_back(
          fmt::format("cpu: {} not timed: a shader file runs on Vulkan only", cell.variant_info().name));
    }
  }
  if (!cpu_cells.empty()) {
    DB_ASSIGN_OR_RETURN(results.cpu, MeasureCpuCosts(cpu_cells, options.cpu));
  }
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return results;
}

Status AddTrade(SpeedResults& speed, const Results& accuracy, const std::string& source) {
  DB_ASSIGN_OR_RETURN(const std::string backend, TradeBackend(accuracy));
  speed.run.accuracy_source = source;
  speed.run.accuracy_backend = backend;
  for (const BackendRecord& record : accuracy.run.backends) {
    if (record.name == backend) speed.run.accuracy_device = record.device.name;
  }
  std::vector<std::string> left_out;
  speed.trade = BuildTrade(speed, accuracy, backend, speed.run.trade_resolution, left_out);
  for (std::string& line : left_out) speed.skipped.push_back(std::move(line));
  return Status::Ok();
}

}  // namespace depthbench
