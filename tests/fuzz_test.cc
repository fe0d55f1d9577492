// The fuzzer's engine: fuzz points and their bytes, reproducer files, the
// invariants on the real CPU backend, the campaign and the worst-case
// search.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>

#include <gtest/gtest.h>

#include "bench/backends/cpu/cpu_backend.h"
#include "bench/fuzz/campaign.h"
#include "bench/fuzz/case_check.h"
#include "bench/fuzz/fuzz_case.h"
#include "bench/fuzz/known_findings.h"
#include "bench/fuzz/worst_case.h"
#include "bench/pipeline/stats.h"
#include "bench/sweep/sweep.h"
#include "tests/command_runner.h"

namespace depthbench {
namespace {

TEST(FuzzPointTest, ZeroAndOneBytesReachBothEndsOfEveryRange) {
  const Domain d = FuzzDomain();
  const std::vector<std::uint8_t> zeros(kFuzzPointBytes, 0), ones(kFuzzPointBytes, 0xff);
  const FuzzCase low = CaseAt(d, DecodePoint(zeros));
  const FuzzCase high = CaseAt(d, DecodePoint(ones));
  EXPECT_DOUBLE_EQ(low.frame.fov_y_degrees, 0.01);
  EXPECT_NEAR(high.frame.fov_y_degrees, 179.9, 1e-9);
  EXPECT_NEAR(low.frame.aspect, 1e-3, 1e-15);
  EXPECT_NEAR(high.frame.aspect, 1e3, 1e-9);
  EXPECT_NEAR(low.frame.near, 1e-7, 1e-19);
  EXPECT_NEAR(high.frame.ratio(), 1e9, 1e-3);
  EXPECT_EQ(low.frame.camera_distance(), 0.0);  // at_origin unit 0: the camera sits at the origin
  EXPECT_NEAR(high.frame.camera_distance(), 1e7, 1.0);
  EXPECT_EQ(low.sample.pick, DepthPick::kStoredZero);
  EXPECT_EQ(low.sample.x, 0u);  // pixel kind 0: the top-left corner
  EXPECT_EQ(low.sample.y, 0u);
}

TEST(FuzzPointTest, BytesRoundTripAndShortInputsReadAsZero) {
  FuzzPoint p;
  for (int k = 0; k < kFuzzUnits; ++k) UnitOf(p, k) = (k + 1) / 19.0;
  const FuzzPoint back = DecodePoint(EncodePoint(p));
  for (int k = 0; k < kFuzzUnits; ++k) {
    EXPECT_NEAR(UnitOf(const_cast<FuzzPoint&>(back), k), UnitOf(p, k), 1e-9) << k;  // 32-bit words
  }
  const std::uint8_t three[] = {1, 2, 3};
  FuzzPoint short_point = DecodePoint(three);
  EXPECT_GT(UnitOf(short_point, 0), 0.0);
  for (int k = 1; k < kFuzzUnits; ++k) EXPECT_EQ(UnitOf(short_point, k), 0.0) << k;
}

TEST(ReproFileTest, RoundTripsTheCaseExactly) {
  FuzzPoint p;
  for (int k = 0; k < kFuzzUnits; ++k) UnitOf(p, k) = std::fmod(0.37 * (k + 1), 1.0);
  UnitOf(p, 13) = 0.9;  // an eye-depth pick
  ReproFile file;
  file.fuzz_case = CaseAt(FuzzDomain(), p);
  file.cells = {*ParseCell("divide/standard/d24")};
  file.backends = {"cpu"};
  const nlohmann::json json = nlohmann::json::parse(ReproFileToJson(file).dump());
  auto back = ReproFileFromJson(json, "x.json");
  ASSERT_TRUE(back.ok()) << back.status().message();
  const Frame &a = file.fuzz_case.frame, &b = back->fuzz_case.frame;
  EXPECT_EQ(a.fov_y_degrees, b.fov_y_degrees);
  EXPECT_EQ(a.tan_half_fov_y, b.tan_half_fov_y);
  EXPECT_EQ(a.aspect, b.aspect);
  EXPECT_EQ(a.near, b.near);
  EXPECT_EQ(a.far, b.far);
  EXPECT_EQ(a.rotation, b.rotation);
  EXPECT_EQ(a.camera_position, b.camera_position);
  EXPECT_EQ(a.volume_depth, b.volume_depth);
  EXPECT_EQ(back->fuzz_case.sample.eye_depth, file.fuzz_case.sample.eye_depth);
  EXPECT_EQ(back->fuzz_case.sample.x, file.fuzz_case.sample.x);
  EXPECT_EQ(back->cells.front(), file.cells.front());
}

// A known finding may name the backends it is accepted on: "vulkan"
// covers the device and its probes, not the CPU, so the same NaN on the
// CPU stays new. A name that is no backend is refused with its field.
TEST(KnownFindingsTest, BackendsScopeAnEntry) {
  const auto parse = [](const std::string& backends) {
    return KnownFindingsFromJson(nlohmann::json::parse(R"({"schema": "depthbench.known_findings", "schema_version": 1,
        "findings": [{"variant": "divide", "conventions": ["reversed-inf"], "formats": ["d32_sfloat"],
                      "backends": )" + backends + R"(, "kind": "nan", "reason": "a device's own"}]})"),
                                 "known.json");
  };
  auto known = parse(R"(["vulkan"])");
  ASSERT_TRUE(known.ok()) << known.status().message();
  const Cell cell{Variant::kDivide, Convention::kReversedInf, Format::kD32Sfloat};
  EXPECT_NE(FindKnown(*known, cell, FindingKind::kNaN, "vulkan"), nullptr);
  EXPECT_NE(FindKnown(*known, cell, FindingKind::kNaN, "vulkan:worst-division"), nullptr);
  EXPECT_EQ(FindKnown(*known, cell, FindingKind::kNaN, "cpu"), nullptr);
  EXPECT_EQ(FindKnown(*known, cell, FindingKind::kInf, "vulkan"), nullptr);
  const Cell other{Variant::kDivide, Convention::kReversed, Format::kD32Sfloat};
  EXPECT_EQ(FindKnown(*known, other, FindingKind::kNaN, "vulkan"), nullptr);
  // Without the field, any backend.
  auto any = KnownFindingsFromJson(nlohmann::json::parse(R"({"schema": "depthbench.known_findings",
      "schema_version": 1, "findings": [{"variant": "divide", "kind": "nan", "reason": "r"}]})"),
                                   "known.json");
  ASSERT_TRUE(any.ok()) << any.status().message();
  EXPECT_NE(FindKnown(*any, cell, FindingKind::kNaN, "cpu"), nullptr);
  auto bad = parse(R"(["gpu"])");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("backends"), std::string::npos) << bad.status().message();
  EXPECT_NE(bad.status().message().find("'gpu' is not a backend"), std::string::npos) << bad.status().message();
}

