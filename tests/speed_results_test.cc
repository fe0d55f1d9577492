// The speed results file: it reads back what was written, refuses records of
// cells that do not exist and files of another schema, ranks within groups,
// and compares the rankings of two runs of one device only.
#include <filesystem>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "bench/speed/speed_results.h"
#include "bench/speed/speed_table.h"

namespace depthbench {
namespace {

TimingSummary Summary(double q1, double median, double q3) {
  TimingSummary s;
  s.count = 5;
  s.min = q1 - 1;
  s.q1 = q1;
  s.median = median;
  s.q3 = q3;
  s.max = q3 + 1;
  return s;
}

GpuTiming Timing(Variant variant, double median, Regime regime = Regime::kAlu) {
  GpuTiming t;
  t.cell = {variant, Convention::kReversed, Format::kD32Sfloat};
  t.resolution = {1920, 1080};
  t.regime = regime;
  t.taps = regime == Regime::kAlu ? 16 : 1;
  t.ns_per_pass = Summary(median - 1, median, median + 1);
  t.repetitions_ns = {median - 2, median - 1, median, median + 1, median + 2};
  t.passes_per_repetition = 3;
  t.warmup_passes = 7;
  return t;
}

SpeedResults Example() {
  SpeedResults r;
  r.run.version = "0.1.0";
  r.run.commit = "abc";
  r.run.started_at = "2026-01-01T00:00:00Z";
  r.run.host = "test";
  r.run.device = {"llvmpipe (LLVM 15.0.6, 256 bits)", "llvmpipe Mesa 22.3.6", "Vulkan 1.3.230", DeviceKind::kCpu, "glslang 12"};
  r.run.device_type = "cpu";
  r.run.timestamp_period_ns = 1.0;
  r.run.timestamp_valid_bits = 64;
  r.run.note = "a CPU implementation";
  r.run.warmup = 2;
  r.run.repetitions = 5;
  r.run.alu_taps = 16;
  r.run.resolutions = {{1920, 1080}};
  r.run.trade_resolution = {1920, 1080};
  r.run.accuracy_source = "results.json";
  r.run.accuracy_backend = "vulkan";
  r.run.accuracy_device = "llvmpipe";
  r.run.cpu_compiler = "g++ 12.2.0";
  r.run.seconds = 3.5;
  r.gpu = {Timing(Variant::kDivide, 100), Timing(Variant::kPq, 50), Timing(Variant::kDivide, 10, Regime::kMemory)};
  RankGpuTimings(r.gpu);
  InstructionMix mix;
  mix.fdiv = {5, 7};
  mix.matrix_vector = {1, 16};
  mix.extended_by_name["InverseSqrt"] = {1, 1};
  mix.extended = {1, 1};
  mix.total_instructions = 40;
  r.static_costs = {{Variant::kDivide, "divide_world_position", mix}};
  CpuCost cpu;
  cpu.cell = {Variant::kDivide, Convention::kReversed, Format::kD32Sfloat};
  cpu.ns_per_reconstruction = Summary(0.9, 1.0, 1.1);
  cpu.runs_per_repetition = 100;
  cpu.samples_per_run = 4096;
  r.cpu = {cpu};
  TradePoint point;
  point.variant = Variant::kDivide;
  point.gpu_ns_per_reconstruction = 100.0 / (1920.0 * 1080.0 * 16.0);
  point.p999_bits_lost = 3.5;
  point.on_gpu_front = true;
  r.trade = {{Convention::kReversed, Format::kD32Sfloat, {point}}};
  r.skipped = {"nothing"};
  BandwidthProbe probe;
  probe.method = "a copy";
  probe.bytes_read = probe.bytes_written = 1000;
  probe.ns_per_pass = Summary(1.5, 2, 2.5);  // 2000 bytes in 2 ns: 1000 GB/s
  probe.repetitions_ns = {0.5, 1.5, 2, 2.5, 3.5};
  probe.passes_per_repetition = 4;
  probe.warmup_passes = 9;
  r.bandwidth = probe;
  r.floors = MemoryFloors(probe, r.gpu);
  StageProbe stages;
  stages.method = "multiply-adds";
  stages.invocations = 1000;
  stages.fma_per_invocation = 1000;
  stages.processors = 132;
  stages.stages = {{"compute", Summary(9, 10, 11), {9, 10, 11}, 4, 9, 132},
                   {"fragment", Summary(300, 320, 340), {300, 320, 340}, 1, 2, 4}};
  stages.left_out = {"vertex: no stores"};
  r.stages = stages;
  return r;
}

TEST(SpeedResultsTest, ReadsBackWhatItWrote) {
  const SpeedResults written = Example();
  const nlohmann::json json = ToJson(written);
  auto read = SpeedResultsFromJson(json, "example.json");
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(ToJson(*read), json);
  EXPECT_EQ(read->gpu.size(), 3u);
  EXPECT_EQ(read->static_costs[0].mix, written.static_costs[0].mix);
  EXPECT_EQ(json["schema"], "depthbench.speed");
  EXPECT_EQ(json["schema_version"], 1);
}

// The floor: (texel bytes + 4 written) per pixel at the probe's rate, per
// format and resolution; a memory-bound timing within 1.5 times it is
// bandwidth-bound.
TEST(SpeedResultsTest, FloorsAreBytesPerPixelOverTheMeasuredBandwidth) {
  SpeedResults r = Example();
  ASSERT_TRUE(r.bandwidth.has_value());
  EXPECT_DOUBLE_EQ(r.bandwidth->bytes_per_second(), 1e12);
  ASSERT_EQ(r.floors.size(), 1u);  // one format, one resolution
  const MemoryFloor* floor = r.FindFloor(Format::kD32Sfloat, {1920, 1080});
  ASSERT_NE(floor, nullptr);
  EXPECT_EQ(floor->bytes_read_per_pixel, 4u);
  EXPECT_EQ(floor->bytes_written_per_pixel, 4u);
  EXPECT_DOUBLE_EQ(floor->ns_per_pass, 1920.0 * 1080.0 * 8.0 / 1000.0);  // 1000 bytes per ns
  EXPECT_FALSE(r.TimesFloor(r.gpu[0]).has_value()) << "an ALU-bound timing has no floor";
  // The memory-bound divide takes 10 ns against a floor of 16589 ns:
  // below it, which only a cache could do; and at 1.5 times it, bound.
  ASSERT_TRUE(r.TimesFloor(r.gpu[2]).has_value());
  EXPECT_DOUBLE_EQ(*r.TimesFloor(r.gpu[2]), 10.0 / floor->ns_per_pass);
  r.gpu[2].ns_per_pass = Summary(1.5 * floor->ns_per_pass - 1, 1.5 * floor->ns_per_pass, 1.5 * floor->ns_per_pass + 1);
  const nlohmann::json json = ToJson(r);
  EXPECT_EQ(json["gpu"][2]["bandwidth_bound"], true);
  EXPECT_EQ(json["memory_floor"][0]["format"], "d32_sfloat");
  EXPECT_EQ(json["bandwidth"]["bytes_per_second"], 1e12);
  r.gpu[2].ns_per_pass = Summary(1.6 * floor->ns_per_pass - 1, 1.6 * floor->ns_per_pass, 1.6 * floor->ns_per_pass + 1);
  EXPECT_EQ(ToJson(r)["gpu"][2]["bandwidth_bound"], false);
  EXPECT_FALSE(ToJson(r)["gpu"][0].contains("bandwidth_bound"));
}

// Speed files made before the bandwidth probe still read, without floors;
// every committed one among them.
TEST(SpeedResultsTest, ReadsFilesWithoutABandwidthProbe) {
  nlohmann::json json = ToJson(Example());
  json.erase("bandwidth");
  json.erase("memory_floor");
  json.erase("bandwidth_bound_factor");
  auto read = SpeedResultsFromJson(json, "old.json");
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_FALSE(read->bandwidth.has_value());
  EXPECT_TRUE(read->floors.empty());
  EXPECT_FALSE(ToJson(*read).contains("memory_floor"));
  const std::filesystem::path committed = std::filesystem::path(DEPTHBENCH_SOURCE_DIR) / "reports" / "speed";
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(committed)) {
    if (entry.path().extension() != ".json") continue;
    ++files;
    auto file = ReadSpeedResults(entry.path());
    EXPECT_TRUE(file.ok()) << entry.path() << ": " << file.status().message();
  }
  EXPECT_GE(files, 4);
}

// The stage probe: each stage's rate from its median (1e6 multiply-adds in
// 10 ns: 1e14 a second), printed with its share of compute's and the
// processors it ran on, and the warning where a drawing stage computes at
// under half compute's rate; a file without the compute row, or with a
// stage that does not exist, is refused at the field.
TEST(SpeedResultsTest, StageProbeGivesEachStagesShareOfCompute) {
  SpeedResults r = Example();
  ASSERT_TRUE(r.stages.has_value());
  EXPECT_DOUBLE_EQ(r.stages->fma_per_second(*r.stages->compute()), 1e14);
  std::ostringstream out;
  PrintSpeedHeader(r, out);
  EXPECT_NE(out.str().find("compute  100000 G multiply-adds/s, on 132 of 132 processors"), std::string::npos)
      << out.str();
  EXPECT_NE(out.str().find("fragment 3125 G multiply-adds/s, 3.1% of compute's, on 4 of 132 processors"),
            std::string::npos)
      << out.str();
  EXPECT_NE(out.str().find("not measured: vertex: no stores"), std::string::npos);
  EXPECT_NE(out.str().find("computes at 3.1% of their rate"), std::string::npos);

  nlohmann::json json = ToJson(r);
  json["stage_probe"]["stages"].erase(0);
  auto no_compute = SpeedResultsFromJson(json, "stages.json");
  ASSERT_FALSE(no_compute.ok());
  EXPECT_NE(no_compute.status().message().find("stage_probe.stages"), std::string::npos)
      << no_compute.status().message();
  json = ToJson(r);
  json["stage_probe"]["stages"][1]["stage"] = "geometry";
  auto unknown = SpeedResultsFromJson(json, "stages.json");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.status().message().find("'geometry' is not a stage"), std::string::npos)
      << unknown.status().message();
}

