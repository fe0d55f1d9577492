// The sweep's plan: a pure function of the options and of what each
// judging stage can do, and the options' and plan's own checks.
#include <gtest/gtest.h>

#include "bench/sweep/sweep_plan.h"

namespace depthbench {
namespace {

constexpr StageTraits kHostCpu{JudgeSite::kHost, false, UINT64_MAX};
constexpr StageTraits kHostGpu{JudgeSite::kHost, true, UINT64_MAX};
constexpr StageTraits kDeviceGpu{JudgeSite::kDevice, true, UINT64_MAX};
constexpr StageTraits kDeviceCpu{JudgeSite::kDevice, false, UINT64_MAX};

SweepPlan Plan(const SweepOptions& options, std::vector<StageTraits> stages, bool devices_can_draw = true) {
  auto plan = PlanSweep(options, stages, devices_can_draw);
  EXPECT_TRUE(plan.ok()) << plan.status().message();
  return plan.ok() ? *plan : SweepPlan{};
}

TEST(SweepPlanTest, AHostJudgeTakesTurnsWithTheBuildOnEveryThread) {
  SweepOptions options;
  options.threads = 16;
  for (const auto& stages : {std::vector{kHostCpu}, std::vector{kHostCpu, kDeviceGpu}, std::vector{kHostGpu}}) {
    const SweepPlan plan = Plan(options, stages);
    EXPECT_EQ(plan.built_for, BatchFor::kHostJudge);
    EXPECT_FALSE(plan.overlap);
    EXPECT_EQ(plan.build_threads, 16u);
    EXPECT_EQ(plan.stage_threads, 0u);
  }
  // The host's batch where no GPU judges, the device judge's where one does.
  EXPECT_EQ(Plan(options, {kHostCpu}).batch_size, kHostBatch);
  EXPECT_EQ(Plan(options, {kHostCpu, kDeviceGpu}).batch_size, kDeviceJudgeBatch);
}

TEST(SweepPlanTest, DeviceJudgesOverlapTheBuildWithAQuarterOfTheThreads) {
  SweepOptions options;
  for (const auto& [threads, stage, build] : {std::tuple{16u, 4u, 12u}, {32u, 4u, 28u}, {8u, 2u, 6u}, {1u, 1u, 1u}}) {
    options.threads = threads;
    const SweepPlan plan = Plan(options, {kDeviceGpu, kDeviceGpu});
    EXPECT_TRUE(plan.overlap) << threads;
    EXPECT_EQ(plan.stage_threads, stage) << threads;
    EXPECT_EQ(plan.build_threads, build) << threads;
  }
  EXPECT_EQ(Plan(options, {kDeviceGpu}).built_for, BatchFor::kDeviceDraws);
  EXPECT_EQ(Plan(options, {kDeviceGpu}, /*devices_can_draw=*/false).built_for, BatchFor::kDeviceJudge);
  options.device_draws = false;
  EXPECT_EQ(Plan(options, {kDeviceGpu}).built_for, BatchFor::kDeviceJudge);
  // A judge on a CPU device keeps the host's batch size.
  EXPECT_EQ(Plan(options, {kDeviceCpu}).batch_size, kHostBatch);
}

TEST(SweepPlanTest, TheBatchIsCutToWhatTheSmallestStageTakes) {
  SweepOptions options;
  options.batch_size = 100000;
  EXPECT_EQ(Plan(options, {kHostCpu, {JudgeSite::kHost, false, 5000}, {JudgeSite::kHost, false, 7000}}).batch_size,
            5000u);
  EXPECT_EQ(Plan(options, {kHostCpu}).batch_size, 100000u);
}

TEST(SweepPlanTest, TheShardAndTheDistanceBandComeFromTheOptions) {
  SweepOptions options;
  options.samples = 1000;
  options.shard = {2, 4};
  const SweepPlan plan = Plan(options, {kHostCpu});
  EXPECT_EQ(plan.first_sample, 250u);
  EXPECT_EQ(plan.end_sample, 500u);
  EXPECT_EQ(plan.only_distance_band, 0);  // the typical domain's cameras sit at the origin
  options.derive_lone_distance_band = false;
  EXPECT_EQ(Plan(options, {kHostCpu}).only_distance_band, std::nullopt);
}

TEST(SweepPlanTest, DeviceJudgingIsWantedWhereTheSiteSaysSo) {
  EXPECT_TRUE(WantsDeviceJudge(JudgeSite::kAuto, true));
  EXPECT_FALSE(WantsDeviceJudge(JudgeSite::kAuto, false));
  EXPECT_TRUE(WantsDeviceJudge(JudgeSite::kDevice, false));
  EXPECT_FALSE(WantsDeviceJudge(JudgeSite::kHost, true));
}

// Each bad field is refused, naming its constraint; nothing is clamped.
TEST(SweepPlanTest, OptionsNameTheViolatedConstraint) {
  const auto message = [](auto change) {
    SweepOptions options;
    change(options);
    return options.Validate().message();
  };
  EXPECT_EQ(message([](SweepOptions&) {}), "");
  EXPECT_EQ(message([](SweepOptions& o) { o.samples = 0; }),
            "Violated constraint: SweepOptions::samples >= 1 (it is 0)");
  EXPECT_EQ(message([](SweepOptions& o) {
              o.shard = {3, 2};
            }),
            "Violated constraint: 1 <= SweepOptions::shard.index <= shard.count (it is 3/2)");
  EXPECT_EQ(message([](SweepOptions& o) { o.batch_size = 63; }),
            "Violated constraint: SweepOptions::batch_size == 0 or in [64, 4194304] (it is 63)");
  EXPECT_EQ(message([](SweepOptions& o) { o.batch_size = kMaxBatch + 1; }),
            "Violated constraint: SweepOptions::batch_size == 0 or in [64, 4194304] (it is 4194305)");
  EXPECT_EQ(message([](SweepOptions& o) { o.flush_every = 0; }),
            "Violated constraint: SweepOptions::flush_every in [1, 2^31] (it is 0)");
  EXPECT_EQ(message([](SweepOptions& o) { o.flush_every = kMaxFlushEvery + 1; }),
            "Violated constraint: SweepOptions::flush_every in [1, 2^31] (it is 2147483649)");
  EXPECT_NE(message([](SweepOptions& o) { o.domain.near = {-1.0, -1.0}; }), "");
  EXPECT_EQ(message([](SweepOptions& o) { o.batch_size = kMinBatch; }), "");
}

TEST(SweepPlanTest, APlanChecksItsOwnConstraints) {
  SweepPlan plan = Plan(SweepOptions{}, {kHostCpu});
  EXPECT_TRUE(plan.Validate().ok());
  SweepPlan overlapping_host = plan;
  overlapping_host.overlap = true;
  overlapping_host.stage_threads = 1;
  EXPECT_EQ(overlapping_host.Validate().message(),
            "Violated constraint: SweepPlan::overlap == (built_for != kHostJudge): a host judge needs the build's "
            "cores");
  SweepPlan idle_stage_pool = plan;
  idle_stage_pool.stage_threads = 2;
  EXPECT_EQ(idle_stage_pool.Validate().message(),
            "Violated constraint: SweepPlan::stage_threads > 0 exactly where it overlaps");
  SweepPlan no_batch = plan;
  no_batch.batch_size = 0;
  EXPECT_EQ(no_batch.Validate().message(), "Violated constraint: SweepPlan::batch_size >= 1");
  EXPECT_EQ(PlanSweep(SweepOptions{}, {}, true).status().message(), "no backend to run");
}

}  // namespace
}  // namespace depthbench
