// Bad input on every path of the program that cli_test, gate_test,
// speed_cli_test, choose_test and report_test do not already cover: output
// files that cannot be written (for each command that writes one), shader
// directories that do not exist or lack a shader, device names that match
// nothing, baselines that do not parse, scene files that are not files.
// Each must give exit code 2 and a message naming the flag or file at fault,
// and an output that cannot be written must be refused before the long work.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

#include "tests/command_runner.h"

namespace depthbench {
namespace {

namespace fs = std::filesystem;
using testing::RunDepthbench;

const std::string kSource = DEPTHBENCH_SOURCE_DIR;
const std::string kScene = kSource + "/bench/scenes/space_game.toml";
const std::string kCpuBaseline = kSource + "/reports/baselines/cpu.json";

// /proc is a folder in which no file can be created, by anyone, root
// included: root is allowed to write any folder by its permission bits, so a
// check that trusted them (access(2)) would let the work run and fail at the
// end. CI runs as root.
const std::string kNoFilesHere = "/proc";

// A temporary folder per test: an empty shader folder, a file that is a
// folder, a broken baseline.
class BadInputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTempDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Runs depthbench, expects exit 2 and `message` in stderr, and returns the
  // wall time in seconds.
  double ExpectRefused(const std::vector<std::string>& args, const std::string& message) {
    const auto start = std::chrono::steady_clock::now();
    const auto r = RunDepthbench(args);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(r.exit_code, 2) << "stderr: " << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << "expected '" << message << "' in stderr: " << r.err;
    out_ = r.out;
    return seconds;
  }

