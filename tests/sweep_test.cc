// Determinism, shard additivity and the results file.
#include <filesystem>
#include <limits>
#include <sstream>

#include <gtest/gtest.h>

#include "bench/backends/cpu/cpu_backend.h"
#include "bench/results/results.h"
#include "bench/results/results_table.h"
#include "bench/sweep/sweep.h"

namespace depthbench {
namespace {

Results RunCpu(std::uint64_t seed, std::uint64_t samples, Shard shard, std::uint32_t batch = 4096, unsigned threads = 2,
               Isa isa = Isa::kWidest) {
  SweepOptions options;
  options.isa = isa;
  options.seed = seed;
  options.samples = samples;
  options.shard = shard;
  options.batch_size = batch;
  options.threads = threads;
  auto cpu = MakeCpuBackend();
  Backend* backends[] = {cpu.get()};
  auto results = RunSweep(options, backends);
  EXPECT_TRUE(results.ok()) << results.status().message();
  return std::move(results).value();
}

void ExpectSameStats(const Results& a, const Results& b) {
  ASSERT_EQ(a.cells.size(), b.cells.size());
  for (std::size_t i = 0; i < a.cells.size(); ++i) {
    EXPECT_EQ(a.cells[i].cell, b.cells[i].cell);
    const CellStats& x = a.cells[i].stats;
    const CellStats& y = b.cells[i].stats;
    EXPECT_TRUE(x == y) << a.cells[i].cell.Name();
  }
}

// A lone camera-distance band made from the joint bands at the end holds
// exactly what recording it sample by sample gives, for cameras at the
// origin and at a fixed distance; a range across bands is recorded.
TEST(SweepTest, LoneDistanceBandIsTheWholeNaturalDistribution) {
  for (const Range distance : {Range{0.0, 0.0}, Range{50.0, 50.0}, Range{0.0, 1e4}}) {
    SweepOptions options;
    options.seed = 9;
    options.samples = 30000;
    options.domain.camera_distance = distance;
    auto cpu = MakeCpuBackend();
    Backend* backends[] = {cpu.get()};
    auto derived = RunSweep(options, backends);
    options.derive_lone_distance_band = false;
    auto recorded = RunSweep(options, backends);
    ASSERT_TRUE(derived.ok() && recorded.ok());
    ExpectSameStats(*derived, *recorded);
    // 0 to 1e4: the origin, [1, 1e2) and [1e2, 1e4).
    EXPECT_EQ(derived->cells.front().stats.distance.size(), distance.max == 1e4 ? 3u : 1u) << distance.ToString();
  }
  EXPECT_EQ(OnlyDistanceBand({0.0, 0.0}), 0);
  EXPECT_EQ(OnlyDistanceBand({50.0, 50.0}), 1);
  EXPECT_EQ(OnlyDistanceBand({100.0, 100.0}), std::nullopt);  // a rounding away from band 1
  EXPECT_EQ(OnlyDistanceBand({0.0, 0.5}), 0);
  EXPECT_EQ(OnlyDistanceBand({0.0, 5.0}), std::nullopt);
}

TEST(SweepTest, SameSeedSameResultsWhateverTheBatchingAndThreads) {
  Results a = RunCpu(42, 20000, {});
  Results b = RunCpu(42, 20000, {}, /*batch=*/777, /*threads=*/1);
  ExpectSameStats(a, b);
  EXPECT_EQ(a.run.reconstructions, 20000u * CellsForDomain(AllCells(), Domain{}).size());
  Results other = RunCpu(43, 20000, {});
  EXPECT_FALSE(a.cells[0].stats == other.cells[0].stats);  // the seed matters
}

TEST(SweepTest, EverySampleIsCountedOnceInEachSplitAndMetric) {
  // Each sample of a cell is finite, NaN, Inf, non-finite by its stored
  // value, degenerate or outside; a sample of the natural distribution in
  // one joint band and one distance band, a coverage sample in its coverage
  // band alone. A finite one has a total and absolute error, and an
  // arithmetic error unless its stored value denotes no holdable point; a
  // judged one has storage and production errors. Fails when statistics are
  // lost or counted twice between the judge and the results (an accumulator
  // not flushed, the encoding's errors not copied into the cells, a coverage
  // sample counted in the natural bands).
  constexpr std::uint64_t kSamples = 20000;
  const Results results = RunCpu(42, kSamples, {});
  ASSERT_FALSE(results.cells.empty());
  const auto counted = [](const BandStats& b) { return b.judged() + b.stored_nonfinite + b.degenerate + b.outside; };
  for (const CellResult& result : results.cells) {
    const std::string name = result.cell.Name();
    const BandStats all = result.stats.All(), coverage = result.stats.AllCoverage();
    EXPECT_EQ(counted(all) + counted(coverage), kSamples) << name;
    // About 69% of samples are natural: three quarters of depths times 92%
    // of pixels; 2% either way is many standard deviations of 20000 draws.
    EXPECT_NEAR(static_cast<double>(counted(all)) / kSamples, 0.69, 0.02) << name;
    EXPECT_GT(all.finite, 0u) << name;
    for (const BandStats* b : {&all, &coverage}) {
      EXPECT_EQ((*b)[Metric::kTotal].Count(), b->finite) << name;
      EXPECT_EQ((*b)[Metric::kAbsolute].Count(), b->finite) << name;
      EXPECT_LE((*b)[Metric::kArith].Count(), b->finite) << name;
      EXPECT_GE((*b)[Metric::kStorage].Count(), b->finite) << name;
      EXPECT_LE((*b)[Metric::kStorage].Count(), b->judged() + b->stored_nonfinite) << name;
      EXPECT_EQ((*b)[Metric::kProduction].Count(), (*b)[Metric::kStorage].Count()) << name;
    }
    std::uint64_t by_distance = 0, arith_by_distance = 0;
    for (int band = 0; band < kDistanceBands; ++band) {
      const BandStats d = result.stats.ForDistance(band);
      by_distance += counted(d);
      arith_by_distance += d[Metric::kArith].Count();
    }
    EXPECT_EQ(by_distance, counted(all)) << name;
    EXPECT_EQ(arith_by_distance, all[Metric::kArith].Count()) << name;
  }
}

// A backend whose outputs follow the sample index, non-finite on purpose:
// index % 4 = 0: (+inf, -inf, 1), infinite components of both signs;
//             1: (NaN, 1, 1);  2: (-inf, NaN, +inf);  3: (1, 2, 3).
class NonFinitePatternBackend final : public Backend {
 public:
  std::string name() const override { return "pattern"; }
  const DeviceInfo& device() const override { return device_; }
  ProgramInfo program() const override { return {"none", "pattern"}; }
  bool concurrent() const override { return true; }
  Status Prepare(std::span<const CellPlan>, PassKind) override { return Status::Ok(); }
  Expected<std::span<const float>> Run(const ShaderInputs& batch, std::span<const std::uint32_t> which,
                                       std::vector<float>& scratch) override {
    constexpr float kInf = std::numeric_limits<float>::infinity(), kNan = std::numeric_limits<float>::quiet_NaN();
    constexpr float kPatterns[4][3] = {{kInf, -kInf, 1}, {kNan, 1, 1}, {-kInf, kNan, kInf}, {1, 2, 3}};
    const std::size_t n = batch.count;
    scratch.resize(which.size() * 3 * n);
    for (std::size_t k = 0; k < which.size(); ++k) {
      for (std::size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) scratch[(k * 3 + c) * n + i] = kPatterns[(batch.first_index + i) % 4][c];
      }
    }
    return std::span<const float>(scratch);
  }

