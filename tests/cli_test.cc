// The depthbench program as a user meets it: bad input gets a message that
// says what is wrong and what is allowed, and exit code 2; good input runs.
#include <cctype>
#include <filesystem>

#include <gtest/gtest.h>

#include "bench/base/text_table.h"
#include "bench/results/results.h"
#include "tests/command_runner.h"
#include "tests/sanitized_stage.h"

namespace depthbench {
namespace {

using testing::RunDepthbench;

struct BadInput {
  std::vector<std::string> args;
  std::string message;  // a part of the error message
};

class CliBadInputTest : public ::testing::TestWithParam<BadInput> {};

TEST_P(CliBadInputTest, NamesTheProblemAndExitsWithTwo) {
  const BadInput& bad = GetParam();
  const auto r = RunDepthbench(bad.args);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(bad.message), std::string::npos) << "stderr: " << r.err;
}

INSTANTIATE_TEST_SUITE_P(
    BadInput, CliBadInputTest,
    ::testing::Values(
        BadInput{{"run", "--variant", "frustum"}, "unknown variant 'frustum'; allowed: frustum_ray, volume_ray"},
        BadInput{{"run", "--convention", "backwards"}, "unknown convention 'backwards'; allowed: standard"},
        BadInput{{"run", "--format", "d48"}, "unknown format 'd48'; allowed: d16_unorm (d16)"},
        BadInput{{"run", "--variant", "divide", "--format", "r32f"}, "no cell matches these filters"},
        BadInput{{"run", "--near", "0"}, "--near: 0 is out of range; allowed (0, 1e+06]"},
        BadInput{{"run", "--near", "-1:2"}, "--near: -1:2 is out of range"},
        BadInput{{"run", "--near", "5", "--far", "2"}, "far must be greater than near"},
        BadInput{{"run", "--far", "10", "--ratio", "100"}, "--far and --ratio cannot be used together"},
        BadInput{{"run", "--fov", "180"}, "--fov: 180 is out of range; allowed (0, 180) degrees"},
        BadInput{{"run", "--fov", "10:5"}, "--fov: minimum 10 is above maximum 5"},
        BadInput{{"run", "--aspect", "x"}, "--aspect: 'x' is not a finite number"},
        BadInput{{"run", "--ratio", "1"}, "--ratio: 1 is out of range; allowed (1, 1e+15]"},
        BadInput{{"run", "--ratio", "10:100,never"}, "--ratio: '10:100,never' is not understood"},
        BadInput{{"run", "--camera-distance", "-5"}, "--camera-distance: -5 is out of range"},
        BadInput{{"run", "--resolution", "1920*1080"}, "--resolution: '1920*1080' is not WIDTHxHEIGHT"},
        BadInput{{"run", "--constants", "double"},
                 "--constants: constants model 'double' is not one of exact, float32"},
        BadInput{{"run", "--samples", "1.5"}, "--samples: '1.5' is not a whole number"},
        BadInput{{"run", "--shard", "3/2"}, "--shard: '3/2' is not K/N with 1 <= K <= N"},
        BadInput{{"run", "--split", "colour"}, "--split: 'colour' is not one of ratio, depth, distance"},
        BadInput{{"run", "--backend", "metal"}, "unknown backend 'metal'; available: cpu, vulkan"},
        BadInput{{"run", "--backend", "vulkan", "--device", "no-such-gpu"},
                 "no Vulkan device matches 'no-such-gpu'; available: llvmpipe"},
        BadInput{{"run", "--backend", "vulkan", "--shaders", "/no/such/dir", "--samples", "10"},
                 "shader directory '/no/such/dir' does not exist"},
        BadInput{{"run", "--samples", "10", "--json", "/no/such/dir/out.json"},
                 "cannot write '/no/such/dir/out.json': directory '/no/such/dir' does not exist"},
        BadInput{{"run", "--index", "-3"}, "--index: '-3' is not a sample index"},
        BadInput{{"merge", "/no/such/file.json", "--json", "x.json"},
                 "results file '/no/such/file.json' does not exist"},
        BadInput{{"explode"}, "unknown subcommand 'explode'; available: list, run, merge"},
        // Near misses get the name they were probably meant to be.
        BadInput{{"rnu"}, "did you mean 'run'?"},
        BadInput{{"run", "--sample", "1e5"}, "unknown option '--sample'; did you mean '--samples'?"},
        BadInput{{"choose", "--secne", "x.toml"}, "unknown option '--secne'; did you mean '--scene'?"},
        BadInput{{"run", "--variant", "recipocal"}, "did you mean 'reciprocal'?"},
        BadInput{{"run", "--convention", "revresed"}, "did you mean 'reversed'?"},
        BadInput{{"run", "--domain", "typcial"}, "did you mean 'typical'?"},
        // Numbers read strictly, never wrapped, clamped or defaulted.
        BadInput{{"run", "--threads", "100000"}, "'100000' is not a thread count (0: one per core) from 0 to 1024"},
        BadInput{{"run", "--seed", "-1"}, "'-1' is not a whole number from 0 to 18446744073709551615"},
        BadInput{{"run", "--seed", ""}, "'' is not a whole number from 0 to"},
        BadInput{{"run", "--seed", "18446744073709551616"}, "is not a whole number from 0 to 18446744073709551615"},
        BadInput{{"run", "--samples", "0x10"}, "--samples: '0x10' is not a whole number"},
        // Too few samples to say anything: refused, not an empty table.
        BadInput{{"fit", "--samples", "64", "--backend", "cpu", "--variant", "divide"},
                 "--samples: no cell could be fitted at p99.9 from 64 samples per far/near ratio"},
        BadInput{{"report", "--quick", "--no-history", "--backend", "cpu", "--variant", "divide", "--samples", "1",
                  "--out", "/tmp/depthbench_cli_test_never_written"},
                 "--samples: no cell could be fitted at p99.9 from 1 samples per far/near ratio"},
        // Fields that are valid alone but not together.
        BadInput{{"run", "--depth", "1e9", "--near", "1", "--far", "100"}, "lies beyond every far plane"},
        BadInput{{"run", "--depth", "0.001:0.01", "--near", "1"}, "lies nearer than every near plane"}),
    [](const ::testing::TestParamInfo<BadInput>& info) {
      // A readable test name from the arguments: run_near_0, ...
      std::string name;
      for (const std::string& arg : info.param.args) {
        for (char c : arg) name += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
        name += '_';
      }
      return name + std::to_string(info.index);
    });

TEST(CliTest, HelpTeachesAndExitsWithZero) {
  const auto r = RunDepthbench({"run", "--help"});
  EXPECT_EQ(r.exit_code, 0);
  for (const char* text : {"--samples", "--ratio", "bits lost", "Examples:", "--shard"}) {
    EXPECT_NE(r.out.find(text), std::string::npos) << text;
  }
}

TEST(CliTest, ListNamesVariantsWithSourcesAndDevices) {
  const auto r = RunDepthbench({"list"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  for (const char* text : {"frustum_ray", "Pettineo 2009", "pq", "engine shader notes", "reversed-inf-gl",
                           "x8_d24_unorm", "130 cells", "106 of them perspective", "ortho-reversed-gl",
                           "ortho_lerp", "llvmpipe"}) {
    EXPECT_NE(r.out.find(text), std::string::npos) << text;
  }
}

TEST(CliTest, RunWritesTheTableAndVersionedJson) {
  const std::string dir = testing::MakeTempDir("cli_run");
  const std::string json = dir + "/out.json";
  const auto r = RunDepthbench(
      {"run", "--samples", "2000", "--variant", "pq", "--convention", "reversed", "--json", json, "--split", "ratio"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("pq/reversed/d32_sfloat"), std::string::npos);
  EXPECT_NE(r.out.find("p99.9 bits lost by far/near ratio band"), std::string::npos);
  auto results = ReadResults(json);
  ASSERT_TRUE(results.ok()) << results.status().message();
  EXPECT_EQ(results->cells.size(), 6u);  // 3 formats x 2 backends
  EXPECT_EQ(results->run.samples, 2000u);
  std::filesystem::remove_all(dir);
}

TEST(CliTest, IndexReplaysOneSampleOnBothBackends) {
  const auto r =
      RunDepthbench({"run", "--index", "77", "--variant", "divide", "--convention", "standard", "--format", "d24"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("sample 77 of seed 1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("divide/standard/x8_d24_unorm"), std::string::npos);
  EXPECT_NE(r.out.find("cpu:"), std::string::npos);
  EXPECT_NE(r.out.find("vulkan:"), std::string::npos);
}

// The default run is informative: in the typical domain (camera-relative,
// far/near 1e2 to 1e5) reversed Z with D32F sits near the float32 floor,
// where the wide domain's cameras a million units out put nearly every
// cell at 24 bits; standard Z with D24 shows its far/near dependence, about
// 3.3 bits per decade of far/near, between the ratio bands 1e2 and 1e4.
TEST(CliTest, TheDefaultRunSeparatesTheConventions) {
  const std::string dir = testing::MakeTempDir("cli_default_run");
  const std::string json = dir + "/out.json";
  const auto r = RunDepthbench({"run", "--samples", "60000", "--backend", "cpu", "--variant", "divide", "--convention",
                                "standard,reversed", "--format", "d24,d32f", "--json", json});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto results = ReadResults(json);
  ASSERT_TRUE(results.ok()) << results.status().message();
  const auto p999 = [](const BandStats& b) { return BitsLost(Summarize(b, Metric::kTotal).p999); };
  for (const CellResult& c : results->cells) {
    if (c.cell.convention == Convention::kReversed && c.cell.format == Format::kD32Sfloat) {
      EXPECT_LT(p999(c.stats.All()), 8.0) << c.cell.Name();
    }
    if (c.cell.convention == Convention::kStandard && c.cell.format == Format::kX8D24Unorm) {
      // Two decades at 3.3 bits each; 2 bits of margin for the bins and
      // the ~10000 samples a band holds.
      EXPECT_GT(p999(c.stats.ForRatio(4)) - p999(c.stats.ForRatio(2)), 4.5) << c.cell.Name();
    }
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace depthbench

namespace depthbench {
namespace {

// Every line a subcommand prints fits a terminal of 120 columns: tables
// leave out their secondary columns and wrap their text, and say so.
TEST(CliTest, OutputFitsOneHundredTwentyColumns) {
  DEPTHBENCH_FIGURES_ONLY("each command's own test");
  const std::string dir = testing::MakeTempDir("cli_width");
  const std::string root = DEPTHBENCH_SOURCE_DIR;
  const std::vector<std::vector<std::string>> commands{
      {"run", "--samples", "3000", "--split", "ratio,depth,distance"},
      {"fit", "--samples", "2e4", "--variant", "divide,reciprocal", "--backend", "cpu"},
      {"choose", "--scene", root + "/bench/scenes/indoor_shooter.toml", "--backend", "cpu", "--samples", "2e4"},
      {"gate", "--baseline", root + "/reports/baselines/cpu.json"},
      {"fuzz", "--seconds", "2", "--out", dir + "/fuzz"},
      {"speed", "--quick", "--resolution", "64x64", "--quiet"}};
  for (const auto& args : commands) {
    const auto r = RunDepthbench(args);
    EXPECT_LE(r.exit_code, 1) << args.front() << ": " << r.err;
    std::size_t line_number = 0, start = 0;
    while (start < r.out.size()) {
      std::size_t end = r.out.find('\n', start);
      if (end == std::string::npos) end = r.out.size();
      const std::string line = r.out.substr(start, end - start);
      ++line_number;
      EXPECT_LE(DisplayWidth(line), 120u) << args.front() << ", line " << line_number << ": " << line;
      start = end + 1;
    }
    EXPECT_GT(line_number, 3u) << args.front() << " printed almost nothing";
  }
  // --wide brings the secondary columns back.
  const auto wide = RunDepthbench({"run", "--samples", "3000", "--wide"});
  EXPECT_EQ(wide.out.find("left out to fit"), std::string::npos);
  std::filesystem::remove_all(dir);
}

// Numeric options say so in --help; none is left as CLI11's TEXT.
TEST(CliTest, HelpNamesWhatEachOptionTakes) {
  for (const char* command : {"run", "merge", "speed", "gate", "fit", "choose", "report", "fuzz"}) {
    const auto r = RunDepthbench({command, "--help"});
    EXPECT_EQ(r.exit_code, 0) << command;
    EXPECT_EQ(r.out.find(" TEXT"), std::string::npos) << command << ":\n" << r.out;
  }
  const auto run = RunDepthbench({"run", "--help"});
  EXPECT_NE(run.out.find("--samples N"), std::string::npos) << run.out;
}

}  // namespace
}  // namespace depthbench
