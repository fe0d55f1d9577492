// SpeedResults: what `depthbench speed` measured on one device, and the
// speed/accuracy trade made from it. Saved as versioned JSON (schema
// "depthbench.speed", version 1) for the report and for `choose`. Results
// are kept per device: every file names the device it was measured on,
// and rankings of different devices are never mixed. The bandwidth probe
// and the memory-bound floors came later: files without them still read
// (no floor is then known).
#pragma once

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/base/json_reader.h"
#include "bench/base/status.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/device_info.h"
#include "bench/pipeline/domain.h"
#include "bench/speed/cpu_cost.h"
#include "bench/speed/instruction_mix.h"
#include "bench/speed/timing_stats.h"

namespace depthbench {

inline constexpr JsonSchema kSpeedSchema{"depthbench.speed", 1, "a speed file of depthbench speed --json"};

// The two regimes of a timed pass.
enum class Regime : std::uint8_t {
  kMemory,  // one reconstruction per pixel: the fetch and the write dominate
  kAlu,     // many reconstructions per pixel (taps), as an SSAO kernel makes
};
const char* RegimeName(Regime regime);
Expected<Regime> ParseRegime(std::string_view name);

// One timed (cell, resolution, regime).
struct GpuTiming {
  Cell cell;
  Resolution resolution{0, 0};
  Regime regime = Regime::kMemory;
  std::uint32_t taps = 1;
  TimingSummary ns_per_pass;           // over the repetitions
  std::vector<double> repetitions_ns;  // each repetition's time per pass
  std::uint32_t passes_per_repetition = 1;
  std::uint32_t warmup_passes = 0;
  std::uint32_t rank = 0;  // among the variants of its group (RankGpuTimings); 0 before ranking
  // The variants of its group whose medians differ from its own by no more
  // than the spread: no ranking between them is claimed.
  std::vector<Variant> indistinguishable_from;

  double pixels() const { return static_cast<double>(resolution.width) * resolution.height; }
  double ns_per_pixel() const { return ns_per_pass.median / pixels(); }
  double spread_ns_per_pixel() const { return ns_per_pass.spread() / pixels(); }
  double ns_per_reconstruction() const { return ns_per_pixel() / taps; }
};

// Timings compete with each other within a group: the same convention,
// format, resolution and regime.
bool SameGroup(const GpuTiming& a, const GpuTiming& b);
// Sets every timing's rank within its group (timing_stats.h RankByTiming)
// and the variants it is indistinguishable from.
void RankGpuTimings(std::vector<GpuTiming>& timings);

// The device's memory bandwidth as the probe measured it
// (GpuPassTimer::MeasureBandwidth): a copy between two device-local
// buffers, timed as the passes are.
struct BandwidthProbe {
  std::string method;                               // what was copied, in words
  std::uint64_t bytes_read = 0, bytes_written = 0;  // per pass
  TimingSummary ns_per_pass;
  std::vector<double> repetitions_ns;
  std::uint32_t passes_per_repetition = 1;
  std::uint32_t warmup_passes = 0;

  // Bytes moved (read and written) per second, at the median.
  double bytes_per_second() const { return static_cast<double>(bytes_read + bytes_written) / ns_per_pass.median * 1e9; }
};

// How fast one shader stage computed the stage probe's arithmetic
// (GpuPassTimer::MeasureStages).
struct StageRate {
  std::string stage;  // "compute", "vertex" or "fragment"
  TimingSummary ns_per_pass;
  std::vector<double> repetitions_ns;
  std::uint32_t passes_per_repetition = 1;
  std::uint32_t warmup_passes = 0;
  std::uint32_t processors_used = 0;  // 0: the device does not name its processors
};

// The same arithmetic timed in each shader stage: whether a pass the
// rasterizer draws (an engine's full-screen reconstruction, the raster
// form) computes as fast as the compute passes timed beside it.
struct StageProbe {
  std::string method;             // what each invocation computes, in words
  std::uint64_t invocations = 0;  // a pass's
  std::uint32_t fma_per_invocation = 0;
  std::uint32_t processors = 0;  // the device's; 0: not named
  std::vector<StageRate> stages;
  std::vector<std::string> left_out;  // a stage not measured, and why

