// The sweep's error paths, driven by a backend told to fail: every fault
// comes back as the sweep's error, naming the backend and the step, with no
// crash, hang or result made up.
#include <gtest/gtest.h>

#include "bench/backends/cpu/cpu_backend.h"
#include "bench/sweep/sweep.h"
#include "tests/stub_backend.h"

namespace depthbench {
namespace {

using Fault = StubBackend::Fault;

SweepOptions SmallSweep() {
  SweepOptions options;
  options.seed = 3;
  options.samples = 20000;
  options.batch_size = 1000;  // twenty batches, so that a fault can strike mid-run
  options.threads = 2;
  return options;
}

Expected<Results> RunWith(StubBackend& stub, SweepOptions options = SmallSweep()) {
  auto cpu = MakeCpuBackend();
  Backend* backends[] = {cpu.get(), &stub};
  return RunSweep(options, backends);
}

void ExpectError(const Expected<Results>& results, StatusCode code, const std::vector<std::string>& parts) {
  ASSERT_FALSE(results.ok());
  EXPECT_EQ(results.status().code(), code) << results.status().message();
  for (const std::string& part : parts) {
    EXPECT_NE(results.status().message().find(part), std::string::npos)
        << "'" << part << "' not in: " << results.status().message();
  }
}

// Without a fault the stub is the CPU backend under another name.
TEST(SweepErrorTest, TheStubWithoutAFaultMeasuresWhatTheCpuMeasures) {
  for (bool concurrent : {true, false}) {
    StubBackend stub({.concurrent = concurrent});
    auto results = RunWith(stub);
    ASSERT_TRUE(results.ok()) << results.status().message();
    const std::size_t cells = results->run.cells.size();
    ASSERT_EQ(results->cells.size(), 2 * cells);
    for (std::size_t c = 0; c < cells; ++c) {
      EXPECT_EQ(results->cells[cells + c].backend, "stub");
      EXPECT_TRUE(results->cells[c].stats == results->cells[cells + c].stats) << results->cells[c].cell.Name();
    }
    EXPECT_GT(stub.runs(), 0u);
  }
}

TEST(SweepErrorTest, AFailedPrepareStopsTheSweepBeforeAnyRun) {
  StubBackend stub({.fault = Fault::kPrepare});
  ExpectError(RunWith(stub), StatusCode::kUnavailable,
              {"preparing the stub backend", "the stub was told to fail in Prepare"});
  EXPECT_EQ(stub.runs(), 0u);
}

// A Run that fails, at the first call or mid-run, from the threads that
// judge by depth slot or from the one call that runs every cell.
TEST(SweepErrorTest, AFailedRunIsTheSweepsError) {
  for (bool concurrent : {true, false}) {
    for (std::uint64_t at : {0u, 7u}) {
      StubBackend stub({.fault = Fault::kRun, .fail_at_run = at, .concurrent = concurrent});
      ExpectError(RunWith(stub), StatusCode::kInternal, {"running the stub backend", "told to fail in Run"});
      EXPECT_GT(stub.runs(), at);
    }
  }
}

TEST(SweepErrorTest, TooFewPositionsReadBackAreRefusedNotJudged) {
  for (bool concurrent : {true, false}) {
    StubBackend stub({.fault = Fault::kReadBack, .fail_at_run = 3, .concurrent = concurrent});
    ExpectError(RunWith(stub), StatusCode::kInternal,
                {"running the stub backend", "the stub backend returned", "needed"});
  }
}

TEST(SweepErrorTest, AFailedRenderingOfDepthsIsTheSweepsError) {
  StubBackend stub({.fault = Fault::kRenderDepths});
  SweepOptions options = SmallSweep();
  options.domain.production = ProductionModel::kRaster;
  ExpectError(RunWith(stub, options), StatusCode::kInternal,
              {"rendering depths on the stub backend", "told to fail in RenderDepths"});
  EXPECT_EQ(stub.runs(), 0u);  // the depths come before any backend runs
}

// Asked to judge on its device, a backend that has no device judge fails
// the sweep, saying why; asked for auto, it is judged on the host.
TEST(SweepErrorTest, AJudgeOnADeviceTheBackendLacksIsRefused) {
  StubBackend stub({});
  Backend* backends[] = {&stub};
  SweepOptions options = SmallSweep();
  options.judge = JudgeSite::kDevice;
  ExpectError(RunSweep(options, backends), StatusCode::kUnavailable, {"judging on the stub backend's device"});
  EXPECT_EQ(stub.runs(), 0u);
  options.judge = JudgeSite::kAuto;
  auto results = RunSweep(options, backends);
  ASSERT_TRUE(results.ok()) << results.status().message();
  EXPECT_EQ(results->run.backends[0].judge, JudgedOn::kHost);
}

TEST(SweepErrorTest, InvalidOptionsFailBeforeAnyBackendIsPrepared) {
  StubBackend stub({.fault = Fault::kPrepare});
  SweepOptions options = SmallSweep();
  options.flush_every = 0;
  ExpectError(RunWith(stub, options), StatusCode::kInvalidArgument,
              {"Violated constraint: SweepOptions::flush_every in [1, 2^31]"});
}

}  // namespace
}  // namespace depthbench