  std::string out_;  // stdout of the last ExpectRefused
  std::string dir_;
};

// Every command that writes a file refuses an output it cannot create, names
// the flag and the path, and does so before the work: nothing is printed on
// stdout (each command prints its tables only after its work), and for the
// commands whose work has a fixed, long size (the gate's full sweep, speed's
// GPU timings) the refusal comes within the limit below. 60 s: starting the
// program (under ASan, on a busy two-core CI machine) and opening lavapipe
// take a few seconds; that work takes minutes.
constexpr double kBeforeTheWorkSeconds = 60.0;

TEST_F(BadInputTest, RunRefusesAnOutputItCannotCreateBeforeSampling) {
  ExpectRefused({"run", "--backend", "cpu", "--samples", "1e4", "--json", kNoFilesHere + "/run.json"},
                "--json: cannot write '/proc/run.json': cannot create a file in directory '/proc'");
  EXPECT_EQ(out_, "");
}

TEST_F(BadInputTest, RunRefusesAnOutputThatIsAFolder) {
  ExpectRefused({"run", "--backend", "cpu", "--samples", "1e4", "--json", dir_},
                "--json: '" + dir_ + "' is a directory");
  EXPECT_EQ(out_, "");
}

TEST_F(BadInputTest, MergeRefusesAnOutputItCannotCreate) {
  // The check comes before the inputs are read, so any existing file will do.
  ExpectRefused({"merge", kCpuBaseline, "--json", kNoFilesHere + "/merged.json"},
                "--json: cannot write '/proc/merged.json'");
  EXPECT_EQ(out_, "");
}

TEST_F(BadInputTest, FitRefusesAnOutputItCannotCreateBeforeSweeping) {
  ExpectRefused({"fit", "--backend", "cpu", "--samples", "1e3", "--json", kNoFilesHere + "/fits.json"},
                "--json: cannot write '/proc/fits.json'");
  EXPECT_EQ(out_, "");
}

TEST_F(BadInputTest, ChooseRefusesAnOutputItCannotCreateBeforeMeasuring) {
  ExpectRefused(
      {"choose", "--scene", kScene, "--backend", "cpu", "--samples", "1e3", "--json", kNoFilesHere + "/choice.json"},
      "--json: cannot write '/proc/choice.json'");
  EXPECT_EQ(out_, "");
}

TEST_F(BadInputTest, GateRefusesJUnitAndJsonOutputsItCannotCreateBeforeSweeping) {
  double seconds = ExpectRefused({"gate", "--baseline", kCpuBaseline, "--junit", kNoFilesHere + "/gate.xml"},
                                 "--junit: cannot write '/proc/gate.xml'");
  EXPECT_LT(seconds, kBeforeTheWorkSeconds);
  EXPECT_EQ(out_, "");
  seconds = ExpectRefused({"gate", "--baseline", kCpuBaseline, "--json", kNoFilesHere + "/gate.json"},
                          "--json: cannot write '/proc/gate.json'");
  EXPECT_LT(seconds, kBeforeTheWorkSeconds);
}

TEST_F(BadInputTest, GateUpdateRefusesABaselineItCannotWriteBeforeSweeping) {
  // A new baseline in a folder where no file can be created...
  double seconds = ExpectRefused({"gate", "--update", "--baseline", kNoFilesHere + "/new.json", "--backend", "cpu"},
                                 "--update: --baseline: cannot write '/proc/new.json'");
  EXPECT_LT(seconds, kBeforeTheWorkSeconds);
  EXPECT_EQ(out_, "");
  // ...and a baseline path that names a folder.
  fs::create_directories(dir_ + "/baseline.json");
  seconds = ExpectRefused({"gate", "--update", "--baseline", dir_ + "/baseline.json", "--backend", "cpu"},
                          "--update: --baseline: '" + dir_ + "/baseline.json' is a directory");
  EXPECT_LT(seconds, kBeforeTheWorkSeconds);
}

TEST_F(BadInputTest, SpeedRefusesAnOutputItCannotCreateBeforeTiming) {
  const double seconds =
      ExpectRefused({"speed", "--json", kNoFilesHere + "/speed.json"}, "--json: cannot write '/proc/speed.json'");
  EXPECT_LT(seconds, kBeforeTheWorkSeconds);
  EXPECT_EQ(out_, "");
}

TEST_F(BadInputTest, ReportRefusesAnOutFolderItCannotWriteInto) {
  // /proc exists, so the folder is "created"; its files cannot be.
  ExpectRefused({"report", "--quick", "--no-history", "--backend", "cpu", "--out", kNoFilesHere},
                "--out: cannot write '/proc/results.json': cannot create a file in directory '/proc'");
  EXPECT_EQ(out_, "");
  // A folder that cannot be created at all.
  ExpectRefused({"report", "--quick", "--no-history", "--backend", "cpu", "--out", kNoFilesHere + "/report"},
                "--out: cannot create folder '/proc/report'");
}

// A shader folder that exists but holds no shaders: the first shader looked
// for is named, whichever command compiles them.
TEST_F(BadInputTest, AShaderFolderWithoutTheShadersNamesTheMissingFile) {
  ExpectRefused({"run", "--backend", "vulkan", "--samples", "10", "--shaders", dir_},
                "shader source '" + dir_ + "/frustum_ray.comp' does not exist");
  ExpectRefused({"choose", "--scene", kScene, "--samples", "10", "--shaders", dir_},
                "shader source '" + dir_ + "/frustum_ray.comp' does not exist");
  ExpectRefused({"speed", "--quick", "--shaders", dir_}, "speed shader directory '" + dir_ + "/speed' does not exist");
}

TEST_F(BadInputTest, GateWithAShaderFolderThatDoesNotExist) {
  ExpectRefused({"gate", "--baseline", kSource + "/reports/baselines/lavapipe.json", "--shaders", "/no/such/dir"},
                "shader directory '/no/such/dir' does not exist");
}

// Unknown device names on the commands cli_test and speed_cli_test do not
// try: the message lists the devices there are.
TEST_F(BadInputTest, UnknownDeviceNamesTheDevicesThereAre) {
  const std::string expected = "no Vulkan device matches 'no-such-gpu'; available: ";
  ExpectRefused({"gate", "--baseline", kSource + "/reports/baselines/lavapipe.json", "--device", "no-such-gpu"},
                expected);
  ExpectRefused({"choose", "--scene", kScene, "--device", "no-such-gpu"}, expected);
  ExpectRefused({"fit", "--backend", "vulkan", "--device", "no-such-gpu"}, expected);
  ExpectRefused({"report", "--quick", "--no-history", "--backend", "vulkan", "--device", "no-such-gpu", "--out",
                 dir_ + "/report"},
                expected);
}

// Valid JSON that is not a baseline (here, a results file): the message
// names the file and what is wrong in it (gate_test covers broken JSON).
TEST_F(BadInputTest, ABaselineThatIsAnotherKindOfFile) {
  const std::string path = dir_ + "/results.json";
  std::ofstream(path) << R"({"schema": "depthbench.results", "schema_version": 1, "cells": []})";
  ExpectRefused({"gate", "--baseline", path}, "the baseline does not parse: " + path +
                                                  ": (top level): schema is 'depthbench.results', expected "
                                                  "'depthbench.baseline'");
}

// A number beyond the range of a double in a results file: once an escaping
// exception that aborted the program (found by fuzz_results_json).
TEST_F(BadInputTest, AResultsFileWithANumberBeyondDoubleRange) {
  const std::string path = dir_ + "/huge.json";
  std::ofstream(path) << R"({"schema": "depthbench.results", "schema_version": 1e999})";
  ExpectRefused({"merge", path, "--json", dir_ + "/merged.json"},
                path + ": not valid JSON: a number beyond the range of a double");
}

// A resolution of 1e300 pixels: refused as out of range (toml++ converted
// such a float to an integer with undefined behaviour; found by fuzz_scene).
TEST_F(BadInputTest, ASceneWithAResolutionBeyondAnyInteger) {
  std::ifstream in(kScene);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string from = "resolution = [2560, 1440]";
  ASSERT_NE(text.find(from), std::string::npos);
  text.replace(text.find(from), from.size(), "resolution = [1e300, 1440]");
  const std::string path = dir_ + "/huge.toml";
  std::ofstream(path) << text;
  ExpectRefused({"choose", "--scene", path}, "projection.resolution: expected [width, height] in pixels, 1 to 65535");
}

// choose_test covers a scene file that does not exist; a folder given as
// the scene is refused as such.
TEST_F(BadInputTest, ASceneThatIsAFolder) {
  ExpectRefused({"choose", "--scene", dir_}, "'" + dir_ + "' is a directory, not a file");
}

// --json - writes the JSON to standard output (the tables go to stderr); a
// standard output that cannot take it (a full disk: /dev/full) is an error,
// exit 2, not a silent success.
TEST_F(BadInputTest, JsonToAStandardOutputThatIsFullFails) {
  const pid_t pid = testing::StartDepthbench({"run", "--backend", "cpu", "--samples", "1e3", "--json", "-"},
                                             "/dev/full", dir_ + "/stderr");
  EXPECT_EQ(testing::WaitForExit(pid, 0), 2);
  EXPECT_NE(testing::ReadText(dir_ + "/stderr").find("cannot write to standard output ('-'): No space left on device"),
            std::string::npos)
      << testing::ReadText(dir_ + "/stderr");
}

}  // namespace
}  // namespace depthbench