  // Fused multiply-adds a second in `stage`, at its median.
  double fma_per_second(const StageRate& stage) const {
    return static_cast<double>(invocations) * fma_per_invocation / stage.ns_per_pass.median * 1e9;
  }
  // The compute row, or null.
  const StageRate* compute() const;
  // The slowest drawing stage's rate over compute's; nullopt where neither
  // drawing stage was measured.
  std::optional<double> drawn_share() const;
};
// Below this share of compute's rate, a pass drawn by the rasterizer costs
// what the compute passes' timings say no longer: speed and the frame costs
// made from its file say so.
inline constexpr double kSlowDrawnShare = 0.5;

// The memory-bound floor of a full-screen pass over one format at one
// resolution: the bytes it must move, one reconstruction per pixel (the
// texel read, the float written), over the measured bandwidth. No pass can
// be faster without caches holding the image; a pass within
// kBandwidthBoundFactor of it is bound by memory bandwidth.
struct MemoryFloor {
  Format format;
  Resolution resolution{0, 0};
  std::uint32_t bytes_read_per_pixel = 0, bytes_written_per_pixel = 0;
  double ns_per_pass = 0.0;
};
// Within this factor of its floor, a memory-bound pass is said to be
// bandwidth-bound: it moves its bytes at two thirds or more of the rate a
// plain copy reaches on the device.
inline constexpr double kBandwidthBoundFactor = 1.5;

// The floors of every format and resolution of `timings`, from `probe`.
std::vector<MemoryFloor> MemoryFloors(const BandwidthProbe& probe, const std::vector<GpuTiming>& timings);

// The fixed cost of a pass, apart from its per-pixel cost: for each cell
// timed in the memory-bound regime at two or more resolutions, the line
// time = fixed + per_pixel * pixels through its smallest and largest
// resolution; the medians over those cells. What a pass costs whatever its
// size (the dispatch, the barrier after it, the timestamps' share) is the
// intercept; a timer that measured launches rather than kernels would show
// it as most of a pass.
struct PassCostSplit {
  std::size_t cells = 0;  // cells with two resolutions or more
  double fixed_ns = 0.0;
  double ns_per_pixel = 0.0;
  Resolution smallest{0, 0}, largest{0, 0};
};
std::optional<PassCostSplit> SplitPassCost(const std::vector<GpuTiming>& timings);

struct StaticCost {
  Variant variant;
  std::string function;  // the SPIR-V function counted, "<variant>_world_position"
  InstructionMix mix;
};

// One variant at one (convention, format) in the trade.
struct TradePoint {
  Variant variant;
  double gpu_ns_per_reconstruction = 0.0;  // ALU-bound regime at the trade's resolution
  double gpu_spread_ns = 0.0;              // its spread, in the same unit
  double gpu_memory_ns_per_pixel = 0.0;    // memory-bound regime, for reference
  double cpu_ns_per_reconstruction = std::numeric_limits<double>::quiet_NaN();  // NaN: not timed (a shader file)
  double cpu_spread_ns = 0.0;
  double p999_bits_lost = 0.0;  // total error, from the accuracy results
  std::uint64_t nonfinite = 0;  // NaN or Inf outputs in the accuracy results
  bool on_gpu_front = false;
  bool on_cpu_front = false;
  bool has_cpu_cost() const { return !std::isnan(cpu_ns_per_reconstruction); }
};

struct TradeFront {
  Convention convention;
  Format format;
  std::vector<TradePoint> points;
};

struct SpeedRunInfo {
  std::string version;
  std::string commit;
  std::string started_at;
  std::string host;
  DeviceInfo device;                 // the Vulkan device the passes ran on
  std::string device_type;           // "cpu", "discrete gpu", ...
  double timestamp_period_ns = 0.0;  // VkPhysicalDeviceLimits::timestampPeriod
  std::uint32_t timestamp_valid_bits = 0;
  std::string note;  // what the figures mean on this device
  std::uint32_t warmup = 0;
  std::uint32_t repetitions = 0;
  std::uint32_t alu_taps = 0;
  std::vector<Resolution> resolutions;
  Resolution trade_resolution{0, 0};
  std::string accuracy_source;   // the results file, or "internal run of N samples"
  std::string accuracy_backend;  // which backend's errors the trade uses
  std::string accuracy_device;
  std::string cpu_compiler;  // the CPU backend's compiler
  double seconds = 0.0;
};

struct SpeedResults {
  // The catalogue the variants below are of (it outlives the results);
  // null: the built-in one.
  const Catalogue* catalogue = nullptr;
  SpeedRunInfo run;
  std::optional<BandwidthProbe> bandwidth;  // none in files made before the probe, or when it failed
  std::vector<MemoryFloor> floors;          // per format and resolution timed; empty without a probe
  std::optional<StageProbe> stages;         // none in files made before the probe, or when it failed
  std::vector<GpuTiming> gpu;
  std::vector<StaticCost> static_costs;
  std::vector<CpuCost> cpu;
  std::vector<TradeFront> trade;
  std::vector<std::string> skipped;  // cells not timed on this device, with the reason

