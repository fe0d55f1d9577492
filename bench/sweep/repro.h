// Repro: one sample, replayed exactly. Everything about it (the frame, the
// pixel, the depth, what each encoding stored, the reference, and each
// backend's output and errors) for the cells asked about. The gate and the
// fuzzer print the command that reproduces a finding with it
// (depthbench run --seed S --index I --variant ... --convention ... --format ...).
#pragma once

#include <cstdint>
#include <ostream>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/backends/backend.h"
#include "bench/base/status.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/domain.h"
#include "bench/pipeline/sampler.h"

namespace depthbench {

struct ReproCellOutput {
  std::string backend;
  float position[3] = {0, 0, 0};
  bool nan = false, inf = false;
  double total = 0, arith = 0, absolute = 0;  // relative, relative, world units
};

struct ReproCell {
  Cell cell;
  std::uint32_t code = 0;
  float fetched = 0.0f;
  double true_depth = 0, denoted_depth = 0, storage = 0, production = 0;  // relative errors
  bool stored_holdable = true;  // a non-finite output of a value that denotes no holdable point is expected
  std::string status;           // "judged", "degenerate", "outside"
  std::vector<ReproCellOutput> outputs;
};

struct Repro {
  std::string origin;  // "sample 12 of seed 1", "the case of findings/x.json"
  std::uint64_t seed = 0;
  std::uint64_t index = 0;
  Domain domain;
  std::string frame;   // the frame's parameters, in words
  std::string sample;  // pixel and depth pick, in words
  std::vector<ReproCell> cells;
};

Expected<Repro> Reproduce(std::uint64_t seed, std::uint64_t index, const Domain& domain, std::span<const Cell> cells,
                          std::span<Backend* const> backends);
// The same for sample `index` of any source (a reproducer file's case).
Expected<Repro> ReproduceFrom(const SampleSource& source, std::uint64_t index, std::span<const Cell> cells,
                              std::span<Backend* const> backends);
void PrintRepro(const Repro& repro, std::ostream& out);
nlohmann::json ReproToJson(const Repro& repro);

// The command line that replays a sample of a run.
std::string ReproCommand(std::uint64_t seed, std::uint64_t index, const Domain& domain, const Cell& cell,
                         const std::string& backend);

}  // namespace depthbench
