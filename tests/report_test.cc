// depthbench report as a user runs it: two nights into one history
// database, the second with a planted precision loss in a shader; what the
// Markdown summary and the JSON document say about them.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/command_runner.h"

namespace depthbench {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using testing::ReadText;
using testing::RunDepthbench;

// A small report: two variants, two conventions, two formats, both
// backends, quick sample counts. Enough for every part of the document.
std::vector<std::string> SmallReport(const std::string& root, const std::string& out) {
  return {"report",    "--quick",         "--out",     out,         "--history",    root + "/history.sqlite",
          "--shaders", root + "/shaders", "--variant", "divide,pq", "--convention", "standard,reversed",
          "--format",  "d24,d32f",        "--no-speed"};
}

class ReportTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = new std::string(testing::MakeTempDir("report_test"));
    testing::CopyShaderSources(*root_);
    // Night 1: the shaders as they are.
    first_ = new testing::CommandResult(RunDepthbench(SmallReport(*root_, *root_ + "/night1")));
    // Night 2: divide squeezes its NDC depth through a 16-bit float, as a
    // careless half-precision optimisation would.
    ASSERT_TRUE(testing::ReplaceInFile(
        *root_ + "/shared/variants/divide.h", "  real ndc_z = ndc_depth_from_window_depth(depth, stored);",
        "  real ndc_z = unpackHalf2x16(packHalf2x16(vec2(ndc_depth_from_window_depth(depth, stored), 0.0f))).x;"));
    std::vector<std::string> args = SmallReport(*root_, *root_ + "/night2");
    args.push_back("--fail-on-regression");
    args.push_back("--summary");
    args.push_back(*root_ + "/night2-summary.md");
    second_ = new testing::CommandResult(RunDepthbench(args));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*root_);
    delete first_;
    delete second_;
    delete root_;
  }

  static json Document(const std::string& night) {
    return json::parse(ReadText(*root_ + "/" + night + "/results.json"));
  }

  static std::string* root_;
  static testing::CommandResult* first_;
  static testing::CommandResult* second_;
};
std::string* ReportTest::root_ = nullptr;
testing::CommandResult* ReportTest::first_ = nullptr;
testing::CommandResult* ReportTest::second_ = nullptr;

TEST_F(ReportTest, WritesThePageTheSummaryAndTheDocument) {
  ASSERT_EQ(first_->exit_code, 0) << first_->err;
  for (const char* name : {"report.html", "report.md", "results.json"}) {
    EXPECT_TRUE(fs::is_regular_file(*root_ + "/night1/" + name)) << name;
  }
  const json doc = Document("night1");
  EXPECT_EQ(doc["schema"], "depthbench.report");
  // 2 variants x 2 conventions x 2 formats, on 2 backends.
  EXPECT_EQ(doc["headline"].size(), 16u);
  // The first night has nothing to compare with, and says so.
  EXPECT_TRUE(doc["history"]["previous"].empty());
  EXPECT_NE(ReadText(*root_ + "/night1/report.md").find("nothing to compare with"), std::string::npos);
  // The page is self-contained: the library and the document are inlined.
  const std::string page = ReadText(*root_ + "/night1/report.html");
  EXPECT_NE(page.find("vegaEmbed"), std::string::npos);
  EXPECT_EQ(page.find("<script src="), std::string::npos) << "the page must not load scripts from anywhere";
  EXPECT_EQ(page.find("DEPTHBENCH:DATA"), std::string::npos);
}

// --summary gets report.md's text, for a CI job's page.
TEST_F(ReportTest, TheSummaryFileIsTheMarkdownSummary) {
  const std::string summary = ReadText(*root_ + "/night2-summary.md");
  EXPECT_FALSE(summary.empty());
  EXPECT_EQ(summary, ReadText(*root_ + "/night2/report.md"));
}

