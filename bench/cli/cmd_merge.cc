// depthbench merge: adds up the results of the shards of one sweep.
#include <iostream>

#include <fmt/format.h>

#include "bench/cli/cli_common.h"
#include "bench/cli/commands.h"
#include "bench/results/results_table.h"

namespace depthbench::cli {
namespace {

struct MergeFlags {
  std::vector<std::string> inputs;
  std::string output;
};

Expected<int> Merge(const MergeFlags& f) {
  DB_RETURN_IF_ERROR(CheckWritable(f.output, "--json"));
  std::vector<Results> parts;
  for (const std::string& path : f.inputs) {
    DB_ASSIGN_OR_RETURN(Results part, ReadResults(path));
    parts.push_back(std::move(part));
  }
  DB_ASSIGN_OR_RETURN(const Results merged, MergeResults(parts));
  std::uint64_t covered = 0;
  for (const Shard& s : merged.run.shards) covered += s.End(merged.run.samples) - s.Begin(merged.run.samples);
  PrintRunHeader(merged, std::cout);
  PrintResultsTable(merged, std::cout);
  if (covered != merged.run.samples) {
    std::cout << fmt::format("\nnote: the merged shards cover {} of the sweep's {} samples\n", covered,
                             merged.run.samples);
  }
  DB_RETURN_IF_ERROR(WriteResults(f.output, merged));
  return kExitOk;
}

}  // namespace

void AddMergeCommand(CLI::App& app, CommandAction& action) {
  auto flags = std::make_shared<MergeFlags>();
  CLI::App* cmd = app.add_subcommand("merge", "Add up the results of the shards of one sweep (run --shard K/N)");
  cmd->footer(
      "Shards of one sweep share seed, sample count and domain; their histograms add up exactly to "
      "the results of running the whole sweep at once.\n\n"
      "Example:\n  depthbench merge part1.json part2.json --json all.json");
  cmd->add_option("inputs", flags->inputs, "results files of shards (depthbench run --shard K/N --json FILE)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--json", flags->output, "where to write the merged results")->required();
  cmd->callback([flags, &action] { action = [flags] { return Merge(*flags); }; });
}

}  // namespace depthbench::cli