// A pass's fixed cost is the intercept of its time against its pixels; a
// negative one (a smaller frame faster per pixel than the line through the
// larger allows, as on an H100 whose 1920x1080 passes took 3.6 ps a pixel
// and its 3840x2160 ones 4.1) is no cost, and the line says so instead.
TEST(SpeedResultsTest, ANegativeFixedCostIsNotPrintedAsACost) {
  SpeedResults r = Example();
  r.gpu = {Timing(Variant::kDivide, 7410, Regime::kMemory), Timing(Variant::kDivide, 33600, Regime::kMemory)};
  r.gpu[1].resolution = {3840, 2160};
  std::ostringstream out;
  PrintSpeedHeader(r, out);
  EXPECT_NE(out.str().find("fixed cost per pass: not measurable here: the 1920x1080 passes took less per pixel than "
                           "the 3840x2160 ones (the line through them meets 0 pixels at -1.3 µs"),
            std::string::npos)
      << out.str();
  EXPECT_EQ(ToJson(r)["pass_cost_split"]["fixed_cost_measurable"], false);

  r.gpu[0].ns_per_pass.median = 9000;  // 9 us and 33.6 us: 0.8 us fixed, 3.95 ps a pixel
  std::ostringstream fitted;
  PrintSpeedHeader(r, fitted);
  EXPECT_NE(fitted.str().find("fixed cost per pass: 0.80 µs, apart from 3.95 ps per pixel"), std::string::npos)
      << fitted.str();
  EXPECT_EQ(ToJson(r)["pass_cost_split"]["fixed_cost_measurable"], true);
}

