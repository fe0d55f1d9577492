// Choose: the cheapest (variant, convention, format) that meets a scene's
// requirement, with the evidence. Every candidate the scene's engine can
// use is measured inside the scene's ranges (and, for a requirement at a
// given depth, at that depth), modelled over eye depth so that the error at
// the scene's far end is predicted, and costed; the ranking puts the
// cheapest candidate that meets the requirement first.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/base/json_reader.h"
#include "bench/choose/scene.h"
#include "bench/fit/error_model.h"

namespace depthbench {

inline constexpr JsonSchema kChooseSchema{"depthbench.choose", 1, "a choice of depthbench choose --json"};

class Backend;  // bench/backends/backend.h

// The cost of a candidate, in one unit for the whole ranking.
struct CandidateCost {
  double value = 0.0;
  std::string unit;    // "ns per reconstruction (llvmpipe ...)", "SPIR-V arithmetic lanes"
  std::string source;  // where it came from
};

// Costs per cell; `nullopt` when none is known for a cell.
using CostLookup = std::function<std::optional<CandidateCost>(const Cell&)>;
// The static cost: arithmetic lanes of the variant's compiled shader.
Expected<CostLookup> StaticCostLookup(const std::string& shader_dir);
// Measured costs from a `depthbench speed --json` file (GPU time per
// reconstruction, ALU-bound regime), falling back to `fallback`.
Expected<CostLookup> SpeedCostLookup(const std::string& speed_file, CostLookup fallback);

struct CandidateVerdict {
  Cell cell;
  // In the requirement's own unit (world units, relative error or bits).
  double measured_p999 = 0.0, measured_max = 0.0;
  double measured = 0.0;   // at the requirement's level
  double predicted = 0.0;  // the model's value at the scene's far end, same unit and level
  std::string model;       // the error model used for the prediction
  std::uint64_t nonfinite = 0;
  // The cause with the largest p99.9 at the requirement's depth:
  // kProduction, kStorage or kArith (the shader's part).
  Metric dominant = Metric::kArith;
  bool meets = false;
  bool over_budget = false;
  std::optional<CandidateCost> cost;
  std::string reason;  // one sentence
};

struct ChooseOptions {
  std::uint64_t samples = 100000;
  std::uint64_t seed = 11;
};

struct ChooseResult {
  std::string scene;
  std::string requirement;
  std::string backend, device;
  std::vector<CandidateVerdict> ranked;  // best first
  std::vector<std::string> suggestions;  // when nothing meets the requirement
  double seconds = 0.0;
};

Expected<ChooseResult> Choose(const Scene& scene, Backend& backend, const CostLookup& costs,
                              const ChooseOptions& options);

void PrintChoice(const ChooseResult& result, std::ostream& out);
nlohmann::json ChoiceToJson(const ChooseResult& result);

}  // namespace depthbench
