// depthbench merge: adds up the results of the shards of one sweep.

#include <fmt/format.h>

#include "bench/base/files.h"
#include "bench/cli/cli_common.h"
#include "bench/cli/commands.h"
#include "bench/results/results_table.h"

namespace depthbench::cli {
namespace {

struct MergeFlags {
  std::vector<std::string> inputs;
  std::string output;
  bool allow_partial = false;
};

Expected<int> Merge(const MergeFlags& f, const CommandContext& context) {
  const TextOutput& out = context.output;
  DB_RETURN_IF_ERROR(CheckWritable(f.output, "--json"));
  FileRoles roles;
  for (const std::string& path : f.inputs) roles.Input(path, "the input");
  DB_RETURN_IF_ERROR(roles.Output(f.output, "--json").Check());
  // Every input is looked at before any is read (a missing last shard is
  // said at once).
  for (const std::string& path : f.inputs) {
    DB_RETURN_IF_ERROR(CheckReadableFile(path, kMaxJsonFileBytes, "results file"));
  }
  std::vector<Results> parts;
  for (const std::string& path : f.inputs) {
    DB_ASSIGN_OR_RETURN(Results part, ReadResults(path));
    parts.push_back(std::move(part));
  }
  DB_ASSIGN_OR_RETURN(const Results merged, MergeResults(parts, f.inputs, f.allow_partial));
  const std::vector<Shard> missing = MissingShards(merged.run.shards);
  if (!missing.empty() && !f.allow_partial) {
    return InvalidArgument(fmt::format(
        "missing shards {} (the inputs hold {} of {} shards): give every shard, or --allow-partial to write "
        "a merge of the shards given",
        ShardList(missing), merged.run.shards.size(), merged.run.shards.front().count));
  }
  PrintRunHeader(merged, out.text);
  PrintResultsTable(merged, out);
  DB_RETURN_IF_ERROR(WriteResults(f.output, merged));
  return kExitOk;
}

}  // namespace

void AddMergeCommand(CLI::App& app, CommandAction& action) {
  auto flags = std::make_shared<MergeFlags>();
  CLI::App* cmd = app.add_subcommand("merge", "Add up the results of the shards of one sweep (run --shard K/N)");
  cmd->footer(
      "Shards of one sweep share what defines it: version, seed, sample count, domain, cells, backends and "
      "devices, shader directories and the hash of the shader sources compiled; their histograms add up exactly to "
      "the results of running the whole sweep at once. Exit 2 when the inputs differ in any of these (the message "
      "names the field and both values), hold shards of different K/N splits or the same shard twice, when a shard "
      "is missing, or when an input is partial (its run was interrupted), unless --allow-partial.\n\n"
      "Example:\n  depthbench merge part1.json part2.json --json all.json");
  cmd->add_option("inputs", flags->inputs, "results files of shards (depthbench run --shard K/N --json FILE)")
      ->required();
  cmd->add_option("--json", flags->output, "where to write the merged results")->required();
  cmd->add_flag("--allow-partial", flags->allow_partial,
                "merge even when shards are missing or an input was interrupted; the header and the file say so");
  cmd->callback(
      [flags, &action] { action = [flags](const CommandContext& context) { return Merge(*flags, context); }; });
}

}  // namespace depthbench::cli
