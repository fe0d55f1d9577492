// Baseline: the headline figures of every cell and band of a gate sweep, as
// committed under reports/baselines/ (one file per backend), with how they
// were made. Schema "depthbench.baseline", version 1, written and read from
// one field list per type (baseline.cc, json_fields.h).
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/base/json_reader.h"
#include "bench/base/status.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/device_info.h"
#include "bench/pipeline/domain.h"
#include "bench/results/results.h"

namespace depthbench {

inline constexpr JsonSchema kBaselineSchema{"depthbench.baseline", 1, "a gate baseline (reports/baselines/)"};

// What a gate compares in one band of one cell: bits lost of the total and
// of the arithmetic error, and the NaN/Inf counts.
struct BandFigures {
  double total_p999 = 0, total_max = 0;
  double arith_p999 = 0, arith_max = 0;
  // Half the width, in bits, of the total p99.9's 95% sampling interval
  // (the larger side): how far the figure could move with other samples.
  double p999_interval_bits = 0;
  std::uint64_t judged = 0, nan = 0, inf = 0;
  std::uint64_t worst_index = 0;            // the sample with the largest total error
  // The sample with the largest error of the shader's part: where an edit
  // of the shader shows even when storage dominates the total (UINT64_MAX
  // when there is none). Unknown in baselines made before it was kept,
  // which are written back without it.
  std::optional<std::uint64_t> arith_worst_index;
  std::uint64_t first_nonfinite_index = 0;  // UINT64_MAX when there is none
  friend bool operator==(const BandFigures&, const BandFigures&) = default;
};

// Band keys: "all" (the natural distribution), "ratio 1e3", "depth 1e2", "distance <1",
// "coverage stored 1" (the samples drawn on purpose, bands.h).
using CellFigures = std::map<std::string, BandFigures>;

// How the figures were made; a gate refuses to compare across any of this.
struct SamplePlan {
  std::uint64_t seed = 0;
  std::uint64_t samples = 0;
  std::uint32_t samples_per_frame = 0;
  Domain domain;
  friend bool operator==(const SamplePlan&, const SamplePlan&) = default;
};

struct Baseline {
  std::string backend;  // "cpu", "vulkan"
  DeviceInfo device;
  std::string version;  // depthbench's
  std::string commit;
  std::string made_at;
  SamplePlan plan;
  std::map<std::string, CellFigures> cells;  // by Cell::Name()
};

// The figures of one backend's cells in a run.
Baseline BaselineFromResults(const Results& results, const std::string& backend);

// The plan as JSON, as the baseline spells it (a key of the report's history).
nlohmann::json SamplePlanToJson(const SamplePlan& plan);

nlohmann::json BaselineToJson(const Baseline& baseline);
// Cell names are checked against `catalogue`.
Expected<Baseline> BaselineFromJson(const nlohmann::json& json, const std::string& source,
                                    const Catalogue& catalogue = Catalogue::BuiltIn());
Status WriteBaseline(const std::filesystem::path& path, const Baseline& baseline);
Expected<Baseline> ReadBaseline(const std::filesystem::path& path, const Catalogue& catalogue = Catalogue::BuiltIn());

}  // namespace depthbench
