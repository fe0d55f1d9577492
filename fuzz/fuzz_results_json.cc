// Fuzz target: the JSON readers of results (run --json), baselines (gate) and
// speed results (speed --json), on the same bytes, through the same parse
// their Read* functions use. Invariants: no crash, hang, sanitizer report or
// escaping exception; a refused document says why; an accepted one, written,
// read back and written again, gives the same text (what the bench reads, it
// writes back in full). That round trip cannot see a reader that forgets a
// member, which is then missing from both writes alike: replaying documents
// the bench wrote (fuzz/written/, with DEPTHBENCH_FUZZ_WRITTEN=1), each must
// also be read by one of the readers and written back exactly as it was.
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
using depthbench::fuzzing::CheckRoundTrip;

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

// Whether the inputs are documents the bench wrote (see the top).
bool InputsAreWritten() {
  static const bool written = std::getenv("DEPTHBENCH_FUZZ_WRITTEN") != nullptr;
  return written;
}

// A document the bench wrote comes back whole from what was read of it.
template <class T>
void CheckWhole(const nlohmann::json& input, const T& value, nlohmann::json (*write)(const T&)) {
  if (InputsAreWritten() && write(value).dump() != input.dump()) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace depthbench;
  const std::string text(reinterpret_cast<const char*>(data), size);
  const Expected<nlohmann::json> json = JsonReader::Parse(text, "fuzz.json");
  if (!Accepted(json)) {
    if (InputsAreWritten()) std::abort();
    return 0;
  }

  const Expected<Results> results = ResultsFromJson(*json, "fuzz.json");
  if (Accepted(results)) {
    CheckRoundTrip<Results>(*results, ToJson, ResultsFromJson);
    CheckWhole<Results>(*json, *results, ToJson);
  }
  const Expected<Baseline> baseline = BaselineFromJson(*json, "fuzz.json");
  if (Accepted(baseline)) {
    CheckRoundTrip<Baseline>(*baseline, BaselineToJson, BaselineFromJson);
    CheckWhole<Baseline>(*json, *baseline, BaselineToJson);
    CheckCoverage(*baseline);
  }
  const Expected<SpeedResults> speed = SpeedResultsFromJson(*json, "fuzz.json");
  if (Accepted(speed)) {
    CheckRoundTrip<SpeedResults>(*speed, ToJson, SpeedResultsFromJson);
    CheckWhole<SpeedResults>(*json, *speed, ToJson);
  }
  if (InputsAreWritten() && !results.ok() && !baseline.ok() && !speed.ok()) std::abort();
  return 0;
}
