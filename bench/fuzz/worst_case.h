// Worst-case search: for one cell, the inputs of a domain that maximise the
// reconstruction's total error, found by an evolutionary local search in
// the sampler's unit coordinates (so it never leaves the domain random
// sampling draws from, and the two maxima compare fairly).
//
// The error surface is rough at the scale of single roundings but smooth
// in the large (it grows with far/near, with depth towards the far plane,
// with the camera's distance from the origin): the search keeps the best
// inputs found, moves their frame and sample units by steps from a quarter
// of the range down to single rounding scales, and keeps drawing fresh
// random points so as not to stall on one ridge.
#pragma once

#include <cstdint>
#include <functional>

#include "bench/backends/backend.h"
#include "bench/fuzz/fuzz_case.h"

namespace depthbench {

struct SearchOptions {
  Cell cell;
  Domain domain;
  std::uint64_t seed = 1;
  double seconds = 1.0;                      // time budget
  std::uint64_t evaluations = 0;             // evaluation budget too, when not 0
  std::uint32_t frames_per_generation = 32;  // x 64 samples
  std::uint32_t elite = 16;                  // best inputs kept
  std::function<void(double fraction, double best_bits)> progress;
};

struct SearchResult {
  double worst = 0.0;  // largest total relative error found (NaN/Inf outputs are not counted)
  FuzzPoint point;     // where
  FuzzCase worst_case;
  std::uint64_t evaluations = 0;
  double seconds = 0.0;
};

Expected<SearchResult> SearchWorstCase(const SearchOptions& options, Backend& backend);

}  // namespace depthbench
