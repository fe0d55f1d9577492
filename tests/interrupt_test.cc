// SIGINT and SIGTERM during long work, as a user's Ctrl-C or a CI job's
// timeout sends them: the program stops promptly with exit 128 + signal,
// keeps what it had found, and leaves no temporary file behind.
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "tests/command_runner.h"

namespace depthbench {
namespace {

namespace fs = std::filesystem;

class InterruptTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTempDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  void TearDown() override { fs::remove_all(dir_); }

  // The names of the files in `folder` whose names contain `part`.
  static std::vector<std::string> FilesWith(const std::string& folder, const std::string& part) {
    std::vector<std::string> names;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(folder, ec)) {
      const std::string name = entry.path().filename().string();
      if (name.find(part) != std::string::npos) names.push_back(name);
    }
    return names;
  }

  std::string dir_;
};

// A campaign of two minutes, stopped by SIGTERM once its first reproducer
// is on disk: the reproducers found so far stay (the code before wrote them
// only at the end, and lost them all), the run ends with 143, and no
// '.NAME.tmp.PID' file is left. The CPU backend finds its first NaN within
// a second here; 60 s allows for a loaded two-core CI machine under ASan.
TEST_F(InterruptTest, FuzzStoppedBySigtermKeepsTheReproducersFoundSoFar) {
  const std::string out = dir_ + "/findings";
  const pid_t pid = testing::StartDepthbench(
      {"fuzz", "--backend", "cpu", "--seconds", "120", "--known", "none", "--quiet", "--out", out}, dir_ + "/stdout",
      dir_ + "/stderr");
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (FilesWith(out, ".json").empty() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_FALSE(FilesWith(out, ".json").empty()) << "no reproducer within 60 s: " << testing::ReadText(dir_ + "/stderr");
  ::kill(pid, SIGTERM);
  // The batch in hand (a fraction of a second) and the file in hand; 30 s
  // as above.
  EXPECT_EQ(testing::WaitForExit(pid, 30), 128 + SIGTERM) << testing::ReadText(dir_ + "/stderr");
  EXPECT_NE(testing::ReadText(dir_ + "/stderr").find("interrupted by SIGTERM"), std::string::npos)
      << testing::ReadText(dir_ + "/stderr");
  const std::vector<std::string> reproducers = FilesWith(out, ".json");
  ASSERT_FALSE(reproducers.empty());
  EXPECT_TRUE(FilesWith(out, ".tmp.").empty()) << FilesWith(out, ".tmp.").front();
  // A reproducer kept is whole: run --repro replays its finding (exit 1).
  const auto replay = testing::RunDepthbench({"run", "--repro", out + "/" + reproducers.front()});
  EXPECT_EQ(replay.exit_code, 1) << replay.err;
  EXPECT_NE(replay.out.find("FINDING"), std::string::npos) << replay.out;
}

// speed polls between its measurements: SIGINT 3 s in ends the run within
// 15 s with exit 130, where the whole run takes about 40 s here (the code
// before ran to its end). At 320x240 one measurement takes well under a
// second on lavapipe; 15 s allows for starting Vulkan and a loaded machine.
TEST_F(InterruptTest, SpeedStopsBetweenMeasurementsOnSigint) {
  const pid_t pid =
      testing::StartDepthbench({"speed", "--quiet", "--resolution", "320x240", "--json", dir_ + "/speed.json"},
                               dir_ + "/stdout", dir_ + "/stderr");
  std::this_thread::sleep_for(std::chrono::seconds(3));
  ::kill(pid, SIGINT);
  EXPECT_EQ(testing::WaitForExit(pid, 15), 128 + SIGINT) << testing::ReadText(dir_ + "/stderr");
  EXPECT_NE(testing::ReadText(dir_ + "/stderr").find("interrupted by SIGINT"), std::string::npos)
      << testing::ReadText(dir_ + "/stderr");
  EXPECT_FALSE(fs::exists(dir_ + "/speed.json"));
  EXPECT_TRUE(FilesWith(dir_, ".tmp.").empty());
}

// A report stopped during its sweeps writes nothing and records nothing:
// before, it wrote its pages from the cut sweeps, unmarked, and recorded
// the run in the history, so that the next report found cells "better".
// Two moments, each as a stage's line appears: as its first sweep starts
// (when the message used to blame --samples), and as the default-domain
// sweep starts, after the sweeps at fixed far/near. (A fixed 3 s into the
// sweeps came after the last of them on an idle machine, where the quick
// report's measuring ends 2.9 s after its first stage.) Its error models
// and bounds still take over 2 s after the second moment, so the signal
// comes before the report is written, however fast the machine.
TEST_F(InterruptTest, AReportStoppedWritesAndRecordsNothing) {
  for (const std::string_view stage_done : {"[speed files]", "[sweeps at fixed far/near]"}) {
    const std::string out = dir_ + "/report", history = dir_ + "/history.sqlite";
    const pid_t pid =
        testing::StartDepthbench({"report", "--quick", "--backend", "cpu", "--out", out, "--history", history},
                                 dir_ + "/stdout", dir_ + "/stderr");
    // Each stage ends within seconds, even under ASan on a busy machine.
    for (int k = 0; k < 600 && testing::ReadText(dir_ + "/stderr").find(stage_done) == std::string::npos; ++k) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    ::kill(pid, SIGINT);
    EXPECT_EQ(testing::WaitForExit(pid, 30), 128 + SIGINT) << testing::ReadText(dir_ + "/stderr");
    const std::string err = testing::ReadText(dir_ + "/stderr");
    EXPECT_NE(err.find("interrupted by SIGINT; nothing was written or recorded"), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(out + "/report.html")) << stage_done;
    EXPECT_FALSE(fs::exists(out + "/results.json")) << stage_done;
    // The history holds no run: the next report finds none to compare with.
    const auto next = testing::RunDepthbench(
        {"report", "--quick", "--backend", "cpu", "--out", dir_ + "/next", "--history", history});
    EXPECT_NE(testing::ReadText(dir_ + "/next/report.md").find("**Verdict: first run**"), std::string::npos)
        << stage_done << ": " << next.err;
    fs::remove_all(dir_ + "/next");
    fs::remove(history);
  }
}

}  // namespace
}  // namespace depthbench