TEST(SpeedResultsTest, RefusesCellsThatDoNotExist) {
  nlohmann::json json = ToJson(Example());
  json["gpu"][1]["cell"] = "divide/linear/r32_sfloat";
  auto read = SpeedResultsFromJson(json, "bad.json");
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.status().message().find("bad.json: gpu[1].cell: cell 'divide/linear/r32_sfloat' does not exist: "
                                         "divide does not read r32_sfloat under the linear convention"),
            std::string::npos)
      << read.status().message();

  json = ToJson(Example());
  json["trade"][0]["points"][0]["variant"] = "frustum_ray";
  read = SpeedResultsFromJson(json, "bad.json");
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.status().message().find(
                "trade[0].points[0]: frustum_ray does not read d32_sfloat under the reversed convention"),
            std::string::npos)
      << read.status().message();
}

TEST(SpeedResultsTest, RefusesOtherSchemas) {
  nlohmann::json json = ToJson(Example());
  json["schema"] = "depthbench.results";
  auto read = SpeedResultsFromJson(json, "x.json");
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.status().message().find("schema is 'depthbench.results', expected 'depthbench.speed'"),
            std::string::npos);
  json = ToJson(Example());
  json["schema_version"] = 2;
  EXPECT_FALSE(SpeedResultsFromJson(json, "x.json").ok());
}

