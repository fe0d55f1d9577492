// Fuzz target: the JSON readers of results (run --json), baselines (gate) and
// speed results (speed --json), on the same bytes, through the same parse
// their Read* functions use. Invariants: no crash, hang, sanitizer report or
// escaping exception; a refused document says why; an accepted one is written
// back and read again with as many records (what the bench reads, it can write).
// An accepted baseline also goes to the gate against itself (everything is
// compared) and against copies that lack a cell or a cell's bands (what is
// missing is reported as not compared, never passed over).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "bench/base/json_reader.h"
#include "bench/gate/baseline.h"
#include "bench/gate/gate.h"
#include "bench/results/results.h"
#include "bench/speed/speed_results.h"
#include "fuzz/fuzz_support.h"

namespace {

using depthbench::fuzzing::Accepted;

// The gate compares every cell and band of a run that the baseline holds,
// and names every one that it lacks.
void CheckCoverage(const depthbench::Baseline& run) {
  using namespace depthbench;
  const GateTolerance tolerance;
  const Expected<GateComparison> self = CompareWithBaseline(run, run, tolerance);
  if (!self.ok()) return;  // a baseline may hold what no run can (a plan that does not validate)
  if (!self->Uncovered().empty() || self->compared() != static_cast<int>(run.cells.size())) std::abort();
  if (run.cells.empty()) return;
  Baseline without_cell = run;
  without_cell.cells.erase(without_cell.cells.begin());
  const Expected<GateComparison> lacking_cell = CompareWithBaseline(without_cell, run, tolerance);
  if (!lacking_cell.ok() || lacking_cell->Uncovered().empty()) std::abort();
  Baseline without_bands = run;
  without_bands.cells.begin()->second.clear();
  const Expected<GateComparison> lacking_bands = CompareWithBaseline(without_bands, run, tolerance);
  const bool had_bands = !run.cells.begin()->second.empty();
  if (!lacking_bands.ok() || lacking_bands->Uncovered().empty() != !had_bands) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace depthbench;
  const std::string text(reinterpret_cast<const char*>(data), size);
  const Expected<nlohmann::json> json = JsonReader::Parse(text, "fuzz.json");
  if (!Accepted(json)) return 0;

  const Expected<Results> results = ResultsFromJson(*json, "fuzz.json");
  if (Accepted(results)) {
    const Expected<Results> again = ResultsFromJson(ToJson(*results), "written");
    if (!again.ok() || again->cells.size() != results->cells.size()) std::abort();
  }
  const Expected<Baseline> baseline = BaselineFromJson(*json, "fuzz.json");
  if (Accepted(baseline)) {
    const Expected<Baseline> again = BaselineFromJson(BaselineToJson(*baseline), "written");
    if (!again.ok() || again->cells.size() != baseline->cells.size()) std::abort();
    CheckCoverage(*baseline);
  }
  const Expected<SpeedResults> speed = SpeedResultsFromJson(*json, "fuzz.json");
  if (Accepted(speed)) {
    const Expected<SpeedResults> again = SpeedResultsFromJson(ToJson(*speed), "written");
    if (!again.ok() || again->gpu.size() != speed->gpu.size() || again->cpu.size() != speed->cpu.size()) {
      std::abort();
    }
  }
  return 0;
}
