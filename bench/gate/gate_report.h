// Formats gate comparisons: the verdict and details for people, JUnit XML
// for CI systems, JSON for tools. Formatting only; the comparing is gate.h's.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/base/json_reader.h"
#include "bench/base/text_table.h"
#include "bench/gate/gate.h"

namespace depthbench {

inline constexpr JsonSchema kGateSchema{"depthbench.gate", 1, "a gate verdict of depthbench gate --json"};

struct GateRun {
  // The catalogue the cells' names are of (it outlives the run); null: the
  // built-in one.
  const Catalogue* catalogue = nullptr;
  GateComparison comparison;
  Baseline baseline;          // what the run was compared with
  Baseline current;           // what the run measured
  std::string shader_dir;     // "" when the built-in shaders ran
  std::string baseline_path;  // the file, for the --update command
};

void PrintGateVerdict(const std::vector<GateRun>& runs, const GateTolerance& tolerance, std::ostream& out);
std::string GateJUnit(const std::vector<GateRun>& runs);
// A short Markdown summary for a CI job's page: the verdict, then each
// worse cell by the band that changed most with the command that replays
// it (at most 20 rows), then the tolerance.
std::string GateSummaryMarkdown(const std::vector<GateRun>& runs, const GateTolerance& tolerance);
// The worse cells as a table (the first `max_rows`): each by the band that
// changed most, what changed, the sample replayed (where the change shows:
// the shader part's worst sample when that part got worse) with its band
// figure before and after, and the command that replays it. What gate
// prints with --table-format csv, markdown or json.
TextTable GateCellsTable(const std::vector<GateRun>& runs, std::size_t max_rows);
nlohmann::json GateJson(const std::vector<GateRun>& runs, const GateTolerance& tolerance);

}  // namespace depthbench