TEST(SpeedResultsTest, RanksWithinGroupsOnly) {
  const SpeedResults r = Example();
  // pq (50) is faster than divide (100) in the ALU-bound group; the
  // memory-bound divide is alone in its group.
  EXPECT_EQ(r.gpu[0].rank, 2u);
  EXPECT_EQ(r.gpu[1].rank, 1u);
  EXPECT_EQ(r.gpu[2].rank, 1u);
  EXPECT_TRUE(r.gpu[0].indistinguishable_from.empty());
  // Within the spread of each other: both rank 1, and each names the other.
  std::vector<GpuTiming> tied = {Timing(Variant::kDivide, 100), Timing(Variant::kPq, 101)};
  RankGpuTimings(tied);
  EXPECT_EQ(tied[0].rank, 1u);
  EXPECT_EQ(tied[1].rank, 1u);
  EXPECT_EQ(tied[0].indistinguishable_from, std::vector<Variant>{Variant::kPq});
  EXPECT_EQ(tied[1].indistinguishable_from, std::vector<Variant>{Variant::kDivide});
}

TEST(SpeedResultsTest, ComparesRankingsOfOneDevice) {
  const SpeedResults first = Example();
  SpeedResults second = Example();
  auto same = CompareRankings(first, second);
  ASSERT_TRUE(same.ok());
  EXPECT_EQ(same->pairs, 1u);
  EXPECT_EQ(same->agree, 1u);
  EXPECT_TRUE(same->contradictions.empty());

  // pq slower than divide now, by more than the spread: a contradiction.
  second.gpu[1].ns_per_pass = Summary(149, 150, 151);
  auto flipped = CompareRankings(first, second);
  ASSERT_TRUE(flipped.ok());
  ASSERT_EQ(flipped->contradictions.size(), 1u);
  EXPECT_NE(flipped->contradictions[0].find("divide is slower than pq in the first run"), std::string::npos)
      << flipped->contradictions[0];

  // Within the spread in the second run: one-sided, not a contradiction.
  second.gpu[1].ns_per_pass = Summary(90, 99, 110);
  auto tie = CompareRankings(first, second);
  ASSERT_TRUE(tie.ok());
  EXPECT_EQ(tie->one_sided, 1u);
  EXPECT_TRUE(tie->contradictions.empty());

  second.run.device.name = "NVIDIA H100";
  auto other = CompareRankings(first, second);
  ASSERT_FALSE(other.ok());
  EXPECT_NE(other.status().message().find("rankings are kept per device"), std::string::npos);
}

TEST(SpeedResultsTest, ParsesResolutions) {
  auto list = ParseResolutions("1920x1080,800x600", "--resolution");
  ASSERT_TRUE(list.ok());
  EXPECT_EQ(list->size(), 2u);
  EXPECT_FALSE(ParseResolutions("1920x1080,", "--resolution").ok());

  auto r = ParseResolution("3840x2160", "--resolution");
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->width, 3840u);
  EXPECT_EQ(r->height, 2160u);
  EXPECT_TRUE(ParseResolution("65535x1", "--resolution").ok());
  // Digits only, each side 1 to kMaxResolutionSide, nothing wrapped.
  for (const char* bad : {"1920", "0x10", "10x", "x10", "10x10x10", "-5x10", "+5x10", " 5x10", "65536x10",
                          "4294967297x10", "1e3x10"}) {
    EXPECT_FALSE(ParseResolution(bad, "--resolution").ok()) << bad;
  }
}

}  // namespace
}  // namespace depthbench