  const GpuTiming* FindGpu(const Cell& cell, Resolution resolution, Regime regime) const;
  const MemoryFloor* FindFloor(Format format, Resolution resolution) const;
  // A memory-bound timing's median over its floor; nullopt for an ALU-bound
  // timing or where no floor is known.
  std::optional<double> TimesFloor(const GpuTiming& timing) const;
  const CpuCost* FindCpu(const Cell& cell) const;
  // The catalogue the variants are of, and one of them: its name, and what
  // it reads.
  const Catalogue& variant_catalogue() const;
  const VariantInfo& variant_info(Variant v) const;
};

nlohmann::json ToJson(const SpeedResults& results);
// `source` names the input in error messages (a file path). Records of
// cells that do not exist (a variant paired with a format or convention it
// does not read) are refused with the field that holds them. Variant names
// are looked up in `catalogue`, which the results then refer to.
Expected<SpeedResults> SpeedResultsFromJson(const nlohmann::json& json, const std::string& source,
                                            const Catalogue& catalogue = Catalogue::BuiltIn());
Status WriteSpeedResults(const std::filesystem::path& path, const SpeedResults& results);
Expected<SpeedResults> ReadSpeedResults(const std::filesystem::path& path,
                                        const Catalogue& catalogue = Catalogue::BuiltIn());

// The speed files committed with depthbench (reports/speed/*.json), by
// name; "x.repeat.json" repeats "x.json" (a repeatability check) and is
// left out.
Expected<std::vector<std::filesystem::path>> CommittedSpeedFiles();
// Whether a speed file's costs may be used by a command running on
// `devices`: when the user named it (then it is labelled as its device's),
// or when it was measured on one of them.
bool SpeedFileApplies(const SpeedResults& speed, bool named, std::span<const DeviceInfo> devices);

// How two runs on one device rank the variants, pair by pair within each
// group present in both.
struct RankingComparison {
  std::uint32_t pairs = 0;                  // pairs of variants compared
  std::uint32_t agree = 0;                  // the same order in both runs, both distinguishable
  std::uint32_t both_ties = 0;              // indistinguishable in both runs
  std::uint32_t one_sided = 0;              // distinguishable in one run, a tie in the other
  std::vector<std::string> contradictions;  // opposite distinguishable orders, described
};
// InvalidArgument when the runs are of different devices: rankings are
// kept per device.
Expected<RankingComparison> CompareRankings(const SpeedResults& first, const SpeedResults& second);

}  // namespace depthbench
