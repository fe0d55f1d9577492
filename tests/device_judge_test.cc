// The judge on the device (bench/device_judge/) against the host judge, on
// lavapipe: for a fixed seed both must record the same statistics, bin for
// bin, count for count, maximum and worst index included. The runs are
// chosen to reach everything the judge records: the wide and extremes
// domains (non-finite outputs by every cause, samples outside the frustum
// and degenerate ones, every coverage kind), camera-distance bands
// recorded sample by sample, batches that start and end inside frames,
// and flushes in the middle of the run.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bench/backends/cpu/cpu_backend.h"
#include "bench/backends/vulkan/vulkan_backend.h"
#include "bench/sweep/sweep.h"

namespace depthbench {
namespace {

class DeviceJudgeTest : public ::testing::Test {
 public:
  static void SetUpTestSuite() {
    VulkanContextOptions options;
    options.validation = true;
    auto context = VulkanContext::Create(options);
    ASSERT_TRUE(context.ok()) << context.status().message();
    context_ = new std::shared_ptr<VulkanContext>(std::move(context).value());
  }
  static void TearDownTestSuite() { delete context_; }

  // A sweep of shard 2/3 (its first sample lies inside a frame) in batches
  // of 1000 samples (not whole frames), flushed every 5000 samples.
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

  static std::shared_ptr<VulkanContext>* context_;
};
std::shared_ptr<VulkanContext>* DeviceJudgeTest::context_ = nullptr;

// What the comparison covered, summed over every cell and band.
struct Reached {
  std::uint64_t judged = 0, findings = 0, stored_nonfinite = 0, degenerate = 0, outside = 0, maxima = 0;
  void Add(const std::map<int, BandStats>& bands) {
    for (const auto& [band, stats] : bands) {
      judged += stats.finite;
      findings += stats.nan + stats.inf;
      stored_nonfinite += stats.stored_nonfinite;
      degenerate += stats.degenerate;
      outside += stats.outside;
      for (Metric m : {Metric::kTotal, Metric::kArith, Metric::kAbsolute}) {
        maxima += stats[m].worst_index != std::numeric_limits<std::uint64_t>::max() ? 1 : 0;
      }
    }
  }
};

void ExpectSameStatistics(const Domain& domain, const std::string& name) {
  SCOPED_TRACE(name);
  auto host = DeviceJudgeTest::Sweep(DeviceJudgeTest::Options(domain), JudgeSite::kHost);
  auto device = DeviceJudgeTest::Sweep(DeviceJudgeTest::Options(domain), JudgeSite::kDevice);
  ASSERT_TRUE(host.ok()) << host.status().message();
  ASSERT_TRUE(device.ok()) << device.status().message();
  ASSERT_EQ(host->cells.size(), device->cells.size());
  Reached reached;
  for (std::size_t c = 0; c < host->cells.size(); ++c) {
    const CellStats& a = host->cells[c].stats;
    const CellStats& b = device->cells[c].stats;
    EXPECT_TRUE(a == b) << host->cells[c].cell.Name();
    reached.Add(b.joint);
    reached.Add(b.distance);
    reached.Add(b.coverage);
  }
  // The comparison means something only where the run reached these.
  EXPECT_GT(reached.judged, 100000u);
  EXPECT_GT(reached.stored_nonfinite, 0u);
  EXPECT_GT(reached.degenerate + reached.outside, 0u);
  EXPECT_GT(reached.maxima, 1000u);
}

TEST_F(DeviceJudgeTest, RecordsWhatTheHostJudgeRecordsInTheWideDomain) {
  ExpectSameStatistics(WideDomain(), "wide");
}

TEST_F(DeviceJudgeTest, RecordsWhatTheHostJudgeRecordsInTheExtremesDomain) {
  ExpectSameStatistics(ExtremesDomain(), "extremes");
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
  for (std::size_t c = 0; c < first->cells.size(); ++c) differing += first->cells[c].stats == second->cells[c].stats ? 0 : 1;
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
  EXPECT_NE(refused.status().message().find("no device to judge on"), std::string::npos)
      << refused.status().message();
  options.judge = JudgeSite::kAuto;  // judged on the host
  EXPECT_TRUE(RunSweep(options, backends).ok());
}

TEST_F(DeviceJudgeTest, TheRasterFormIsJudgedOnTheHost) {
  SweepOptions options = Options(TypicalDomain());
  options.samples = 3000;
  options.domain.production = ProductionModel::kRaster;
  auto refused = Sweep(options, JudgeSite::kDevice);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("raster form is judged on the host"), std::string::npos)
      << refused.status().message();
}

}  // namespace
}  // namespace depthbench
