// The judge on the device (bench/device_judge/) against the host judge, on
// lavapipe: for a fixed seed both must record the same statistics, bin for
// bin, count for count, maximum and worst index included. The runs are
// chosen to reach everything the judge records: the wide and extremes
// domains (non-finite outputs by every cause, samples outside the frustum
// and degenerate ones, every coverage kind), camera-distance bands
// recorded sample by sample, batches that start and end inside frames,
// and flushes in the middle of the run.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "bench/backends/cpu/cpu_backend.h"
#include "bench/backends/vulkan/vulkan_backend.h"
#include "bench/device_judge/device_judge.h"
#include "bench/device_judge/judge_groups.h"
#include "bench/numerics/formulas_mpfr.h"
#include "bench/sweep/sweep.h"
#include "shared/compat.h"

namespace depthbench {
// The words the host and the passes exchange, as C++ instantiates them.
namespace judge_words {
using uint = std::uint32_t;
#include "shared/judge.h"
}  // namespace judge_words

namespace {

class DeviceJudgeTest : public ::testing::Test {
 public:
  // DEPTHBENCH_TEST_DEVICE names another device than lavapipe (a GPU:
  // the same comparisons then run there, without the validation layer,
  // which a GPU machine may lack).
  static void SetUpTestSuite() {
    VulkanContextOptions options;
    const char* device = std::getenv("DEPTHBENCH_TEST_DEVICE");
    options.device = device != nullptr ? device : "";
    options.validation = options.device.empty();
    auto context = VulkanContext::Create(options);
    ASSERT_TRUE(context.ok()) << context.status().message();
    context_ = new std::shared_ptr<VulkanContext>(std::move(context).value());
  }
  static void TearDownTestSuite() { delete context_; }

  // A sweep of shard 2/3 (its first sample lies inside a frame) in batches
  // of 1000 samples (not whole frames; ExpectSameStatistics may ask
  // others), flushed every 5000 samples.
  static SweepOptions Options(const Domain& domain) {
    SweepOptions options;
    options.seed = 7;
    options.samples = 45000;
    options.shard = {2, 3};
    options.domain = domain;
    options.batch_size = 1000;
    options.flush_every = 5000;
    options.derive_lone_distance_band = false;
    return options;
  }

  static Expected<Results> Sweep(SweepOptions options, JudgeSite judge) {
    options.judge = judge;
    DB_ASSIGN_OR_RETURN(std::unique_ptr<Backend> vulkan, MakeVulkanBackend(*context_, BackendOptions{}));
    Backend* backends[] = {vulkan.get()};
    Expected<Results> results = RunSweep(options, backends);
    const std::vector<std::string> messages = (*context_)->TakeValidationMessages();
    EXPECT_TRUE(messages.empty()) << messages.front();
    return results;
  }

