// The history keeps a report run only once the report is written: a run
// recorded but not committed (the page failed, the disk was full) is gone
// when the database is opened again.
#include <filesystem>

#include <gtest/gtest.h>

#include "bench/report/history.h"
#include "tests/command_runner.h"

namespace depthbench {
namespace {

Baseline OneCell() {
  Baseline b;
  b.backend = "cpu";
  b.device.name = "test";
  b.cells["divide/standard/d32_sfloat"]["all"] = BandFigures{};
  return b;
}

TEST(HistoryTest, ARunIsKeptOnlyOnceCommitted) {
  const std::filesystem::path path = testing::MakeTempDir("history_test") + "/history.sqlite";
  const Baseline baselines[] = {OneCell()};
  {
    Expected<History> history = History::Open(path);
    ASSERT_TRUE(history.ok()) << history.status().message();
    ASSERT_TRUE(history->Record(HistoryRun{}, baselines).ok());
    Expected<std::int64_t> inside = history->RunCount();
    ASSERT_TRUE(inside.ok());
    EXPECT_EQ(*inside, 1);  // the report reads its own run (trends, previous run)
  }                         // closed without Commit: as when writing the report failed
  {
    Expected<History> history = History::Open(path);
    ASSERT_TRUE(history.ok()) << history.status().message();
    EXPECT_EQ(*history->RunCount(), 0);
    ASSERT_TRUE(history->Record(HistoryRun{}, baselines).ok());
    ASSERT_TRUE(history->Commit().ok());
  }
  Expected<History> history = History::Open(path);
  ASSERT_TRUE(history.ok());
  EXPECT_EQ(*history->RunCount(), 1);
  std::filesystem::remove_all(path.parent_path());
}

}  // namespace
}  // namespace depthbench