TEST_F(ReportTest, TwoRunsGiveTwoTrendPointsPerCell) {
  ASSERT_NE(second_->exit_code, 2) << second_->err;
  const json doc = Document("night2");
  std::map<std::pair<std::string, std::string>, std::set<std::int64_t>> runs;
  for (const json& p : doc["history"]["trend"]) runs[{p["backend"], p["cell"]}].insert(p["run"].get<std::int64_t>());
  ASSERT_EQ(runs.size(), 16u);
  for (const auto& [key, ids] : runs) EXPECT_EQ(ids.size(), 2u) << key.second << " on " << key.first;
  EXPECT_EQ(doc["history"]["runs_recorded"], 2);
}

TEST_F(ReportTest, PlantedRegressionIsFlaggedAndOnlyThere) {
  // --fail-on-regression: the planted loss is a finding.
  EXPECT_EQ(second_->exit_code, 1) << second_->out << second_->err;
  const json doc = Document("night2");
  std::set<std::string> worse_cells;
  for (const json& c : doc["history"]["changes"]) {
    if (c["direction"] == "worse")
      worse_cells.insert(c["cell"].get<std::string>() + " on " + c["backend"].get<std::string>());
  }
  // The GPU ran the edited shader; the CPU backend's formulas are compiled
  // in, and pq was not touched: with a fixed seed nothing else may move.
  EXPECT_FALSE(worse_cells.empty());
  for (const std::string& cell : worse_cells) {
    EXPECT_EQ(cell.rfind("divide/", 0), 0u) << cell;
    EXPECT_NE(cell.find(" on vulkan"), std::string::npos) << cell;
  }
  EXPECT_TRUE(worse_cells.count("divide/reversed/d32_sfloat on vulkan")) << "reversed D32F loses most to a half";
  const std::string summary = ReadText(*root_ + "/night2/report.md");
  EXPECT_NE(summary.find("got worse"), std::string::npos) << summary;
  EXPECT_NE(summary.find("`divide/reversed/d32_sfloat` on vulkan"), std::string::npos) << summary;
  // A CI job summary: the verdict, with counts, on the first line; at most
  // 40 lines in all (tests/report_render_test.cc: however much got worse),
  // the page for detail.
  const auto verdict = summary.find("**Verdict: ");
  EXPECT_EQ(verdict, 0u) << summary;
  EXPECT_NE(summary.find("cell(s) got worse** since", verdict), std::string::npos) << summary;
  EXPECT_NE(summary.find("cells worse,", verdict), std::string::npos) << summary;
  EXPECT_LE(std::count(summary.begin(), summary.end(), '\n'), 40) << summary;
  EXPECT_NE(summary.find("`report.html`"), std::string::npos) << summary;
}

TEST_F(ReportTest, SummaryNamesTheWorstCells) {
  const json doc = Document("night1");
  // Worst: the highest p99.9 bits lost over the default domain, then the
  // highest maximum; null is not finite, the worst of all.
  struct Row {
    double p999, max;
    std::string name, backend;
  };
  auto bits = [](const json& v) { return v.is_null() ? INFINITY : v.get<double>(); };
  std::vector<Row> rows;
  for (const json& r : doc["headline"]) {
    rows.push_back({bits(r["p999_bits"]), bits(r["max_bits"]),
                    "`" + r["variant"].get<std::string>() + "/" + r["convention"].get<std::string>() + "/" +
                        r["format"].get<std::string>() + "`",
                    r["backend"].get<std::string>()});
  }
  std::stable_sort(rows.begin(), rows.end(),
                   [](const Row& a, const Row& b) { return a.p999 != b.p999 ? a.p999 > b.p999 : a.max > b.max; });
  const std::string summary = ReadText(*root_ + "/night1/report.md");
  const auto section = summary.find("## Worst cells");
  ASSERT_NE(section, std::string::npos) << summary;
  const std::size_t line = summary.find("- worst ", section);
  ASSERT_NE(line, std::string::npos) << summary;
  const std::string worst = summary.substr(line, summary.find('\n', line) - line);
  // One line of three; a cell with the same figures on both backends is
  // one entry that names both, so the three worst rows are all there.
  for (std::size_t i = 0; i < 3; ++i) {
    bool named = false;
    for (std::size_t at = worst.find(rows[i].name + " on "); at != std::string::npos;
         at = worst.find(rows[i].name + " on ", at + 1)) {
      named = named || worst.substr(at, worst.find(')', at) - at).find(rows[i].backend) != std::string::npos;
    }
    EXPECT_TRUE(named) << rows[i].name << " on " << rows[i].backend << "\n" << worst;
  }
  // The best cell of all is not among the worst.
  EXPECT_EQ(worst.find(rows.back().name), std::string::npos) << rows.back().name;
}

