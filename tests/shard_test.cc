// A sweep split into shards that run at once, as a scheduler runs them, and
// merged: the same results as the sweep run whole, with the same seed.
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/command_runner.h"

namespace depthbench {
namespace {

using testing::FinishDepthbench;
using testing::MakeTempDir;
using testing::RunDepthbench;
using testing::StartDepthbench;
using testing::StartedCommand;

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// The fields of a results file's run header that may differ between the
// merge of the shards and the whole run, though the sweep is the same:
//   started_at: each process's own clock when it started (merge keeps the
//               first shard's);
//   seconds, stage_seconds: wall time and its stages, of one process
//               against the sum of the shards'.
// run.shards differs too (the four shards against 1/1); the test checks it
// by itself. Everything else (version, commit, host, seed, samples, domain,
// cells, backends with their devices and shader hashes, the counts judged)
// and every cell's histograms, maxima with their samples and counts must
// be equal.
nlohmann::json WithoutRunSpecificFields(nlohmann::json results) {
  for (const char* field : {"started_at", "seconds", "stage_seconds", "shards"}) results["run"].erase(field);
  return results;
}

TEST(ShardedSweep, ShardsRunAtOnceMergeToTheWholeRun) {
  const std::string dir = MakeTempDir("shard_test");
  constexpr int kShards = 4;
  // Both backends (the CPU and lavapipe) and every cell; 20001 samples make
  // shards of unequal size (5000 and 5001 samples), and batches of 1024
  // give each shard several batches and a short last one. One thread each:
  // the five processes share the machine's cores.
  const std::vector<std::string> sweep = {"run",     "--samples", "20001",     "--seed", "5",
                                          "--batch", "1024",      "--threads", "1",      "--quiet"};
  const auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = sweep;
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  };

  // Every process is started before any is waited for.
  std::vector<StartedCommand> started;
  std::vector<std::string> shard_files;
  for (int k = 1; k <= kShards; ++k) {
    shard_files.push_back(dir + "/shard-" + std::to_string(k) + ".json");
    started.push_back(StartDepthbench(
        with({"--shard", std::to_string(k) + "/" + std::to_string(kShards), "--json", shard_files.back()})));
  }
  started.push_back(StartDepthbench(with({"--json", dir + "/whole.json"})));
  for (const StartedCommand& command : started) {
    const testing::CommandResult result = FinishDepthbench(command);
    ASSERT_EQ(result.exit_code, 0) << result.err;
  }

  std::vector<std::string> merge = {"merge"};
  merge.insert(merge.end(), shard_files.begin(), shard_files.end());
  merge.insert(merge.end(), {"--json", dir + "/merged.json"});
  const testing::CommandResult merged_run = RunDepthbench(merge);
  ASSERT_EQ(merged_run.exit_code, 0) << merged_run.err;
  EXPECT_EQ(merged_run.out.find("PARTIAL"), std::string::npos) << merged_run.out;

  const nlohmann::json whole = ReadJson(dir + "/whole.json");
  const nlohmann::json merged = ReadJson(dir + "/merged.json");
  EXPECT_EQ(whole["run"]["shards"], nlohmann::json::array({"1/1"}));
  EXPECT_EQ(merged["run"]["shards"], nlohmann::json::array({"1/4", "2/4", "3/4", "4/4"}));
  // The sweep did something worth comparing: both backends, every sample.
  ASSERT_EQ(whole["run"]["backends"].size(), 2u);
  ASSERT_EQ(whole["run"]["samples_judged"], 20001);
  ASSERT_GT(whole["cells"].size(), 100u);

  const nlohmann::json a = WithoutRunSpecificFields(whole), b = WithoutRunSpecificFields(merged);
  // On a difference, the JSON Patch from one to the other says where.
  EXPECT_EQ(a, b) << nlohmann::json::diff(a, b).dump(1).substr(0, 4000);
}

}  // namespace
}  // namespace depthbench
