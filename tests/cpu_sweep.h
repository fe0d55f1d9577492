// A sweep of named cells on the CPU backend, for tests that check what a
// domain does to a few cells' figures.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bench/backends/cpu/cpu_backend.h"
#include "bench/sweep/sweep.h"

namespace depthbench::testing_support {

// The results of `cells` ("variant/convention/format", short names
// allowed) over `samples` of `domain`; a failed sweep fails the test and
// gives no cells.
inline Results CpuSweep(const Domain& domain, const std::vector<std::string>& cells, std::uint64_t seed,
                        std::uint64_t samples = 100000) {
  SweepOptions options;
  options.seed = seed;
  options.samples = samples;
  options.domain = domain;
  for (const std::string& name : cells) options.cells.push_back(*ParseCell(name));
  auto cpu = MakeCpuBackend();
  Backend* backends[] = {cpu.get()};
  auto run = RunSweep(options, backends);
  EXPECT_TRUE(run.ok()) << run.status().message();
  return run.ok() ? *std::move(run) : Results{};
}

}  // namespace depthbench::testing_support
