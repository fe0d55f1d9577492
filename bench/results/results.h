// Results: what a run measured, per cell and backend, with how it was made.
// Saved as versioned JSON (kResultsSchema), written and read from one field
// list per type (results.cc, json_fields.h). The JSON keeps the full
// histograms, so results of shards merge exactly into the results of the
// whole sweep.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/base/json_fields.h"
#include "bench/base/json_reader.h"
#include "bench/base/status.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/device_info.h"
#include "bench/pipeline/domain.h"
#include "bench/pipeline/raster_model.h"
#include "bench/pipeline/stats.h"

namespace depthbench {

// Version 2: the production metric, non-finite outputs by cause, coverage
// bands, the domain's name and production model. Version 3: what defines the
// sweep (the cells run, each backend's shader sources and their hash) and
// whether it was interrupted (run.partial, run.samples_judged). Older files
// lack what merge must compare, so they are refused, not guessed at.
inline constexpr JsonSchema kResultsSchema{"depthbench.results", 3, "a results file of depthbench run --json"};

// Shard K of N (1-based, as "--shard K/N" spells it): samples
// [total * (K-1) / N, total * K / N) of the sweep.
struct Shard {
  std::uint32_t index = 1;
  std::uint32_t count = 1;
  std::uint64_t Begin(std::uint64_t total) const;
  std::uint64_t End(std::uint64_t total) const;
  std::string ToString() const;
  friend bool operator==(const Shard&, const Shard&) = default;
  friend auto operator<=>(const Shard&, const Shard&) = default;
};
Expected<Shard> ParseShard(std::string_view text);

// The shards of a K/N split that `held` lacks, in order ("2/4", "3/4"); empty
// when `held` is complete or mixes splits of different N.
std::vector<Shard> MissingShards(const std::vector<Shard>& held);
// "2/4, 3/4"; past ten shards, the first ten and "and N more".
std::string ShardList(const std::vector<Shard>& shards);

// Where a backend's outputs were judged: read back and judged on the host,
// or judged where they were made (bench/device_judge/).
enum class JudgedOn : std::uint8_t { kHost, kDevice };

struct BackendRecord {
  std::string name;  // "cpu", "vulkan"
  DeviceInfo device;
  ProgramInfo program;  // what its formulas were built from
  // Where its outputs were judged (bench/device_judge/ for the device).
  // Not part of a sweep's identity: both give the same figures, so shards
  // judged either way merge.
  JudgedOn judge = JudgedOn::kHost;
  // For a backend that rasterized its own depths, how they agreed with
  // the host's model of a rasterizer, per encoding the run stored; empty
  // for every other backend and form.
  std::vector<RasterAgreement> raster_agreement;
};

// Where a sweep's wall time went, in seconds (summed over merged shards).
// The build and the judging take turns where the host judges; where every
// backend judges on its device, the host builds the next batch while the
// devices take the last one, and the slower stage sets the pace: the
// other then waits.
struct StageSeconds {
  double setup = 0.0;    // within the clock, before the first batch: the device judges made, their shaders compiled
  double build = 0.0;    // the batches built: samples, frames' constants, stored depths, reference
  double judging = 0.0;  // the backends run and their outputs judged, on the host or on their devices
  double build_waited = 0.0;   // the build waiting for the judging of the batch before
  double device_waited = 0.0;  // the judging waiting for a device to finish its passes (device judge)
  // The devices' own seconds in each pass of the device judge, in the
  // order the passes run (DeviceJudge::pass_seconds, summed over devices);
  // empty where no device judged or none could time its passes.
  std::vector<std::pair<std::string, double>> device_passes;
  // Adds `seconds` to the pass called `name`, a new one going last.
  void AddDevicePass(const std::string& name, double seconds);
  // The host's seconds in each step of the device judges' work on their
  // thread (DeviceJudge::host_seconds, summed over devices), in order:
  // what the device waits for when it idles; empty where no device judged.
  std::vector<std::pair<std::string, double>> judge_host_steps;
  void AddJudgeHostStep(const std::string& name, double seconds);

  bool empty() const { return build == 0.0 && judging == 0.0; }
};

struct RunInfo {
  std::string version;
  std::string commit;
  std::string started_at;
  std::string host;
  std::uint64_t seed = 0;
  std::uint64_t samples = 0;  // of the whole sweep, every shard together
  std::uint32_t samples_per_frame = 0;
  std::vector<Shard> shards;  // the shards these results hold
  std::vector<Cell> cells;    // the cells the sweep ran (the filter, after the domain's)
  Domain domain;
  std::vector<BackendRecord> backends;
  double seconds = 0.0;               // wall time (summed over merged shards)
  std::uint64_t reconstructions = 0;  // cell evaluations judged against the reference
  // An interrupted sweep (SIGINT, SIGTERM) stops between batches: its
  // figures are of the first samples_judged samples of its shards only.
  bool partial = false;
  std::uint64_t samples_judged = 0;  // of the shards held, summed over merged parts
  StageSeconds stages;               // all zero where a file has no stage_seconds
};

struct CellResult {
  Cell cell;
  std::string backend;
  CellStats stats;
};

struct Results {
  RunInfo run;
  std::vector<CellResult> cells;

  const CellResult* Find(const Cell& cell, const std::string& backend) const;
};

nlohmann::json ToJson(const Results& results);
// `source` names the input in error messages (a file path). Cell names are
// looked up in `catalogue`, which the cells read then point to.
Expected<Results> ResultsFromJson(const nlohmann::json& json, const std::string& source,
                                  const Catalogue& catalogue = Catalogue::BuiltIn());
Status WriteResults(const std::filesystem::path& path, const Results& results);
Expected<Results> ReadResults(const std::filesystem::path& path, const Catalogue& catalogue = Catalogue::BuiltIn());

// Adds up the results of shards of one sweep. They must share what defines
// the sweep (version, seed, sample count, plan, domain, cells, backends with
// their devices, shader directories and shader hashes) and hold disjoint
// shards of one K/N split; a refusal names the field and both values.
// `sources` names the parts in messages (file paths; "part K" when absent).
// Partial (interrupted) parts are refused unless `allow_partial`.
Expected<Results> MergeResults(const std::vector<Results>& parts, const std::vector<std::string>& sources = {},
                               bool allow_partial = false);

// What the other saved files share with results (json_fields.h): the
// field lists of a device and a domain, and the names of cells and their
// parts as every file spells them ("divide/reversed/d32_sfloat").
const JsonFields<DeviceInfo>& DeviceFields();
const JsonFields<Domain>& DomainFields();
// Names read in `catalogue`, which outlives the codecs.
JsonNamed<Cell> JsonCellName(const Catalogue& catalogue);
JsonNamed<Variant> JsonVariantName(const Catalogue& catalogue);
JsonNamed<Convention> JsonConventionName();
JsonNamed<Format> JsonFormatName();

nlohmann::json DomainToJson(const Domain& domain);
nlohmann::json DeviceToJson(const DeviceInfo& device);
Expected<DeviceInfo> DeviceFromJson(const JsonReader& json);

}  // namespace depthbench