TEST(ReproFileTest, BadFilesNameTheField) {
  ReproFile file;
  file.fuzz_case = CaseAt(FuzzDomain(), FuzzPoint{});
  file.cells = {*ParseCell("pq/reversed/d32f")};
  const nlohmann::json good = ReproFileToJson(file);
  struct Case {
    std::string pointer;
    nlohmann::json value;
    std::string message;
  };
  for (const Case& c : std::vector<Case>{
           {"/schema", "depthbench.results", "expected 'depthbench.repro'"},
           {"/case/frame/near", -1.0, "case.frame.near: -1 is out of range"},
           {"/case/frame/far", 1e-9, "must be greater than near"},
           {"/case/frame/rotation/0", 2.0, "not an orthonormal matrix"},
           {"/case/frame/camera_position/0", 0.1, "must be a float32 value"},
           {"/case/sample/x", 99999, "is outside the"},
           {"/case/sample/pick", "somewhere", "unknown depth pick 'somewhere'"},
           {"/cells/0", "divide/sideways/d24", "sideways"},
       }) {
    nlohmann::json bad = good;
    bad[nlohmann::json::json_pointer(c.pointer)] = c.value;
    auto read = ReproFileFromJson(bad, "bad.json");
    ASSERT_FALSE(read.ok()) << c.pointer;
    EXPECT_NE(read.status().message().find(c.message), std::string::npos) << read.status().message();
    EXPECT_NE(read.status().message().find("bad.json"), std::string::npos) << read.status().message();
  }
}

