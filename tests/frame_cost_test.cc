// Frame cost: the bytes a depth choice makes a frame move, the extra
// target a linear depth needs, stencil, and which speed file costs a
// command on which device.
#include <gtest/gtest.h>

#include "bench/choose/frame_cost.h"
#include "bench/choose/scene.h"
#include "bench/speed/trade.h"

namespace depthbench {
namespace {

const std::string kSpeedDir = std::string(DEPTHBENCH_SOURCE_DIR) + "/reports/speed/";

Cell CellOf(Variant v, Convention c, Format f) { return Cell{v, c, f}; }

TEST(FrameCostTest, AttachmentBytesFollowTheFormatsAsStored) {
  EXPECT_EQ(AttachmentBytes(Format::kD16Unorm, false), 2u);
  EXPECT_EQ(AttachmentBytes(Format::kX8D24Unorm, false), 4u);
  EXPECT_EQ(AttachmentBytes(Format::kD32Sfloat, false), 4u);
  EXPECT_EQ(AttachmentBytes(Format::kD16Unorm, true), 4u);
  EXPECT_EQ(AttachmentBytes(Format::kX8D24Unorm, true), 4u);  // the stencil takes the X8 byte
  EXPECT_EQ(AttachmentBytes(Format::kD32Sfloat, true), 8u);
  // Colour targets never hold stencil.
  EXPECT_EQ(AttachmentBytes(Format::kR32Sfloat, true), 4u);
  EXPECT_EQ(AttachmentBytes(Format::kR16Sfloat, true), 2u);
}

// A linear depth pays for its target on top of the attachment its depth
// test keeps: written and read, where a hardware depth is read instead.
TEST(FrameCostTest, TheLinearTargetIsCharged) {
  const FrameBytes linear = FrameBytesOf(CellOf(Variant::kFrustumRay, Convention::kLinear, Format::kR32Sfloat), false);
  const FrameBytes hardware = FrameBytesOf(CellOf(Variant::kDivide, Convention::kReversed, Format::kD32Sfloat), false);
  EXPECT_EQ(linear.target, 4u);
  EXPECT_EQ(linear.attachment, AttachmentBytes(kLinearTestAttachment, false));
  EXPECT_EQ(linear.moved(), 4u + 2u * 4u);
  EXPECT_EQ(hardware.target, 0u);
  EXPECT_EQ(hardware.moved(), 2u * 4u);
  EXPECT_GT(linear.moved(), hardware.moved());
}

// A speed file with a known bandwidth and equal ALU times for two cells.
SpeedResults Synthetic(double bytes_per_second, double alu_ns_per_pass, double alu_spread_ns) {
  SpeedResults speed;
  speed.run.device.name = "test GPU";
  BandwidthProbe probe;
  probe.bytes_read = probe.bytes_written = 500'000'000;
  probe.ns_per_pass.median = 1e9 * 1e9 / bytes_per_second;  // 1e9 bytes moved
  probe.ns_per_pass.q1 = probe.ns_per_pass.q3 = probe.ns_per_pass.median;
  speed.bandwidth = probe;
  for (Format f : {Format::kX8D24Unorm, Format::kD32Sfloat}) {
    GpuTiming t;
    t.cell = CellOf(Variant::kDivide, Convention::kReversed, f);
    t.resolution = {1000, 1000};
    t.regime = Regime::kAlu;
    t.taps = 16;
    t.ns_per_pass.median = alu_ns_per_pass;
    t.ns_per_pass.q1 = alu_ns_per_pass - alu_spread_ns / 2;
    t.ns_per_pass.q3 = alu_ns_per_pass + alu_spread_ns / 2;
    speed.gpu.push_back(t);
  }
  return speed;
}

// The figures follow from the probe and the timing alone: 1e6 pixels, 8
// bytes each at 1e12 B/s is 8 us; 16e6 ns over 16 taps is 1 ns a pixel,
// 1000 us a frame.
TEST(FrameCostTest, CostIsBytesAtTheBandwidthPlusOneReconstructionPerPixel) {
  FrameCostModel model{std::make_shared<const SpeedResults>(Synthetic(1e12, 16e6, 0.0)), "synthetic", {1000, 1000},
                       false};
  auto cost = model.Cost(CellOf(Variant::kDivide, Convention::kReversed, Format::kD32Sfloat));
  ASSERT_TRUE(cost.ok()) << cost.status().message();
  EXPECT_NEAR(cost->memory_us, 8.0, 1e-9);
  EXPECT_NEAR(cost->alu_us, 1000.0, 1e-9);
  // A frame four times larger costs four times as much.
  model.frame = {2000, 2000};
  auto larger = model.Cost(CellOf(Variant::kDivide, Convention::kReversed, Format::kD32Sfloat));
  ASSERT_TRUE(larger.ok());
  EXPECT_NEAR(larger->total_us(), 4.0 * cost->total_us(), 1e-6);
  // A cell the file did not time has no cost.
  EXPECT_FALSE(model.Cost(CellOf(Variant::kPq, Convention::kReversed, Format::kD32Sfloat)).ok());
}

// A cost's ALU part is a compute pass's; where the file's stage probe has
// a drawing stage at under half compute's rate (an H100: 3.6%), the cost's
// source says what a drawn pass computes at; at half or more, nothing.
TEST(FrameCostTest, ACostSaysWhereTheDeviceDrawsFarSlowerThanItComputes) {
  SpeedResults speed = Synthetic(1e12, 16e6, 0.0);
  StageProbe probe;
  probe.invocations = probe.fma_per_invocation = 1000;
  probe.stages = {{"compute", {}, {}, 1, 1, 0}, {"vertex", {}, {}, 1, 1, 0}, {"fragment", {}, {}, 1, 1, 0}};
  probe.stages[0].ns_per_pass.median = 100;
  probe.stages[1].ns_per_pass.median = 150;   // 67%
  probe.stages[2].ns_per_pass.median = 2800;  // 3.6%
  speed.stages = probe;
  const Cell d32 = CellOf(Variant::kDivide, Convention::kReversed, Format::kD32Sfloat);
  const auto slow = FrameCostLookup({std::make_shared<const SpeedResults>(speed), "h100.json", {1000, 1000}, false});
  ASSERT_TRUE(slow(d32));
  EXPECT_EQ(slow(d32)->source,
            "h100.json; ALU from compute passes: a pass drawn by the rasterizer computes at 3.6% of their rate on "
            "this device (speed's stage probe)");
  speed.stages->stages[2].ns_per_pass.median = 190;  // 53%: the slowest drawing stage at half or more
  const auto near = FrameCostLookup({std::make_shared<const SpeedResults>(speed), "gpu.json", {1000, 1000}, false});
  ASSERT_TRUE(near(d32));
  EXPECT_EQ(near(d32)->source, "gpu.json");
}

// D24 and D32F tie on bytes without stencil; with it D32F moves twice the
// bytes, more than the spread of the timings apart when memory matters.
TEST(FrameCostTest, D24AndD32fNoLongerTieWithStencil) {
  // Bandwidth-heavy: 1e10 B/s makes 8 bytes a pixel 800 us against 100 us of ALU (spread 2 us).
  auto speed = std::make_shared<const SpeedResults>(Synthetic(1e10, 1.6e6, 32e3));
  const Cell d24 = CellOf(Variant::kDivide, Convention::kReversed, Format::kX8D24Unorm);
  const Cell d32 = CellOf(Variant::kDivide, Convention::kReversed, Format::kD32Sfloat);
  const CostLookup without = FrameCostLookup({speed, "synthetic", {1000, 1000}, false});
  const CostLookup with = FrameCostLookup({speed, "synthetic", {1000, 1000}, true});
  EXPECT_TRUE(CostsTie(*without(d24), *without(d32)));
  ASSERT_TRUE(with(d24) && with(d32));
  EXPECT_FALSE(CostsTie(*with(d24), *with(d32)));
  EXPECT_EQ(with(d32)->bytes_per_pixel, 16u);
  EXPECT_EQ(with(d24)->bytes_per_pixel, 8u);
  EXPECT_NEAR(with(d32)->value - with(d24)->value, 800.0, 1e-6);
}

TEST(FrameCostTest, AFileWithoutBandwidthProbeIsRefusedWithTheFix) {
  SpeedResults speed = Synthetic(1e12, 16e6, 0.0);
  speed.bandwidth.reset();
  const Status status = CheckFrameCostable(speed, "old.json");
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("old.json"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("speed --quick"), std::string::npos) << status.message();
}

// No absent device's cost without --speed: the committed files are of
// lavapipe and an H200; a command on any other device gets none, one on
// lavapipe gets lavapipe's, and a file named is used whatever its device.
TEST(FrameCostTest, OnlyTheCommandsOwnDeviceIsCostedUnlessAFileIsNamed) {
  std::string source;
  DeviceInfo other;
  other.name = "Some Other GPU";
  auto none = SpeedFileFor(other, "", Catalogue::BuiltIn(), source);
  ASSERT_TRUE(none.ok()) << none.status().message();
  EXPECT_EQ(*none, nullptr);

  auto named = SpeedFileFor(other, kSpeedDir + "nvidia-h200.json", Catalogue::BuiltIn(), source);
  ASSERT_TRUE(named.ok()) << named.status().message();
  ASSERT_NE(*named, nullptr);
  EXPECT_EQ((*named)->run.device.name, "NVIDIA H200");
  const FrameCostModel model{*named, source, {2560, 1440}, false};
  EXPECT_EQ(model.Unit(), "µs per 2560x1440 frame on NVIDIA H200");

  DeviceInfo lavapipe;
  lavapipe.name = "llvmpipe (LLVM 15.0.6, 256 bits)";
  auto own = SpeedFileFor(lavapipe, "", Catalogue::BuiltIn(), source);
  ASSERT_TRUE(own.ok()) << own.status().message();
  ASSERT_NE(*own, nullptr);
  EXPECT_EQ((*own)->run.device.name, lavapipe.name);
  EXPECT_NE(source.find("llvmpipe.json"), std::string::npos) << source;
}

// The fixed cost of a pass is the intercept of its time against its
// pixels: 1000 ns + 2 ns a pixel at two sizes gives back both.
TEST(FrameCostTest, SplitPassCostRecoversTheInterceptAndTheSlope) {
  std::vector<GpuTiming> timings;
  for (Resolution r : {Resolution{100, 100}, Resolution{200, 100}, Resolution{400, 400}}) {
    GpuTiming t;
    t.cell = CellOf(Variant::kDivide, Convention::kReversed, Format::kD32Sfloat);
    t.resolution = r;
    t.ns_per_pass.median = 1000.0 + 2.0 * t.pixels();
    timings.push_back(t);
  }
  const std::optional<PassCostSplit> split = SplitPassCost(timings);
  ASSERT_TRUE(split.has_value());
  EXPECT_EQ(split->cells, 1u);
  EXPECT_NEAR(split->fixed_ns, 1000.0, 1e-6);
  EXPECT_NEAR(split->ns_per_pixel, 2.0, 1e-12);
  // One resolution says nothing about the split.
  timings.resize(1);
  EXPECT_FALSE(SplitPassCost(timings).has_value());
}

// choose keeps what it was given: a listed format that no listed
// convention reads is named, with the convention it needs.
TEST(FrameCostTest, ADroppedFormatIsNamed) {
  auto scene = ParseScene(
      "name = \"dropped\"\n[projection]\nnear = 0.1\nfar = 1000\nfov_degrees = 60\naspect = 1.5\n"
      "[engine]\nconventions = [\"standard\", \"reversed\"]\nformats = [\"r16_sfloat\", \"r32_sfloat\", "
      "\"d32_sfloat\"]\n[requirement]\nrelative_error = 1e-3\n",
      "dropped.toml");
  ASSERT_TRUE(scene.ok()) << scene.status().message();
  const std::vector<std::string> unusable = scene->UnusableFormats();
  ASSERT_EQ(unusable.size(), 2u);
  EXPECT_EQ(unusable[0], "r16_sfloat: read only under linear, which engine.conventions does not list");
  EXPECT_EQ(unusable[1].rfind("r32_sfloat:", 0), 0u) << unusable[1];
}

}  // namespace
}  // namespace depthbench
