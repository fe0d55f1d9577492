// report.md is a CI job summary: its verdict line first, then at most 40
// lines, for the full set of cells and whatever changed since the last run
// (the most that every part of it can hold: every convention and format,
// more worse cells, notes and finding causes than it lists).
#include <algorithm>
#include <string>

#include <gtest/gtest.h>

#include "bench/pipeline/cells.h"
#include "bench/report/report.h"
#include "bench/report/report_render.h"

namespace depthbench {
namespace {

std::size_t Lines(const std::string& text) {
  return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

// A report as large as report.md can be: a first-screen row for every
// encoding some cell reads, a history with many worse cells, each in many
// bands, and notes, more worst cells and finding causes than it lists.
Report LargestReport() {
  Report report;
  report.environment.commit = "0123456789abcdef";
  report.environment.started_at = "2026-12-01T00:00:00Z";
  report.environment.backends = {{"cpu", DeviceInfo{}}, {"vulkan", DeviceInfo{}}};
  report.environment.seconds = 180.0;
  // A report's domain is perspective or orthographic; the perspective
  // one's cells are the most.
  for (const Encoding& e : AllEncodings()) {
    if (Info(e.convention).orthographic()) continue;
    RecommendationRow row;
    row.convention = std::string(Info(e.convention).name);
    row.format = std::string(Info(e.format).name);
    row.backend = "vulkan";
    row.ratio = (Info(e.convention).bits & catalog::kInf) != 0 ? "inf" : "1e4";
    row.variants = {"inverse_vp", "pq", "reciprocal", "divide"};
    row.bits = 20.2;
    row.bits_low = 20.1;
    row.bits_high = 20.3;
    row.cost = 1.61;
    row.cost_unit = "µs per 1920x1080 frame on NVIDIA H200";
    row.ratio_for_1e3 = {BudgetRatio::Kind::kRatio, 134.0};
    row.ratio_for_1e6 = {BudgetRatio::Kind::kNever, {}};
    report.recommendations.push_back(row);
  }
  for (const Cell& cell : AllCells()) {
    if (Info(cell.convention).orthographic()) continue;
    for (const char* backend : {"cpu", "vulkan"}) {
      HeadlineRow row;
      row.cell = {std::string(Info(cell.variant).name), std::string(Info(cell.convention).name),
                  std::string(Info(cell.format).name), backend};
      row.measured = HeadlineRow::Measured{22.6, 23.6, 0, 0};
      report.headline.push_back(row);
    }
  }
  for (const char* variant : {"inverse_vp", "pq", "divide", "reciprocal", "eye_ray"}) {
    FindingGroup g;
    g.variant = variant;
    g.rows = 20;
    g.outputs = 12858;
    g.sweeps = {"f/n 1e7", "f/n 1e7.5"};
    g.backends = {"cpu", "vulkan"};
    g.command = "depthbench run --seed 1 --index 2";
    report.finding_groups.push_back(g);
  }
  HistorySection history;
  history.database = "history.sqlite";
  history.previous = {{"cpu", 1, "2026-11-30", "aaaaaaaaaaaa"}, {"vulkan", 1, "2026-11-30", "aaaaaaaaaaaa"}};
  history.notes = {"cpu: the baseline has 2 cells this run lacks", "vulkan: another note", "a third note"};
  const std::vector<Cell> cells = AllCells();
  for (std::size_t i = 0; i < 12; ++i) {
    for (const char* band : {"all", "ratio 1e2-1e3", "ratio 1e3-1e4", "depth 1e1-1e2", "depth 1e2-1e3"}) {
      history.changes.push_back(
          {HistorySection::Direction::kWorse, "vulkan", cells[i].Name(), band, {"p99.9 +1.2 bits"}, 20.0, 21.2});
    }
  }
  history.changes.push_back(
      {HistorySection::Direction::kBetter, "cpu", cells[20].Name(), "all", {"p99.9 -0.5 bits"}, 20.0, 19.5});
  CountChangedCells(report.headline.size(), history);
  report.history = history;
  report.worst_cells = WorstCells(report.headline);
  return report;
}

TEST(ReportRenderTest, SummaryIsAVerdictLineThenAtMostFortyLines) {
  const std::string summary = RenderMarkdown(LargestReport());
  EXPECT_EQ(summary.rfind("**Verdict: 12 cell(s) got worse** since", 0), 0u) << summary;
  // The limit is the issue's: a CI job summary of a verdict line and at
  // most about 40 lines; the verdict line counts among them.
  EXPECT_LE(Lines(summary), 40u) << summary;
  // Nothing of the first screen is dropped to get there: every finite
  // convention and format has its line, and an infinite-far form folds into
  // its finite one's line.
  for (const RecommendationRow& row : LargestReport().recommendations) {
    if (row.ratio == "inf") continue;
    EXPECT_NE(summary.find("| " + row.convention + " | " + row.format + " |"), std::string::npos)
        << row.convention << " " << row.format;
  }
  EXPECT_EQ(summary.find("| standard-inf |"), std::string::npos) << summary;
  EXPECT_NE(summary.find("... and 9 more: see report.html"), std::string::npos) << summary;
  EXPECT_NE(summary.find("... and 2 more causes"), std::string::npos) << summary;
}

// The first screen leads with the lever: a combination that keeps nothing
// says "do not use", never a variant; the others name theirs, with the
// error in world units and the bytes a frame moves.
TEST(ReportRenderTest, FirstScreenSaysDoNotUseWhereNothingIsKept) {
  Report report = LargestReport();
  RecommendationRow& lost = report.recommendations.front();
  lost.keeps_nothing = true;
  lost.bits = lost.bits_low = lost.bits_high = 24.0;
  RecommendationRow& kept = report.recommendations[1];
  kept.bytes_per_pixel = 8;
  kept.error_far_100m = 0.0031;  // 3.1 mm
  kept.error_far_10km = 31.0;
  const std::string summary = RenderMarkdown(report);
  const std::string lost_line = "| " + lost.convention + " | " + lost.format + " | **do not use**: keeps nothing |";
  EXPECT_NE(summary.find(lost_line), std::string::npos) << summary;
  const std::string kept_line = "| " + kept.convention + " | " + kept.format + " | `inverse_vp` (= pq, reciprocal, "
                                "divide) | 1e4 | 20.2 [20.1, 20.3] | none | 3.1 mm | 31 m | 8 |";
  EXPECT_NE(summary.find(kept_line), std::string::npos) << summary;
}

// Without a history (the first run, or --no-history) it is shorter still.
TEST(ReportRenderTest, FirstRunSummaryIsShorter) {
  Report report = LargestReport();
  report.history.reset();
  const std::string summary = RenderMarkdown(report);
  EXPECT_EQ(summary.rfind("**Verdict: not compared**", 0), 0u) << summary;
  EXPECT_LE(Lines(summary), 34u) << summary;
}

// A committed speed file measured on another device does not cost this
// report's candidates; one the user names does, whatever made it.
TEST(ReportSpeedFilesTest, OnlyThoseOfThisReportsDevicesUnlessNamed) {
  SpeedResults h100;
  h100.run.device.name = "NVIDIA H100 80GB HBM3";
  SpeedResults llvmpipe;
  llvmpipe.run.device.name = "llvmpipe (LLVM 15.0.6, 256 bits)";
  std::vector<DeviceInfo> devices(2);
  devices[0].name = "cpu";
  devices[1].name = "llvmpipe (LLVM 15.0.6, 256 bits)";
  EXPECT_FALSE(SpeedFileApplies(h100, /*named=*/false, devices));
  EXPECT_TRUE(SpeedFileApplies(llvmpipe, /*named=*/false, devices));
  EXPECT_TRUE(SpeedFileApplies(h100, /*named=*/true, devices));
  // Another build of the same driver (another LLVM, another vector width)
  // is another device.
  SpeedResults narrower = llvmpipe;
  narrower.run.device.name = "llvmpipe (LLVM 15.0.6, 128 bits)";
  EXPECT_FALSE(SpeedFileApplies(narrower, /*named=*/false, devices));
}

}  // namespace
}  // namespace depthbench