TEST(CaseCheckTest, BoundFollowsTheConditionNumbers) {
  Frame frame;
  frame.fov_y_degrees = 60;
  frame.aspect = 1;
  frame.near = 1;
  frame.far = 1e6;
  CompleteFrame(frame, std::nullopt);
  f32::DepthParams standard{};
  standard.coefficients.x = 1.0f;  // A of standard Z with a far plane far away
  f32::DepthParams reversed{};
  reversed.coefficients.x = 0.0f;
  const Cell s = *ParseCell("divide/standard/d32f"), r = *ParseCell("divide/reversed/d32f");
  // Standard Z near the far plane: ndc - A is tiny, the bound grows as 1/gap.
  const double near_far_plane = ArithmeticBound(s, frame, standard, 1.0f - 0x1.0p-20f, 1e5);
  const double mid = ArithmeticBound(s, frame, standard, 0.5f, 1e5);
  EXPECT_GT(near_far_plane / mid, 1e4);
  // Reversed Z: the same depth is well conditioned.
  EXPECT_LT(ArithmeticBound(r, frame, reversed, 0x1.0p-20f, 1e5), 4 * mid);
  // A camera 1e6 from the origin costs 1e6 / distance in the world step.
  frame.camera_position = glm::dvec3(1e6, 0, 0);
  EXPECT_GT(ArithmeticBound(r, frame, reversed, 0.5f, 1.0), 1e5 * kRoundings * 0x1.0p-24);
}

// A named extreme of the catalogue (issue 7): the fuzz campaign on the CPU
// backend, 64 x 64 x 8 inputs with the extreme held and everything else
// random, against the invariants.
struct Extreme {
  std::string name;
  std::function<void(Domain&)> domain;  // applied to the well-conditioned base below
  std::vector<std::pair<int, double>> pinned;
  // The cells expected to fail, as "variant kind" pairs; empty: none.
  std::set<std::string> expected;
};

void PrintTo(const Extreme& e, std::ostream* os) { *os << e.name; }

// The base: everything but the extreme inside what float32 constants carry
// (far/near up to 1e6: f/(f - n) still differs from 1 in float32).
Domain Base() {
  Domain d;
  d.ratio = {10.0, 1e6};
  return d;
}

// Units of a FuzzPoint (fuzz_case.h): 13 pick, 15 pixel kind.
constexpr int kPick = 13, kPixelKind = 15;

class ExtremeTest : public ::testing::TestWithParam<Extreme> {};

TEST_P(ExtremeTest, FiniteWithinTheBoundOrACountedFinding) {
  const Extreme& e = GetParam();
  auto cpu = MakeCpuBackend();
  CampaignOptions options;
  options.seconds = 0;
  options.cases = 64 * 64 * 8;
  options.domain = Base();
  e.domain(options.domain);
  ASSERT_TRUE(options.domain.Validate().ok()) << options.domain.Validate().message();
  options.cells = CellsForDomain(AllCells(), options.domain);
  // Eye depths and uniform pixels unless the extreme pins a stored value or
  // a corner: each test isolates its extreme.
  options.pinned = {{kPick, 0.6}, {kPixelKind, 0.5}};
  options.pinned.insert(options.pinned.end(), e.pinned.begin(), e.pinned.end());
  const std::string out = testing::MakeTempDir("extreme_" + e.name);
  options.out = out;
  Backend* backends[] = {cpu.get()};
  auto result = RunCampaign(options, backends);
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_GT(result->checks, options.cases);  // every input went through many cells
  std::set<std::string> found;
  for (const CampaignFinding& f : result->findings) {
    found.insert(std::string(Info(f.cell.variant).name) + " " + FindingKindName(f.kind));
    // Every finding is counted and written as a reproducer that replays it.
    EXPECT_GE(f.hits, 1u);
    auto file = ReadReproFile(f.file);
    ASSERT_TRUE(file.ok()) << file.status().message();
    auto one = CaseChecker::Make(file->cells, {cpu.get()}, 1);
    ASSERT_TRUE(one.ok());
    const CaseSource source(file->fuzz_case);
    ASSERT_TRUE(one->Evaluate(source, 0, 1).ok());
    EXPECT_TRUE(one->At(0, 0, 0).violates()) << f.signature << " does not replay";
  }
  EXPECT_EQ(found, e.expected);
}