  static const std::shared_ptr<VulkanContext>& Context() { return *context_; }
  static std::shared_ptr<VulkanContext>* context_;
};
std::shared_ptr<VulkanContext>* DeviceJudgeTest::context_ = nullptr;

// What the comparison covered, summed over every cell and band.
struct Reached {
  std::uint64_t judged = 0, findings = 0, stored_nonfinite = 0, degenerate = 0, outside = 0, undrawn = 0, maxima = 0;
  void Add(const std::map<int, BandStats>& bands) {
    for (const auto& [band, stats] : bands) {
      judged += stats.finite;
      findings += stats.nan + stats.inf;
      stored_nonfinite += stats.stored_nonfinite;
      degenerate += stats.degenerate;
      outside += stats.outside;
      undrawn += stats.undrawn;
      for (Metric m : {Metric::kTotal, Metric::kArith, Metric::kAbsolute}) {
        maxima += stats[m].worst_index != std::numeric_limits<std::uint64_t>::max() ? 1 : 0;
      }
    }
  }
};

// Every cell's statistics equal in the two runs; what the comparison
// covered (the device's run's bands).
Reached ExpectSameCells(const Results& host, const Results& device) {
  Reached reached;
  EXPECT_EQ(host.cells.size(), device.cells.size());
  for (std::size_t c = 0; c < std::min(host.cells.size(), device.cells.size()); ++c) {
    const CellStats& a = host.cells[c].stats;
    const CellStats& b = device.cells[c].stats;
    EXPECT_TRUE(a == b) << host.cells[c].cell.Name();
    reached.Add(b.joint);
    reached.Add(b.distance);
    reached.Add(b.coverage);
  }
  return reached;
}

// The names of timed steps in order, and their sum; each step's seconds
// are checked to be at least zero, or above it.
std::pair<std::vector<std::string>, double> NamesAndTotal(const std::vector<std::pair<std::string, double>>& steps,
                                                          bool each_positive) {
  std::vector<std::string> names;
  double total = 0.0;
  for (const auto& [name, seconds] : steps) {
    names.push_back(name);
    if (each_positive) {
      EXPECT_GT(seconds, 0.0) << name;
    } else {
      EXPECT_GE(seconds, 0.0) << name;
    }
    total += seconds;
  }
  return {names, total};
}

void ExpectSameStatistics(const Domain& domain, const std::string& name, DeviceJudgeTuning tuning = {},
                          bool device_draws = true, std::uint32_t batch_size = 1000) {
  SCOPED_TRACE(name);
  SweepOptions on_host = DeviceJudgeTest::Options(domain);
  on_host.batch_size = batch_size;
  auto host = DeviceJudgeTest::Sweep(on_host, JudgeSite::kHost);
  SweepOptions on_device = on_host;
  on_device.device_tuning = tuning;
  on_device.device_draws = device_draws;
  auto device = DeviceJudgeTest::Sweep(on_device, JudgeSite::kDevice);
  ASSERT_TRUE(host.ok()) << host.status().message();
  ASSERT_TRUE(device.ok()) << device.status().message();
  ASSERT_EQ(host->cells.size(), device->cells.size());
  // The results say where each was judged.
  EXPECT_EQ(host->run.backends.at(0).judge, JudgedOn::kHost);
  EXPECT_EQ(device->run.backends.at(0).judge, JudgedOn::kDevice);
  // And where the time went. Here the build of a batch overlaps the
  // judging of the one before: the main thread's spans (set-up, building, waiting
  // for the judging) are disjoint within the wall clock, and so are the
  // judging thread's; the device's passes are waited for within the
  // judging, and on lavapipe take most of it.
  const StageSeconds& t = device->run.stages;
  EXPECT_LE(t.setup + t.build + t.build_waited, device->run.seconds);
  EXPECT_GT(t.setup, 0.0);  // the judge's shaders compiled
  EXPECT_LE(t.judging, device->run.seconds);
  EXPECT_GT(t.device_waited, 0.0);
  EXPECT_LE(t.device_waited, t.judging);
  EXPECT_GT(t.build_waited, 0.0);
  // The device's own clock, pass by pass, in the order they run: each
  // interval lies on the device's timeline apart from the others, within
  // the run; the judge's and the reconstruction's always take some time,
  // and so does the sample pass where the device draws.
  const auto [names, device_total] = NamesAndTotal(t.device_passes, /*each_positive=*/false);
  // Fused (by request, or by default on a GPU), the reconstruction runs in
  // the judge's phase 0, and the interval before the judge's submission is
  // a wait.
  const bool fused = tuning.fusion == JudgeFusion::kFused ||
                     (tuning.fusion == JudgeFusion::kAuto &&
                      DeviceJudgeTest::Context()->properties().type != VK_PHYSICAL_DEVICE_TYPE_CPU);
  const std::string reconstruction = fused ? "reconstruction+judge" : "reconstruction";
  const std::string judge = fused ? "reconstruction+judge" : "judge";
  const std::vector<std::string> expected =
      fused ? std::vector<std::string>{"idle", "sample", "store", "wait", "reference", "reconstruction+judge", "maxima"}
            : std::vector<std::string>{"idle", "sample", "store", "reconstruction", "reference", "judge", "maxima"};
  EXPECT_EQ(names, expected);
  EXPECT_LE(device_total, device->run.seconds);
  const auto seconds_of = [&](const std::string& pass) {
    return std::find_if(t.device_passes.begin(), t.device_passes.end(), [&](const auto& p) { return p.first == pass; })
        ->second;
  };
  EXPECT_GT(seconds_of(judge), 0.0);
  EXPECT_GT(seconds_of(reconstruction), 0.0);
  if (device_draws) {
    EXPECT_GT(seconds_of("sample"), 0.0);
  }
  // They reach the results file and come back from it, in order.
  auto read = ResultsFromJson(ToJson(*device), "device.json");
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(read->run.stages.device_passes, t.device_passes);
  EXPECT_EQ(read->run.stages.judge_host_steps, t.judge_host_steps);
  // The judge's thread: its steps in order, each some time, within the
  // judging they make up.
  const auto [steps, host_total] = NamesAndTotal(t.judge_host_steps, /*each_positive=*/true);
  EXPECT_EQ(steps, (std::vector<std::string>{"finish", "upload", "stage", "queue"}));
  EXPECT_LE(host_total, t.judging);
  const Reached reached = ExpectSameCells(*host, *device);
  // The comparison means something only where the run reached these.
  EXPECT_GT(reached.judged, 100000u);
  EXPECT_GT(reached.stored_nonfinite, 0u);
  EXPECT_GT(reached.degenerate + reached.outside, 0u);
  EXPECT_GT(reached.maxima, 1000u);
}

// Either way of adding bins on the device (lavapipe's default is the
// device's counters; a GPU's, the workgroup's table first). In the wide
// domain the table overflows for about a seventh of the bins, so its
// fallback to the device's counters runs too. And either way of finding
// the index of each maximum: from the candidates phase 0 lists, or, with
// no room for one, by judging every accumulator again. And either way of
// drawing the samples: on the device (the default) or on the host
// (`run --draw host`). And either way of reconstructing: the backend's
// pass apart (lavapipe's default), or fused into the judge's program (a
// GPU's), where phase 1 with no candidates reconstructs again, and where
// the host uploads the pixels the next batch's upload would overwrite.
TEST_F(DeviceJudgeTest, RecordsWhatTheHostJudgeRecordsInTheWideDomain) {
  ExpectSameStatistics(WideDomain(), "wide, device counters, drawn on the host",
                       {.bins = JudgeBinMerge::kDeviceCounters}, /*device_draws=*/false);
  ExpectSameStatistics(WideDomain(), "wide, workgroup table, no candidates",
                       {.bins = JudgeBinMerge::kWorkgroupTable, .candidates_per_row = 0});
  ExpectSameStatistics(
      WideDomain(), "wide, fused, workgroup table, no candidates, drawn on the host",
      {.bins = JudgeBinMerge::kWorkgroupTable, .fusion = JudgeFusion::kFused, .candidates_per_row = 0},
      /*device_draws=*/false);
}

// Batches of 1000 samples leave each of a workgroup's 1024 lanes (the
// table's shape on lavapipe, as on a GPU) one sample at most. Batches of
// 7000 (7000, 7000 and 1000 samples of the shard's 15000) give a lane
// seven samples in turn, as a GPU's batches of 262144 give it sixteen: the
// loop over a lane's samples, and the table and maxima kept across them,
// are judged too.
TEST_F(DeviceJudgeTest, RecordsWhatTheHostJudgeRecordsWhereALaneJudgesSeveralSamples) {
  ExpectSameStatistics(WideDomain(), "wide, workgroup table, batches of 7000", {.bins = JudgeBinMerge::kWorkgroupTable},
                       /*device_draws=*/true, /*batch_size=*/7000);
  ExpectSameStatistics(WideDomain(), "wide, fused, workgroup table, batches of 7000",
                       {.bins = JudgeBinMerge::kWorkgroupTable, .fusion = JudgeFusion::kFused},
                       /*device_draws=*/true, /*batch_size=*/7000);
}

TEST_F(DeviceJudgeTest, RecordsWhatTheHostJudgeRecordsInTheExtremesDomain) {
  ExpectSameStatistics(ExtremesDomain(), "extremes, device counters, no candidates",
                       {.bins = JudgeBinMerge::kDeviceCounters, .candidates_per_row = 0});
  ExpectSameStatistics(ExtremesDomain(), "extremes, workgroup table", {.bins = JudgeBinMerge::kWorkgroupTable});
  ExpectSameStatistics(ExtremesDomain(), "extremes, fused, device counters",
                       {.bins = JudgeBinMerge::kDeviceCounters, .fusion = JudgeFusion::kFused});
}

// An off-centre lens (a VR eye, with TAA jitter on top): the device draws
// each pixel's ray through the frame's centre as the host does.
TEST_F(DeviceJudgeTest, RecordsWhatTheHostJudgeRecordsThroughAnOffCentreLens) {
  Domain domain = WideDomain();
  domain.eye_fov = EyeFov{-52.0, 43.0, 47.0, -53.0};
  domain.jitter = 0.5;
  ExpectSameStatistics(domain, "wide, an off-centre eye with jitter", {.bins = JudgeBinMerge::kDeviceCounters});
}

// One batch of `domain` (every cell it allows), its reference computed by
// the host (in `batch`) and by the device (returned), which draws the
// samples itself where it can (float32 production: BatchFor::kDeviceDraws),
// so that the comparison covers its draw too.
struct TwoReferences {
  RunLayout layout;
  Batch batch;
  ReferenceArrays device;
};
void ComputeBothReferences(const Domain& domain, TwoReferences& out) {
  const std::shared_ptr<VulkanContext>& context = DeviceJudgeTest::Context();
  out.layout = MakeRunLayout(CellsForDomain(AllCells(), domain));
  auto vulkan = MakeVulkanBackend(context, BackendOptions{});
  ASSERT_TRUE(vulkan.ok()) << vulkan.status().message();
  ASSERT_TRUE((*vulkan)->Prepare(out.layout.cells, PassKind::kCompute).ok());
  auto judge = DeviceJudge::Create(**vulkan, out.layout, domain.production, true);
  ASSERT_TRUE(judge.ok()) << judge.status().message();
  const Sampler sampler(3, domain);
  const BatchBuilder builder(sampler, out.layout.encodings);
  ThreadPool pool(2);
  DeviceJudgeInputs inputs;
  builder.Build(1000000037, 6000, out.batch, pool, BatchFor::kHostJudge, &inputs);  // starts inside a frame
  Batch frames_only;
  DeviceJudgeInputs draw_inputs;
  if (builder.DevicesCanDraw()) {
    builder.Build(1000000037, 6000, frames_only, pool, BatchFor::kDeviceDraws, &draw_inputs);
  }
  std::vector<CellAccumulator> accumulators(out.layout.cells.size());
  const bool drawn_on_device = draw_inputs.draw_seed.has_value();
  const Status judged = (*judge)->Judge(drawn_on_device ? frames_only : out.batch,
                                        drawn_on_device ? draw_inputs : inputs, accumulators, {}, pool);
  ASSERT_TRUE(judged.ok()) << judged.message();
  auto device = (*judge)->LastReference();
  ASSERT_TRUE(device.ok()) << device.status().message();
  out.device = std::move(device).value();
  EXPECT_TRUE(context->TakeValidationMessages().empty());
}

// The device's reference against the host's, element by element and bit
// for bit: the first differences are named.
void ExpectSameReference(const Domain& domain, const std::string& name) {
  SCOPED_TRACE(name);
  TwoReferences both;
  ComputeBothReferences(domain, both);
  const ReferenceArrays &host = both.batch.reference, &device = both.device;
  ASSERT_EQ(device.true_depth.size(), host.true_depth.size());
  const auto same = [](double a, double b) {
    return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
  };
  std::size_t differing = 0, judged = 0;
  for (std::size_t r = 0; r < host.true_depth.size(); ++r) {
    const bool equal =
        same(host.true_depth[r], device.true_depth[r]) && same(host.denoted_depth[r], device.denoted_depth[r]) &&
        same(host.inverse_distance_sq[r], device.inverse_distance_sq[r]) &&
        same(host.storage_square[r], device.storage_square[r]) &&
        same(host.production_square[r], device.production_square[r]) && host.joint_band[r] == device.joint_band[r] &&
        host.status[r] == device.status[r] && host.stored_holdable[r] == device.stored_holdable[r];
    judged += host.status[r] == ReferenceStatus::kJudged ? 1 : 0;
    if (!equal && differing++ < 5) {
      const Encoding e = both.layout.encodings[r / both.batch.count];
      ADD_FAILURE() << Info(e.convention).name << "/" << Info(e.format).name << ", sample " << r % both.batch.count
                    << fmt::format(
                           ": true {} / {}, denoted {} / {}, inverse {} / {}, storage {} / {}, production "
                           "{} / {}, band {} / {}, status {} / {}, holdable {} / {}",
                           host.true_depth[r], device.true_depth[r], host.denoted_depth[r], device.denoted_depth[r],
                           host.inverse_distance_sq[r], device.inverse_distance_sq[r], host.storage_square[r],
                           device.storage_square[r], host.production_square[r], device.production_square[r],
                           host.joint_band[r], device.joint_band[r], static_cast<int>(host.status[r]),
                           static_cast<int>(device.status[r]), host.stored_holdable[r], device.stored_holdable[r]);
    }
  }
  EXPECT_EQ(differing, 0u);
  EXPECT_GT(judged, host.true_depth.size() / 2);
}

// Far/near 1e9 with depths produced exactly or in float32, where a decode
// near the far plane cancels 30 bits in any precision unless it is written
// without the cancellation (shared/depth_mapping.h).
Domain FarOverNear1e9(ProductionModel production) {
  Domain domain = WideDomain();
  domain.ratio = {1e9, 1e9};
  domain.production = production;
  return domain;
}

TEST_F(DeviceJudgeTest, ComputesTheHostsReference) {
  ExpectSameReference(TypicalDomain(), "typical");
  ExpectSameReference(WideDomain(), "wide");
  ExpectSameReference(ExtremesDomain(), "extremes");
  ExpectSameReference(FarOverNear1e9(ProductionModel::kFloat32), "f/n 1e9");
  ExpectSameReference(FarOverNear1e9(ProductionModel::kExact), "f/n 1e9, exact production");
}

// The device's decode of stored window depths at far/near 1e9 against
// MPFR's (400 bits) evaluation of the same mapping: the device keeps the
// double nearest the double-double, so it may be off by half an ulp of a
// double (2^-53) plus the double-double's own error (below 2^-96, as
// tests/reference_test.cc shows on the host): 2^-52 bounds both, 29 bits
// below float32's rounding. A textbook decode B / (d - A) in double would
// miss it by up to 2^-23 near the far plane.
// Float32 values where storing is hardest to get right: each side of
// every rounding midpoint of the halves (subnormal ones included) and of
// the unorm steps near 0 and 1, the limits of each format, and what lies
// outside [0, 1]: negative values, NaN, infinities, float32 subnormals.
std::vector<float> HardValuesToStore() {
  std::vector<float> values;
  const auto around = [&](float x) {
    values.push_back(std::nextafter(x, -INFINITY));
    values.push_back(x);
    values.push_back(std::nextafter(x, INFINITY));
  };
  for (std::uint16_t h = 0; h < 0x7bff; ++h) {
    const float low = HalfToFloat(h), high = HalfToFloat(static_cast<std::uint16_t>(h + 1));
    around(low + (high - low) / 2);  // exact: twelve significant bits
  }
  for (const double scale : {65535.0, 16777215.0}) {
    for (int k = 0; k < 2000; ++k) {
      around(static_cast<float>((k + 0.5) / scale));
      around(static_cast<float>((scale - 1 - k + 0.5) / scale));
    }
  }
  for (const float x : {0.0f, 1.0f, 1.5f, 65504.0f, 65520.0f, 1e30f, 0x1p-25f, 0x1p-24f, 0x1p-14f,
                        std::numeric_limits<float>::min(), std::numeric_limits<float>::denorm_min()}) {
    around(x);
    around(-x);
  }
  for (const float x : {INFINITY, -INFINITY, NAN, -NAN}) values.push_back(x);
  return values;
}

// The storage pass against encode.cc's StoreFloats, texel for texel, on
// the hard values in every pipeline: the picks keep the host's texels.
// (Under exact production the host's floats are uploaded, so the test
// can choose them.)
TEST_F(DeviceJudgeTest, StoresEveryFormatAsTheHostDoes) {
  const std::shared_ptr<VulkanContext>& context = Context();
  Domain domain = TypicalDomain();
  domain.production = ProductionModel::kExact;
  // One cell per encoding: every depth slot, in what lavapipe binds at once.
  std::vector<Cell> cells;
  for (const Cell& cell : CellsForDomain(AllCells(), domain)) {
    const auto same = [&](const Cell& c) { return c.encoding() == cell.encoding(); };
    if (std::none_of(cells.begin(), cells.end(), same)) cells.push_back(cell);
  }
  const RunLayout layout = MakeRunLayout(cells);
  ASSERT_GE(layout.encodings.size(), 20u);
  auto vulkan = MakeVulkanBackend(context, BackendOptions{});
  ASSERT_TRUE(vulkan.ok()) << vulkan.status().message();
  ASSERT_TRUE((*vulkan)->Prepare(layout.cells, PassKind::kCompute).ok());
  auto judge = DeviceJudge::Create(**vulkan, layout, domain.production, true);
  ASSERT_TRUE(judge.ok()) << judge.status().message();
  const std::vector<float> values = HardValuesToStore();
  const auto count = static_cast<std::uint32_t>(values.size());
  const Sampler sampler(5, domain);
  ThreadPool pool(2);
  Batch batch;
  DeviceJudgeInputs inputs;
  const BatchBuilder builder(sampler, layout.encodings);
  builder.Build(7, count, batch, pool, BatchFor::kDeviceJudge, &inputs);
  EXPECT_FALSE(inputs.draw_seed.has_value());
  // The stored-value picks' texels, per frame and slot, are those a batch
  // for the host judge stores for each pick.
  const std::size_t slots = layout.encodings.size();
  ASSERT_EQ(inputs.edge_texels.size(), batch.frames.size() * slots * 4);
  const auto edge_texel = [&](std::size_t slot, std::uint32_t i) {
    const auto pick = static_cast<std::size_t>(batch.samples.pick[i]);
    return inputs.edge_texels[(batch.FrameOf(i) * slots + slot) * 4 + pick - 1];
  };
  Batch for_host;
  DeviceJudgeInputs for_host_inputs;
  builder.Build(7, count, for_host, pool, BatchFor::kHostJudge, &for_host_inputs);
  ASSERT_EQ(for_host_inputs.edge_texels, inputs.edge_texels);
  std::size_t picks = 0;
  for (std::uint32_t i = 0; i < count; ++i) {
    if (batch.samples.pick[i] == DepthPick::kEyeDepth) continue;
    ++picks;
    for (std::size_t slot = 0; slot < slots; ++slot) {
      ASSERT_EQ(std::bit_cast<std::uint32_t>(for_host.depths[slot * count + i]),
                std::bit_cast<std::uint32_t>(edge_texel(slot, i)));
    }
  }
  // A batch for the device judge holds no texels (the storage pass makes
  // them), so a run that reads the host's is refused, saying why.
  EXPECT_EQ(batch.depth_slots, layout.encodings.size());
  EXPECT_TRUE(batch.depths.empty());
  EXPECT_TRUE(batch.codes.empty());
  // Where the device produces the depths too (float32 production), the
  // batch holds of its samples only what was drawn, the host judge's
  // batch's, and the same rays; not what the reference derives from the
  // frame and the ray.
  {
    const Sampler float32_sampler(5, TypicalDomain());
    const BatchBuilder float32_builder(float32_sampler, layout.encodings);
    Batch lean, full;
    DeviceJudgeInputs lean_inputs;
    float32_builder.Build(7, count, lean, pool, BatchFor::kDeviceJudge, &lean_inputs);
    float32_builder.Build(7, count, full, pool, BatchFor::kHostJudge);
    EXPECT_TRUE(lean.samples.near.empty());
    EXPECT_TRUE(lean.samples.inverse_distance_sq.empty());
    EXPECT_EQ(full.samples.near.size(), count);
    EXPECT_EQ(lean.samples.eye_depth, full.samples.eye_depth);
    EXPECT_EQ(lean.samples.coverage, full.samples.coverage);
    EXPECT_EQ(lean.ray_x, full.ray_x);
    EXPECT_EQ(lean.ray_z, full.ray_z);
    // Where the device draws the samples, the batch holds none of them,
    // and its inputs hold the sampler's seed to draw them from.
    Batch frames_only;
    DeviceJudgeInputs draw_inputs;
    ASSERT_TRUE(float32_builder.DevicesCanDraw());
    float32_builder.Build(7, count, frames_only, pool, BatchFor::kDeviceDraws, &draw_inputs);
    EXPECT_EQ(draw_inputs.draw_seed, std::optional<std::uint64_t>(5));
    EXPECT_TRUE(frames_only.samples.pick.empty());
    EXPECT_TRUE(frames_only.pixels.empty());
    EXPECT_TRUE(frames_only.ray_x.empty());
    EXPECT_EQ(frames_only.frames.size(), lean.frames.size());
    EXPECT_EQ(draw_inputs.edge_texels, lean_inputs.edge_texels);
    // Without inputs to carry the seed, nothing is drawn on the device.
    Batch not_drawn;
    float32_builder.Build(7, count, not_drawn, pool, BatchFor::kDeviceDraws);
    EXPECT_EQ(not_drawn.samples.pick.size(), count);
    // Exact production needs the host's floats: no device draws there.
    EXPECT_FALSE(builder.DevicesCanDraw());
  }
  std::vector<float> scratch;
  auto host_texels = (*vulkan)->Run(batch, std::vector<std::uint32_t>{0}, scratch);
  ASSERT_FALSE(host_texels.ok());
  EXPECT_NE(host_texels.status().message().find("0 stored depths"), std::string::npos)
      << host_texels.status().message();
  // Nor may a cell read a depth slot past the batch's, texels or not.
  Batch one_slot = for_host;
  one_slot.depth_slots = 1;
  one_slot.depths.resize(count);
  const auto last = static_cast<std::uint32_t>(layout.cells.size() - 1);
  ASSERT_GT(layout.cells[last].depth_slot, 0u);
  auto past = (*vulkan)->Run(one_slot, std::vector<std::uint32_t>{last}, scratch);
  ASSERT_FALSE(past.ok());
  EXPECT_NE(past.status().message().find("reads depth slot"), std::string::npos) << past.status().message();
  for (std::size_t at = 0; at < batch.pipeline_floats.size(); ++at) batch.pipeline_floats[at] = values[at % count];
  std::vector<CellAccumulator> accumulators(layout.cells.size());
  const Status judged = (*judge)->Judge(batch, inputs, accumulators, {}, pool);
  ASSERT_TRUE(judged.ok()) << judged.message();
  auto texels = (*judge)->LastTexels();
  ASSERT_TRUE(texels.ok()) << texels.status().message();
  ASSERT_EQ(texels->size(), layout.encodings.size() * count);
  std::size_t differing = 0;
  for (std::size_t slot = 0; slot < layout.encodings.size(); ++slot) {
    const Format format = layout.encodings[slot].format;
    for (std::uint32_t i = 0; i < count; ++i) {
      const bool pick = batch.samples.pick[i] != DepthPick::kEyeDepth;
      const float expected = pick ? edge_texel(slot, i) : StoreFloat(format, values[i]).fetched;
      const float device = (*texels)[slot * count + i];
      if (std::bit_cast<std::uint32_t>(expected) != std::bit_cast<std::uint32_t>(device) && differing++ < 5) {
        ADD_FAILURE() << fmt::format("{}, sample {} (pick {}): {:a} stored as {:a} on the host, {:a} on the device",
                                     Info(format).name, i, pick, values[i], expected, device);
      }
    }
  }
  EXPECT_EQ(differing, 0u);
  EXPECT_GT(picks, 0u);  // both kinds of texel were stored
  EXPECT_TRUE(context->TakeValidationMessages().empty());
}

TEST_F(DeviceJudgeTest, ItsDecodeAgreesWithMpfrAtFarOverNear1e9) {
  TwoReferences both;
  ComputeBothReferences(FarOverNear1e9(ProductionModel::kExact), both);
  const Batch& batch = both.batch;
  double worst = 0.0;
  std::size_t checked = 0, near_far_plane = 0;
  for (std::size_t s = 0; s < both.layout.encodings.size(); ++s) {
    const Encoding e = both.layout.encodings[s];
    if (Info(e.format).stores != DepthInput::kHardware) continue;
    const std::uint32_t bits = Info(e.convention).bits;
    for (std::size_t i = 0; i < batch.count; ++i) {
      const std::size_t r = s * batch.count + i;
      const double denoted = both.device.denoted_depth[r];
      if (!(denoted > 0.0) || denoted == std::numeric_limits<double>::max()) continue;
      const mp::real d(static_cast<double>(batch.depths[r]));
      const mp::real exact = mp::eye_depth_from_window_depth(
          mp::real(batch.samples.near[i]), mp::real(batch.samples.far[i]), bits, d, mp::real(1.0) - d);
      worst = std::max(worst, std::fabs(((mp::real(denoted) - exact) / exact).ToDouble()));
      ++checked;
      near_far_plane += denoted > 0.5 * batch.samples.depth_limit[i] ? 1 : 0;
    }
  }
  EXPECT_LE(worst, std::ldexp(1.0, -52));
  EXPECT_GT(checked, 10000u);
  EXPECT_GT(near_far_plane, 1000u);  // the last doubling, where the cancellation would be
}

// The comparison above can fail: a different sample population (another
// seed) changes the statistics the device judge records.
TEST_F(DeviceJudgeTest, AnotherSeedRecordsOtherStatistics) {
  SweepOptions options = Options(WideDomain());
  auto first = Sweep(options, JudgeSite::kDevice);
  options.seed = 8;
  auto second = Sweep(options, JudgeSite::kDevice);
  ASSERT_TRUE(first.ok() && second.ok());
  std::size_t differing = 0;
  for (std::size_t c = 0; c < first->cells.size(); ++c)
    differing += first->cells[c].stats == second->cells[c].stats ? 0 : 1;
  EXPECT_EQ(differing, first->cells.size());
}

// The judge's widest binding (five doubles per depth slot and sample)
// outgrows the device's limit before the backend's do when cells are few
// and depth slots many: divide alone reads 24 slots with 24 cells. A batch
// asked for larger is cut to what the judge binds (lavapipe binds 128 MiB:
// 2^22 samples would need 3.8 GiB), or the validation layer objects.
TEST_F(DeviceJudgeTest, CutsABatchToWhatTheDeviceBinds) {
  SweepOptions options = Options(TypicalDomain());
  options.cells = {};
  for (const Cell& cell : AllCells()) {
    if (cell.variant == Variant::kDivide) options.cells.push_back(cell);
  }
  options.samples = 300000;
  options.shard = {};
  options.batch_size = 1u << 22;
  auto run = Sweep(options, JudgeSite::kDevice);
  ASSERT_TRUE(run.ok()) << run.status().message();
  EXPECT_EQ(run->run.samples_judged, 300000u);
}

TEST_F(DeviceJudgeTest, TheCpuBackendHasNoDeviceToJudgeOn) {
  SweepOptions options = Options(TypicalDomain());
  options.samples = 3000;
  auto cpu = MakeCpuBackend();
  Backend* backends[] = {cpu.get()};
  options.judge = JudgeSite::kDevice;
  auto refused = RunSweep(options, backends);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("no device to judge on"), std::string::npos) << refused.status().message();
  options.judge = JudgeSite::kAuto;  // judged on the host
  EXPECT_TRUE(RunSweep(options, backends).ok());
}

// The raster form judged on its device: the texels its rasterizer stored,
// fetched, each marked drawn or not, and judged against the reference the
// device computes from them; the host judge adopts the same texels. At
// f/n 1e4 with the camera at the origin a few triangles within a float32
// step of the far plane fail the depth test and leave their texel
// uncovered (undrawn), and the samples that pick a stored value have no
// geometry (degenerate): each path is reached and counted alike. Eight
// threads give the judging stage two (sweep_plan.cc), so that pass 2a is
// recorded on both, each a share of the window's blocks
// (RasterPass::RecordCapturesInParallel), whatever cores the machine has.
TEST_F(DeviceJudgeTest, RecordsWhatTheHostJudgeRecordsInTheRasterForm) {
  SweepOptions options = Options(TypicalDomain());
  options.samples = 300000;
  options.threads = 8;
  options.domain.ratio = {1e4, 1e4};
  options.domain.infinite_far = false;
  options.domain.camera_distance = {0.0, 0.0};
  options.domain.production = ProductionModel::kRaster;
  for (const char* name : {"frustum_ray/linear/r32f", "volume_ray/linear/r16f", "eye_ray/linear/viewz",
                           "reciprocal/standard/d24", "pq/reversed/d32f"}) {
    const Expected<Cell> cell = ParseCell(name);
    ASSERT_TRUE(cell.ok()) << cell.status().message();
    options.cells.push_back(*cell);
  }
  auto host = Sweep(options, JudgeSite::kHost);
  auto device = Sweep(options, JudgeSite::kDevice);
  ASSERT_TRUE(host.ok()) << host.status().message();
  ASSERT_TRUE(device.ok()) << device.status().message();
  EXPECT_EQ(device->run.backends.at(0).judge, JudgedOn::kDevice);
  // The device's texels, counted against the host's model by the run
  // that judged them, as the host's run counts them.
  EXPECT_EQ(device->run.backends.at(0).raster_agreement, host->run.backends.at(0).raster_agreement);
  // The raster submission's parts, each timed: every one does work.
  std::vector<std::string> passes;
  for (const auto& [pass, seconds] : device->run.stages.device_passes) {
    passes.push_back(pass);
    if (pass == "depth" || pass == "attributes" || pass == "reconstruction") {
      EXPECT_GT(seconds, 0.0) << pass;
    }
  }
  EXPECT_EQ(passes, (std::vector<std::string>{"idle", "sample", "store", "depth", "fetch", "attributes",
                                              "reconstruction", "no geometry", "raster idle", "reference", "judge",
                                              "maxima"}));
  const Reached reached = ExpectSameCells(*host, *device);
  EXPECT_GT(reached.judged, 400000u);
  EXPECT_GT(reached.degenerate, 0u);
  EXPECT_GT(reached.undrawn, 0u);
  EXPECT_GT(reached.maxima, 100u);
}

// Beside another backend, the raster form's rendered texels are the stored
// values of all of them, adopted and judged on the host: asking for the
// device judge there is refused (auto judges on the host).
TEST_F(DeviceJudgeTest, TheRasterFormBesideAnotherBackendIsJudgedOnTheHost) {
  SweepOptions options = Options(TypicalDomain());
  options.samples = 3000;
  options.domain.production = ProductionModel::kRaster;
  auto vulkan = MakeVulkanBackend(Context(), BackendOptions{});
  ASSERT_TRUE(vulkan.ok()) << vulkan.status().message();
  auto cpu = MakeCpuBackend();
  Backend* backends[] = {vulkan->get(), cpu.get()};
  options.judge = JudgeSite::kDevice;
  auto refused = RunSweep(options, backends);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(refused.status().message().find("only where it is the run's one backend"), std::string::npos)
      << refused.status().message();
  EXPECT_TRUE(Context()->TakeValidationMessages().empty());
}

// shared/judge.h's packed words, field by field. A word's fields, as
// numbers (a flag as 0 or 1), and the largest each holds.
template <std::size_t N>
struct PackedWord {
  std::uint32_t (*pack)(const std::array<std::uint32_t, N>&);
  std::array<std::uint32_t, N> (*fields)(std::uint32_t);
  std::array<std::uint32_t, N> largest;
};

// Every field comes back as it went in, alone or with the others, at 0, at
// 1 and at its largest value; a field at its largest sets no bit that
// another field's does; and a field given all 32 bits keeps to its own
// (reading as its largest value) and leaves the others at 0.
template <std::size_t N>
void ExpectFieldsRoundTrip(const PackedWord<N>& word) {
  const std::array<std::uint32_t, N> zeros{};
  EXPECT_EQ(word.pack(zeros), 0u);
  EXPECT_EQ(word.fields(word.pack(zeros)), zeros);
  EXPECT_EQ(word.fields(word.pack(word.largest)), word.largest);
  std::uint32_t union_of_fields = 0;
  for (std::size_t f = 0; f < N; ++f) {
    SCOPED_TRACE(fmt::format("field {}", f));
    for (const std::uint32_t value : {1u, word.largest[f]}) {
      std::array<std::uint32_t, N> alone{};
      alone[f] = value;
      EXPECT_EQ(word.fields(word.pack(alone)), alone);
      std::array<std::uint32_t, N> with_others = word.largest;
      with_others[f] = value;
      EXPECT_EQ(word.fields(word.pack(with_others)), with_others);
    }
    std::array<std::uint32_t, N> alone{};
    alone[f] = word.largest[f];
    const std::uint32_t bits = word.pack(alone);
    EXPECT_EQ(bits & union_of_fields, 0u) << fmt::format("{:#010x} overlaps {:#010x}", bits, union_of_fields);
    union_of_fields |= bits;
    std::array<std::uint32_t, N> all_ones{};
    all_ones[f] = 0xffffffffu;
    EXPECT_EQ(word.fields(word.pack(all_ones)), alone);
  }
  EXPECT_EQ(union_of_fields, word.pack(word.largest));
}

namespace W = judge_words;

TEST(DeviceJudgeWords, TheEncodingWordKeepsEachField) {
  ExpectFieldsRoundTrip(PackedWord<5>{
      [](const std::array<std::uint32_t, 5>& f) { return W::db_encoding_word(f[0], f[1], f[2], f[3] != 0, f[4]); },
      [](std::uint32_t w) {
        return std::array<std::uint32_t, 5>{W::db_encoding_stores(w), W::db_encoding_convention(w),
                                            W::db_encoding_hardware(w), W::db_encoding_infinite_far(w) ? 1u : 0u,
                                            W::db_encoding_pipeline(w)};
      },
      {0xfu, 0xfu, 0xfu, 1u, 0xffffu}});
}

TEST(DeviceJudgeWords, TheTexelWordKeepsEachField) {
  ExpectFieldsRoundTrip(
      PackedWord<2>{[](const std::array<std::uint32_t, 2>& f) { return W::db_texel_word(f[0], f[1]); },
                    [](std::uint32_t w) {
                      return std::array<std::uint32_t, 2>{W::db_texel_kind(w), W::db_texel_unorm_bits(w)};
                    },
                    {0xffu, 0xffffffu}});
}

TEST(DeviceJudgeWords, TheCoverageWordKeepsEachField) {
  ExpectFieldsRoundTrip(
      PackedWord<2>{[](const std::array<std::uint32_t, 2>& f) { return W::db_coverage_word(f[0], f[1]); },
                    [](std::uint32_t w) {
                      return std::array<std::uint32_t, 2>{W::db_coverage_kind(w), W::db_coverage_pick(w)};
                    },
                    {0xffu, 0xffffffu}});
}

TEST(DeviceJudgeWords, TheReferenceInfoWordKeepsEachField) {
  ExpectFieldsRoundTrip(PackedWord<3>{
      [](const std::array<std::uint32_t, 3>& f) { return W::db_reference_info_word(f[0], f[1], f[2] != 0); },
      [](std::uint32_t w) {
        return std::array<std::uint32_t, 3>{W::db_reference_info_joint_band(w), W::db_reference_info_status(w),
                                            W::db_reference_info_stored_holdable(w) ? 1u : 0u};
      },
      {0xffu, 0xffu, 1u}});
}

// The workgroup's shape from the device's limits alone. A GPU gets the
// table of bins as large as fits beside judge.glsl's word per (slot,
// metric) of running maxima: 4096 entries where a workgroup may hold 48 KiB
// or 32 KiB (lavapipe's limit), 2048 where only the 16 KiB Vulkan
// guarantees (4096 entries and the 369 words would need 17860 bytes). A
// CPU device adds to the device's counters directly, in groups of 64.
VulkanDeviceProperties DeviceWithLimits(VkPhysicalDeviceType type, std::uint32_t shared_bytes,
                                        std::uint32_t invocations) {
  VulkanDeviceProperties device;
  device.type = type;
  device.limits.maxComputeSharedMemorySize = shared_bytes;
  device.limits.maxComputeWorkGroupInvocations = invocations;
  device.limits.maxComputeWorkGroupSize[0] = invocations;
  return device;
}

TEST(JudgeGroupsTest, TheTableFillsWhatSharedMemoryHoldsBesideTheMaxima) {
  const std::uint32_t maxima_words = W::DB_JUDGE_SLOTS * W::DB_JUDGE_METRICS;
  for (const auto& [shared_bytes, entries] : {std::pair{49152u, 4096u}, {32768u, 4096u}, {16384u, 2048u}}) {
    SCOPED_TRACE(shared_bytes);
    const JudgeGroups groups =
        ChooseJudgeGroups(DeviceWithLimits(VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, shared_bytes, 1024), {});
    EXPECT_EQ(groups.use_table, VK_TRUE);
    EXPECT_EQ(groups.table_entries, entries);
    EXPECT_EQ(JudgeSharedWords(groups), entries + maxima_words);
    EXPECT_LE(JudgeSharedWords(groups) * 4, shared_bytes);
    EXPECT_EQ(groups.invocations, 1024u);
    EXPECT_EQ(groups.samples, 16384u);  // below 2^15, what a table entry counts
  }
  // Fewer invocations than 1024 where the device allows fewer.
  EXPECT_EQ(ChooseJudgeGroups(DeviceWithLimits(VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, 16384, 256), {}).invocations,
            256u);
}

TEST(JudgeGroupsTest, ACpuDeviceAddsToTheDevicesCounters) {
  const JudgeGroups cpu = ChooseJudgeGroups(DeviceWithLimits(VK_PHYSICAL_DEVICE_TYPE_CPU, 32768, 1024), {});
  EXPECT_EQ(cpu.use_table, VK_FALSE);
  EXPECT_EQ(cpu.invocations, 64u);
  EXPECT_EQ(cpu.samples, 64u);
  // Either choice can be asked for.
  EXPECT_EQ(ChooseJudgeGroups(DeviceWithLimits(VK_PHYSICAL_DEVICE_TYPE_CPU, 32768, 1024),
                              {.bins = JudgeBinMerge::kWorkgroupTable})
                .use_table,
            VK_TRUE);
  EXPECT_EQ(ChooseJudgeGroups(DeviceWithLimits(VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, 49152, 1024),
                              {.bins = JudgeBinMerge::kDeviceCounters})
                .use_table,
            VK_FALSE);
}

}  // namespace
}  // namespace depthbench