// The first screen's interval is that of its point: the fit's model at the
// far plane of the row's ratio, so it holds the point. Infinite-far rows
// are where a band's interval once stood beside the model's point (24 bits
// "in" [22.7, 23.7]): standard Z with D16 reaches every bit at the far end.
TEST(ReportFirstScreenTest, EveryIntervalHoldsItsPoint) {
  const std::string out = testing::MakeTempDir("report_first_screen");
  const auto r = RunDepthbench({"report", "--samples", "1e5", "--default-samples", "1e4", "--variant", "divide,pq",
                                "--convention", "standard,standard-inf,reversed-inf", "--format", "d16,d32f",
                                "--backend", "cpu", "--no-speed", "--no-history", "--out", out});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json doc = json::parse(ReadText(out + "/results.json"));
  std::size_t infinite = 0, with_interval = 0, proven = 0;
  for (const json& row : doc["recommendations"]) {
    const std::string name = row["convention"].get<std::string>() + "/" + row["format"].get<std::string>();
    if (row["ratio"] == "inf") ++infinite;
    // The proven bound is at or above every sample of the row's population,
    // so at or above the lower end of its far-plane p99.9. Not where the
    // row keeps nothing: there the far plane's figure is the model's, past
    // the last stored value before the one that denotes infinity, and no
    // judged sample reaches it (reversed-inf/d16_unorm: the model says 24,
    // every sample 23.0 at most, the bound 23.0).
    if (!row["proven_bits"].is_null() && !row["bits_low"].is_null() && !row["keeps_nothing"].get<bool>()) {
      ++proven;
      EXPECT_LE(row["bits_low"].get<double>(), row["proven_bits"].get<double>()) << name;
    }
    // null: every bit lost, or no interval (a fit without a covariance).
    if (row["bits"].is_null() || row["bits_low"].is_null() || row["bits_high"].is_null()) continue;
    ++with_interval;
    const double bits = row["bits"], low = row["bits_low"], high = row["bits_high"];
    EXPECT_LE(low, bits) << name;
    EXPECT_LE(bits, high) << name;
  }
  EXPECT_EQ(infinite, 4u) << "two infinite-far conventions, two formats";
  EXPECT_EQ(with_interval, doc["recommendations"].size());
  EXPECT_EQ(proven, 3u) << "standard (d16, d32f) and reversed-inf/d32f keep bits, and each is bounded";
  fs::remove_all(out);
}

TEST_F(ReportTest, RefusesAFileThatIsNotAHistory) {
  const std::string bogus = *root_ + "/not_a_db.sqlite";
  std::ofstream(bogus) << "this is not a database\n";
  const auto r = RunDepthbench({"report", "--quick", "--out", *root_ + "/bogus", "--history", bogus, "--backend", "cpu",
                                "--variant", "divide", "--convention", "standard", "--format", "d24"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("not_a_db.sqlite"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("not a SQLite database"), std::string::npos) << r.err;
}

TEST_F(ReportTest, MissingPlotLibraryIsACleanError) {
  const auto r = RunDepthbench({"report", "--quick", "--out", *root_ + "/nolib", "--no-history", "--plot-library",
                                *root_ + "/nowhere", "--backend", "cpu"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("npm ci --prefix reports"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(*root_ + "/nolib/report.html"));
}

}  // namespace
}  // namespace depthbench