INSTANTIATE_TEST_SUITE_P(
    Catalogue, ExtremeTest,
    ::testing::Values(Extreme{"near_1e_6",
                              [](Domain& d) {
                                d.near = {1e-6, 1e-6};
                              },
                              {},
                              {}},
                      Extreme{"near_1e_7",
                              [](Domain& d) {
                                d.near = {1e-7, 1e-7};
                              },
                              {},
                              {}},
                      // Far/near beyond 2^24: f/(f - n) rounds to 1 in float32. The
                      // pipeline, computing depth from that same float A, stores values
                      // at the far plane that denote infinity: their non-finite outputs
                      // are expected, no finding. divide alone still returns NaN where
                      // its own ndc_z/B - A/B cancels for stored values that denote a
                      // finite point.
                      Extreme{"ratio_1e9",
                              [](Domain& d) {
                                d.ratio = {1e9, 1e9};
                              },
                              {},
                              {"divide nan"}},
                      // divide forms ndc_z/B - A/B: on [-1, 1] infinite conventions the
                      // two quotients are equal in float32 for depths far enough, the
                      // difference is exactly 0 and the position NaN (seed 004's trap).
                      Extreme{"infinite_far", [](Domain& d) { d.finite_far = false; }, {}, {"divide nan"}},
                      Extreme{"fov_0_01",
                              [](Domain& d) {
                                d.fov_degrees = {0.01, 0.01};
                              },
                              {},
                              {}},
                      Extreme{"fov_179_9",
                              [](Domain& d) {
                                d.fov_degrees = {179.9, 179.9};
                              },
                              {},
                              {}},
                      Extreme{"aspect_1e_3",
                              [](Domain& d) {
                                d.aspect = {1e-3, 1e-3};
                              },
                              {},
                              {}},
                      Extreme{"aspect_1e3",
                              [](Domain& d) {
                                d.aspect = {1e3, 1e3};
                              },
                              {},
                              {}},
                      Extreme{"camera_1e7",
                              [](Domain& d) {
                                d.camera_distance = {1e7, 1e7};
                              },
                              {},
                              {}},
                      Extreme{"stored_zero", [](Domain&) {}, {{kPick, 0.005}}, {}},
                      Extreme{"stored_one", [](Domain&) {}, {{kPick, 0.018}}, {}},
                      Extreme{"smallest_subnormal", [](Domain&) {}, {{kPick, 0.03}}, {}},
                      // The same trap on standard infinite Z: ndc_z = 1 - 2^-24 and A = 1.
                      Extreme{"one_step_below_one", [](Domain&) {}, {{kPick, 0.045}}, {"divide nan"}},
                      Extreme{"corner_top_left", [](Domain&) {}, {{kPixelKind, 0.001}}, {}},
                      Extreme{"corner_bottom_right", [](Domain&) {}, {{kPixelKind, 0.031}}, {}}),
    [](const ::testing::TestParamInfo<Extreme>& info) { return info.param.name; });

// With a quarter of the evaluations, the search finds an error at least as
// large as the largest of 10^6 random samples. The budget is a count, not a
// time, so the outcome does not depend on how loaded the machine is.
TEST(WorstCaseTest, SearchFindsAtLeastTheRandomMaximum) {
  auto cpu = MakeCpuBackend();
  for (const char* name : {"reciprocal/reversed/d32f", "frustum_ray/linear/r32f"}) {
    const Cell cell = *ParseCell(name);
    SweepOptions sweep;
    sweep.samples = 1'000'000;
    sweep.seed = 7;
    sweep.cells = {cell};
    Backend* only[] = {cpu.get()};
    auto random = RunSweep(sweep, only);
    ASSERT_TRUE(random.ok()) << random.status().message();
    const double random_worst = random->cells.front().stats.All()[Metric::kTotal].max();

    SearchOptions options;
    options.cell = cell;
    options.domain = sweep.domain;
    options.seconds = 600;  // a safety stop only
    options.evaluations = sweep.samples / 4;
    auto found = SearchWorstCase(options, *cpu);
    ASSERT_TRUE(found.ok()) << found.status().message();
    EXPECT_GE(found->evaluations, options.evaluations);
    EXPECT_GE(found->worst, random_worst)
        << name << ": search " << BitsLost(found->worst) << " bits in " << found->evaluations << " evaluations, random "
        << BitsLost(random_worst) << " bits in " << sweep.samples;
  }
}

}  // namespace
}  // namespace depthbench

