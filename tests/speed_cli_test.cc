// `depthbench speed` as a user runs it: bad input gets a message and exit
// code 2; a small quick run prints its tables, says what lavapipe timings
// are, measures the memory-bound floor, and writes a speed file that reads
// back.
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bench/speed/speed_results.h"
#include "tests/command_runner.h"

namespace depthbench {
namespace {

using testing::RunDepthbench;

struct BadSpeedInput {
  std::vector<std::string> args;
  std::string message;  // a part of the error message
};

class SpeedBadInputTest : public ::testing::TestWithParam<BadSpeedInput> {};

TEST_P(SpeedBadInputTest, NamesTheProblemAndExitsWithTwo) {
  const BadSpeedInput& bad = GetParam();
  std::vector<std::string> args = {"speed"};
  args.insert(args.end(), bad.args.begin(), bad.args.end());
  const auto r = RunDepthbench(args);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(bad.message), std::string::npos) << "stderr: " << r.err;
}

INSTANTIATE_TEST_SUITE_P(
    BadInput, SpeedBadInputTest,
    ::testing::Values(
        BadSpeedInput{{"--variant", "divide", "--format", "r32f"}, "no cell matches these filters"},
        BadSpeedInput{{"--variant", "sideways"}, "unknown variant 'sideways'"},
        BadSpeedInput{{"--taps", "1"}, "--taps: 1 is out of range; allowed 2 to 64"},
        BadSpeedInput{{"--taps", "65"}, "--taps: 65 is out of range"},
        BadSpeedInput{{"--repetitions", "2"}, "--repetitions: 2 is too few; at least 3"},
        BadSpeedInput{{"--warmup", "0"}, "--warmup: at least 1 warm-up pass is needed"},
        BadSpeedInput{{"--resolution", "1920"}, "--resolution: '1920' is not WIDTHxHEIGHT"},
        BadSpeedInput{{"--accuracy-samples", "0"}, "--accuracy-samples: '0' is not a whole number"},
        BadSpeedInput{{"--device", "no-such-gpu"}, "no Vulkan device matches 'no-such-gpu'; available: llvmpipe"},
        BadSpeedInput{{"--shaders", "/no/such/dir"}, "shader directory '/no/such/dir' does not exist"},
        BadSpeedInput{{"--results", "/no/such/results.json"}, "--results: file '/no/such/results.json' does not exist"},
        BadSpeedInput{{"--compare", "/no/such/speed.json"}, "--compare: file '/no/such/speed.json' does not exist"},
        BadSpeedInput{{"--json", "/no/such/dir/speed.json"}, "cannot write '/no/such/dir/speed.json'"}),
    [](const ::testing::TestParamInfo<BadSpeedInput>& info) {
      std::string name = info.param.args[0].substr(2);
      for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
      return name + "_" + std::to_string(info.index);
    });

TEST(SpeedCliTest, QuickRunPrintsTheTradeAndWritesItsFile) {
  const std::string dir = testing::MakeTempDir("speed_cli");
  const std::string json = dir + "/speed.json";
  const std::vector<std::string> args = {"speed",
                                         "--variant",
                                         "divide,pq,inverse_vp",
                                         "--convention",
                                         "reversed",
                                         "--format",
                                         "d32f",
                                         "--resolution",
                                         "64x64",
                                         "--quick",
                                         "--quiet",
                                         "--json",
                                         json};
  const auto r = RunDepthbench(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("is a CPU implementation of Vulkan: its timings are of JIT-compiled CPU code"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("GPU time of a whole frame"), std::string::npos);
  EXPECT_NE(r.out.find("64x64 µs/frame"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("64x64 G recon/s"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Static cost"), std::string::npos);
  EXPECT_NE(r.out.find("CPU backend"), std::string::npos);
  EXPECT_NE(r.out.find("The trade at 64x64"), std::string::npos);

  auto read = ReadSpeedResults(json);
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(read->gpu.size(), 6u);  // 3 cells, 1 resolution, 2 regimes
  EXPECT_EQ(read->static_costs.size(), 3u);
  EXPECT_EQ(read->cpu.size(), 3u);
  ASSERT_EQ(read->trade.size(), 1u);
  ASSERT_EQ(read->trade[0].points.size(), 3u);
  bool any_on_front = false;
  for (const TradePoint& p : read->trade[0].points) any_on_front = any_on_front || p.on_gpu_front;
  EXPECT_TRUE(any_on_front) << "a front is never empty";
  EXPECT_EQ(read->run.accuracy_backend, "vulkan");
  EXPECT_EQ(read->run.device_type, "cpu");
  // The memory-bound floor, measured: a bandwidth, and the floor of the one
  // format at the one resolution, below each memory-bound pass (on
  // lavapipe a pass runs JIT-compiled per-pixel code besides moving its
  // bytes: 8 to 14 times its floor in runs here).
  EXPECT_NE(r.out.find("memory bandwidth: "), std::string::npos) << r.out;
  ASSERT_TRUE(read->bandwidth.has_value());
  EXPECT_GT(read->bandwidth->bytes_per_second(), 0.0);
  ASSERT_EQ(read->floors.size(), 1u);
  for (const GpuTiming& t : read->gpu) {
    if (t.regime != Regime::kMemory) continue;
    ASSERT_TRUE(read->TimesFloor(t).has_value()) << t.cell.Name();
    EXPECT_GT(*read->TimesFloor(t), 1.0) << t.cell.Name();
  }

  // The same run again, compared with the first: it reports how the two
  // rank the variants (exit 1 only if a ranking flipped).
  std::vector<std::string> again = args;
  again.back() = dir + "/speed2.json";
  again.push_back("--compare");
  again.push_back(json);
  const auto second = RunDepthbench(again);
  EXPECT_TRUE(second.exit_code == 0 || second.exit_code == 1) << second.err;
  EXPECT_NE(second.out.find("Repeatability: 6 pairs of variants compared"), std::string::npos) << second.out;
}

// --budget: depth images whose timings would end past it are left out and
// listed; what was measured still makes a table.
TEST(SpeedCliTest, BudgetLeavesOutWhatWouldEndPastIt) {
  const auto r = RunDepthbench({"speed", "--variant", "divide", "--convention", "standard,reversed", "--format", "d32f",
                                "--resolution", "64x64,128x128", "--quick", "--quiet", "--budget", "1e-6"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("over the --budget of 1e-06 s"), std::string::npos) << r.out;
  // The first depth image is always measured: the rate comes from it.
  EXPECT_NE(r.out.find("divide   standard"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("not measured: divide/reversed/d32_sfloat at 64x64"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace depthbench