 private:
  DeviceInfo device_{"pattern", "test", "none", DeviceKind::kCpu, "none"};
};

TEST(SweepTest, NonFiniteOutputsAreCountedByTheirComponents) {
  // NaN when a component is NaN; Inf when one is infinite and none is NaN,
  // whatever the signs (+inf and -inf together are not a NaN output).
  // Hardware formats with a finite far plane at moderate ratios: no sample
  // is degenerate, so every judged output is counted by its pattern.
  SweepOptions options;
  options.samples = 4000;
  options.domain.infinite_far = false;
  options.domain.ratio = {10.0, 1e3};
  for (const Cell& cell : CellsForDomain(AllCells(), options.domain)) {
    if (Info(cell.format).stores == DepthInput::kHardware) options.cells.push_back(cell);
  }
  ASSERT_FALSE(options.cells.empty());
  NonFinitePatternBackend pattern;
  Backend* backends[] = {&pattern};
  const auto results = RunSweep(options, backends);
  ASSERT_TRUE(results.ok()) << results.status().message();
  for (const CellResult& result : results->cells) {
    const BandStats all = result.stats.Everything();
    ASSERT_EQ(all.degenerate, 0u) << result.cell.Name();
    ASSERT_EQ(all.stored_nonfinite, 0u) << result.cell.Name();
    // Samples outside the frustum (a few stored-value picks beyond a
    // plane) are not judged, whatever the output: each takes one sample
    // out of its pattern's count.
    EXPECT_EQ(all.inf + all.nan + all.finite + all.outside, 4000u) << result.cell.Name();
    EXPECT_LT(all.outside, 40u) << result.cell.Name();
    EXPECT_LE(all.inf, 1000u) << result.cell.Name();
    EXPECT_GE(all.inf + all.outside, 1000u) << result.cell.Name();
    EXPECT_LE(all.nan, 2000u) << result.cell.Name();
    EXPECT_GE(all.nan + all.outside, 2000u) << result.cell.Name();
    EXPECT_LE(all.finite, 1000u) << result.cell.Name();
    EXPECT_EQ(all.first_nonfinite_index, 0u) << result.cell.Name();
  }
}

TEST(SweepTest, EveryInstructionSetGivesTheSameResults) {
  // The hot loops are compiled for the build's baseline and for AVX-512
  // (bench/base/isa.h); both must count every error in the same bin, with the
  // same maxima. 777-sample batches end inside frames and chunks, so the
  // four-lane loops' scalar tails run too. The widest the processor runs is
  // what a sweep picks by default.
  const Results baseline = RunCpu(5, 30000, {}, 777, 2, Isa::kBaseline);
  ExpectSameStats(baseline, RunCpu(5, 30000, {}, 777, 2, Isa::kWidest));
  if (ProcessorRuns(Isa::kAvx512)) {
    ExpectSameStats(baseline, RunCpu(5, 30000, {}, 777, 2, Isa::kAvx512));
    EXPECT_EQ(Resolve(Isa::kWidest), Isa::kAvx512);
  } else {
    // Without AVX-512 the default is the baseline, and asking for AVX-512
    // is refused rather than run into an illegal instruction.
    EXPECT_EQ(Resolve(Isa::kWidest), Isa::kBaseline);
    SweepOptions options;
    options.isa = Isa::kAvx512;
    options.samples = 100;
    auto cpu = MakeCpuBackend();
    Backend* backends[] = {cpu.get()};
    const auto refused = RunSweep(options, backends);
    ASSERT_FALSE(refused.ok());
    EXPECT_NE(refused.status().message().find("instruction set"), std::string::npos) << refused.status().message();
  }
}

TEST(SweepTest, ShardsAddUpToTheWhole) {
  Results whole = RunCpu(7, 30001, {});
  std::vector<Results> parts;
  for (std::uint32_t k = 1; k <= 3; ++k) parts.push_back(RunCpu(7, 30001, {k, 3}));
  // Merge in a scrambled order: addition must not care.
  auto merged = MergeResults({parts[2], parts[0], parts[1]});
  ASSERT_TRUE(merged.ok()) << merged.status().message();
  ExpectSameStats(whole, *merged);
  EXPECT_EQ(merged->run.shards.size(), 3u);
}

TEST(SweepTest, MergeRefusesOverlappingOrForeignShards) {
  Results a = RunCpu(7, 2000, {1, 2});
  Results b = RunCpu(7, 2000, {1, 2});
  EXPECT_FALSE(MergeResults({a, b}).ok());
  Results c = RunCpu(8, 2000, {2, 2});
  auto merged = MergeResults({a, c});
  ASSERT_FALSE(merged.ok());
  EXPECT_NE(merged.status().message().find("same sweep"), std::string::npos);
}

TEST(SweepTest, MergeNamesTheFieldThatDiffersAndBothValues) {
  const Results a = RunCpu(7, 2000, {1, 2});
  Results b = RunCpu(7, 2000, {2, 2});
  ASSERT_TRUE(MergeResults({a, b}).ok());
  b.run.backends[0].program.hash = "depthbench 9.9.9";
  auto merged = MergeResults({a, b}, {"a.json", "b.json"});
  ASSERT_FALSE(merged.ok());
  EXPECT_NE(merged.status().message().find("'b.json' is not a shard of the same sweep as 'a.json': "
                                           "run.backends.program_hash differs: 'cpu=depthbench " +
                                           a.run.version + "' in 'a.json', 'cpu=depthbench 9.9.9' in 'b.json'"),
            std::string::npos)
      << merged.status().message();
  b = RunCpu(7, 2000, {2, 2});
  b.run.cells.pop_back();
  merged = MergeResults({a, b});
  ASSERT_FALSE(merged.ok());
  EXPECT_NE(merged.status().message().find("part 2 is not a shard of the same sweep as part 1: run.cells differs"),
            std::string::npos)
      << merged.status().message();
  b = RunCpu(7, 2000, {2, 2});
  b.run.version = "9.9.9";
  EXPECT_NE(MergeResults({a, b}).status().message().find("run.version differs"), std::string::npos);
}

TEST(SweepTest, MergeCallsShardsOfDifferentSplitsSo) {
  auto merged = MergeResults({RunCpu(7, 2000, {1, 2}), RunCpu(7, 2000, {2, 3})});
  ASSERT_FALSE(merged.ok());
  EXPECT_NE(merged.status().message().find("shards 1/2 and 2/3 are of different splits"), std::string::npos)
      << merged.status().message();
  EXPECT_EQ(merged.status().message().find("overlap"), std::string::npos) << merged.status().message();
}

TEST(SweepTest, MergeRefusesAPartialPartUnlessAllowed) {
  const Results a = RunCpu(7, 2000, {1, 2});
  Results b = RunCpu(7, 2000, {2, 2});
  b.run.partial = true;
  b.run.samples_judged = 500;
  auto merged = MergeResults({a, b}, {"a.json", "b.json"});
  ASSERT_FALSE(merged.ok());
  EXPECT_NE(merged.status().message().find("'b.json' is partial: its sweep was interrupted after 500"),
            std::string::npos)
      << merged.status().message();
  merged = MergeResults({a, b}, {}, /*allow_partial=*/true);
  ASSERT_TRUE(merged.ok()) << merged.status().message();
  EXPECT_TRUE(merged->run.partial);
  EXPECT_EQ(merged->run.samples_judged, 1000u + 500u);
}

TEST(SweepTest, AnAllNanCellShowsNoBitsFigure) {
  // Bits lost of no finite output read 0.0, as if it were perfect.
  Results results = RunCpu(7, 100, {});
  CellResult& cell = results.cells.front();
  cell.stats = CellStats{};
  cell.stats.joint[JointBand(0, 0)].nan = 100;
  results.cells.resize(1);
  std::ostringstream out;
  PrintResultsTable(results, TextOutput(out));
  const std::string table = out.str();
  const auto row = table.find(cell.cell.Name());
  ASSERT_NE(row, std::string::npos) << table;
  const std::string line = table.substr(row, table.find('\n', row) - row);
  EXPECT_NE(line.find("none finite"), std::string::npos) << table;
  EXPECT_EQ(line.find("0.0"), std::string::npos) << table;
}

TEST(SweepTest, ResultsSurviveTheJsonRoundTrip) {
  Results original = RunCpu(9, 5000, {});
  const auto path = std::filesystem::temp_directory_path() / "depthbench_sweep_test.json";
  ASSERT_TRUE(WriteResults(path, original).ok());
  auto read = ReadResults(path);
  ASSERT_TRUE(read.ok()) << read.status().message();
  ExpectSameStats(original, *read);
  EXPECT_EQ(read->run.seed, 9u);
  EXPECT_EQ(read->run.domain.near, original.run.domain.near);
  EXPECT_EQ(read->run.stages.build, original.run.stages.build);
  EXPECT_EQ(read->run.stages.judging, original.run.stages.judging);
  std::filesystem::remove(path);
  // Files written before the stage times were recorded still read.
  nlohmann::json old = ToJson(original);
  old["run"].erase("stage_seconds");
  auto older = ResultsFromJson(old, "old.json");
  ASSERT_TRUE(older.ok()) << older.status().message();
  EXPECT_TRUE(older->run.stages.empty());
}

// Where the host judges, the build and the judging take turns on the
// main thread: their times are disjoint spans of the run's wall clock,
// and with the set-up before the first batch and the last flush (judging),
// nearly all of it: 80%, since the results are assembled outside them
// (moves of a few hundred statistics, milliseconds even on a busy
// machine). Merged shards add them up.
TEST(SweepTest, StageTimesShareOutTheWallClock) {
  const Results whole = RunCpu(7, 200000, {});
  const StageSeconds& t = whole.run.stages;
  EXPECT_GT(t.build, 0.0);
  EXPECT_GT(t.judging, 0.0);
  EXPECT_GT(t.setup, 0.0);
  EXPECT_LE(t.setup + t.build + t.judging, whole.run.seconds);
  EXPECT_GE(t.setup + t.build + t.judging, 0.8 * whole.run.seconds);
  EXPECT_EQ(t.build_waited, 0.0);   // nothing overlaps
  EXPECT_EQ(t.device_waited, 0.0);  // no device judges
  const Results a = RunCpu(7, 2000, {1, 2}), b = RunCpu(7, 2000, {2, 2});
  auto merged = MergeResults({a, b});
  ASSERT_TRUE(merged.ok()) << merged.status().message();
  EXPECT_EQ(merged->run.stages.build, a.run.stages.build + b.run.stages.build);
  EXPECT_EQ(merged->run.stages.judging, a.run.stages.judging + b.run.stages.judging);
  EXPECT_TRUE(merged->run.stages.device_passes.empty());  // no device judged
  // Devices' passes add up by name, in the order they first came; a pass
  // one shard lacks keeps the other's time.
  Results c = a, d = b;
  c.run.stages.device_passes = {{"idle", 0.5}, {"judge", 2.0}};
  d.run.stages.device_passes = {{"idle", 0.25}, {"sample", 1.0}, {"judge", 4.0}};
  merged = MergeResults({c, d});
  ASSERT_TRUE(merged.ok()) << merged.status().message();
  EXPECT_EQ(merged->run.stages.device_passes,
            (std::vector<std::pair<std::string, double>>{{"idle", 0.75}, {"judge", 6.0}, {"sample", 1.0}}));
}

TEST(SweepTest, BadResultsFilesNameTheFieldThatIsWrong) {
  nlohmann::json j = ToJson(RunCpu(1, 500, {}));
  j["cells"][2]["bands"]["joint"][0]["finite"] = "many";
  auto bad = ResultsFromJson(j, "bad.json");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("bad.json: cells[2].bands.joint[0].finite"), std::string::npos)
      << bad.status().message();
  j = ToJson(RunCpu(1, 500, {}));
  j["schema_version"] = 99;
  EXPECT_NE(ResultsFromJson(j, "x.json").status().message().find("schema_version 99"), std::string::npos);
}

}  // namespace
}  // namespace depthbench