namespace depthbench {
namespace {

// depthbench fuzz as a user runs it, on lavapipe and the CPU together:
// far/near 1e9 (beyond what float32 constants carry) makes the divide
// variant's ndc/B - A/B cancel to 0 near the far plane on both backends.
// With no known-findings file the campaign says so (one finding, both
// backends merged), exits 1, writes one shrunk reproducer per backend, and
// `run --repro` replays it with the same verdict; with the committed file
// the same finding is known, reported with its reason, and the run exits 0.
TEST(FuzzCommandTest, FindsShrinksWritesAndReplaysOnBothBackends) {
  const std::string out = testing::MakeTempDir("fuzz_command");
  const std::vector<std::string> campaign = {"fuzz",   "--cases",      "8192",      "--ratio",  "1e9",  "--variant",
                                             "divide", "--convention", "standard",  "--format", "d32f", "--out",
                                             out,      "--quiet",      "--validate"};
  std::vector<std::string> unknown = campaign;
  unknown.insert(unknown.end(), {"--known", "none"});
  const testing::CommandResult fuzz = testing::RunDepthbench(unknown);
  ASSERT_EQ(fuzz.exit_code, 1) << fuzz.out << fuzz.err;
  EXPECT_NE(fuzz.out.find("1 new shader findings"), std::string::npos) << fuzz.out;
  EXPECT_NE(fuzz.out.find("divide/standard/d32_sfloat nan  cpu, vulkan"), std::string::npos) << fuzz.out;
  const testing::CommandResult known = testing::RunDepthbench(campaign);
  EXPECT_EQ(known.exit_code, 0) << known.out << known.err;
  EXPECT_NE(known.out.find("no new findings"), std::string::npos) << known.out;
  EXPECT_NE(known.out.find("- divide nan in 1 cells (divide/standard/d32_sfloat): divide forms ndc/B - A/B"),
            std::string::npos)
      << known.out;
  for (const char* backend : {"cpu", "vulkan"}) {
    const std::string file = out + "/divide_standard_d32_sfloat_" + backend + "_nan.json";
    const testing::CommandResult replay = testing::RunDepthbench({"run", "--repro", file, "--validate"});
    EXPECT_EQ(replay.exit_code, 1) << replay.out << replay.err;
    EXPECT_NE(replay.out.find(std::string("divide/standard/d32_sfloat on ") + backend +
                              ": FINDING: NaN where the reference is finite"),
              std::string::npos)
        << replay.out;
  }
  // A file that is not a reproducer is refused with its field named.
  const testing::CommandResult bad =
      testing::RunDepthbench({"run", "--repro", std::string(DEPTHBENCH_SOURCE_DIR) + "/reports/baselines/cpu.json"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("schema is 'depthbench.baseline', expected 'depthbench.repro'"), std::string::npos) << bad.err;
}

// On unchanged code the campaign finds nothing that the committed
// known-findings file does not explain (each entry with its reason): a
// fuzz job in CI stays green until something new appears.
TEST(FuzzCommandTest, UnchangedCodeHasNoNewFindings) {
  const std::string out = testing::MakeTempDir("fuzz_unchanged");
  const testing::CommandResult fuzz = testing::RunDepthbench({"fuzz", "--seconds", "30", "--out", out, "--quiet"});
  EXPECT_EQ(fuzz.exit_code, 0) << fuzz.out << fuzz.err;
  EXPECT_NE(fuzz.out.find("no new findings"), std::string::npos) << fuzz.out;
}

}  // namespace
}  // namespace depthbench
