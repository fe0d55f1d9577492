#include "bench/cli/app.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <map>
#include <string>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "bench/base/build_info.h"
#include "bench/base/files.h"
#include "bench/base/interrupt.h"
#include "bench/base/resources.h"
#include "bench/base/suggest.h"
#include "bench/base/text_table.h"
#include "bench/cli/cli_common.h"
#include "bench/cli/commands.h"
#include "bench/pipeline/user_variant.h"

namespace depthbench::cli {
namespace {

// The one place where a command that could not run becomes a message
// ("depthbench: error: ...") and exit code 2. A command that returns after
// SIGINT or SIGTERM (its long work stopped early) ends with 128 + signal,
// whatever it returned.
int ExitCode(const Expected<int>& ran) {
  if (ran.ok() && Interrupted()) return ReportError(InterruptedError("what was written is partial"));
  return ran.ok() ? *ran : ReportError(ran.status());
}

// What an option takes, for --help, where its declaration leaves CLI11
// to say TEXT (counts are read as text so that 1e6 parses, files as
// strings): one table for every subcommand, by flag.
void NameOptionTypes(CLI::App& app) {
  static const std::map<std::string, std::string> kTypes{{"--samples", "N"},
                                                         {"--default-samples", "N"},
                                                         {"--accuracy-samples", "N"},
                                                         {"--against-random", "N"},
                                                         {"--cases", "N"},
                                                         {"--index", "N"},
                                                         {"--seed", "N"},
                                                         {"--threads", "N"},
                                                         {"--batch", "N"},
                                                         {"--warmup", "N"},
                                                         {"--repetitions", "N"},
                                                         {"--taps", "N"},
                                                         {"--seconds", "SECONDS"},
                                                         {"--shard", "K/N"},
                                                         {"--level", "LEVEL"},
                                                         {"--split", "BAND[,BAND]"},
                                                         {"--json", "FILE|-"},
                                                         {"--junit", "FILE"},
                                                         {"--summary", "FILE"},
                                                         {"--scene", "FILE"},
                                                         {"--baseline", "FILE"},
                                                         {"--results", "FILE"},
                                                         {"--repro", "FILE"},
                                                         {"--speed", "FILE"},
                                                         {"--compare", "FILE"},
                                                         {"--known", "FILE"},
                                                         {"--history", "FILE"},
                                                         {"--template", "FILE"},
                                                         {"--plot-library", "FILE"},
                                                         {"--shaders", "DIR"},
                                                         {"--variant-file", "FILE"},
                                                         {"--out", "DIR"},
                                                         {"--backend", "NAME[,NAME]"},
                                                         {"--device", "NAME"},
                                                         {"--variant", "NAME[,NAME]"},
                                                         {"--convention", "NAME[,NAME]"},
                                                         {"--format", "NAME[,NAME]"},
                                                         {"--domain", "NAME|FILE"},
                                                         {"--production", "MODEL"},
                                                         {"--constants", "MODEL"},
                                                         {"--resolution", "WxH[,WxH]"},
                                                         {"--corpus", "PATH"},
                                                         {"inputs", "FILE"}};
  for (CLI::App* sub : app.get_subcommands({})) {
    for (CLI::Option* option : sub->get_options()) {
      if (option->get_type_name().rfind("TEXT", 0) != 0 && !option->get_type_name().empty()) continue;
      std::vector<std::string> keys{option->get_name(true, false)};
      for (const std::string& name : option->get_lnames()) keys.push_back("--" + name);
      for (const std::string& key : keys) {
        auto it = kTypes.find(key);
        if (it != kTypes.end()) option->type_name(it->second);
      }
    }
  }
}

// Every --json says that '-' is standard output.
void DescribeStandardOutput(CLI::App& app) {
  for (CLI::App* sub : app.get_subcommands({})) {
    CLI::Option* json = sub->get_option_no_throw("--json");
    if (json == nullptr) continue;
    json->description(json->get_description() + " ('-': standard output, and the tables go to standard error)");
  }
}

// "depthbench SUB: error: unknown option '--x'; did you mean '--y'?" for
// each flag in argv that subcommand `sub` (and the program) does not know.
std::string UnknownOptions(const CLI::App& sub, int argc, const char* const* argv) {
  std::vector<std::string> flags;
  for (const CLI::App* app : {&sub, sub.get_parent()}) {
    if (app == nullptr) continue;
    for (const CLI::Option* option : app->get_options()) {
      for (const std::string& name : option->get_lnames()) flags.push_back("--" + name);
    }
  }
  std::string message;
  for (int k = 1; k < argc; ++k) {
    const std::string word(argv[k]);
    if (word == "--") break;
    if (word.rfind("--", 0) != 0) continue;
    const std::string flag = word.substr(0, word.find('='));
    if (std::find(flags.begin(), flags.end(), flag) != flags.end()) continue;
    message +=
        fmt::format("depthbench {}: error: unknown option '{}'{}\n", sub.get_name(), flag, DidYouMean(flag, flags));
  }
  return message;
}

// Seeds and thread counts are read strictly: CLI11 would wrap -1 to
// 2^64 - 1, clamp what is past 2^64 and read '' as 0.
constexpr unsigned kMostThreads = 1024;
std::string WholeNumberError(const std::string& text, std::uint64_t most, const std::string& what) {
  const bool digits = !text.empty() && text.size() <= 20 &&
                      std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
  // Twenty digits may still pass 2^64 - 1: compare as text of equal length.
  const std::string largest = std::to_string(most);
  const bool in_range = digits && (text.size() < largest.size() || (text.size() == largest.size() && text <= largest));
  return in_range ? "" : fmt::format("'{}' is not {} from 0 to {}", text, what, most);
}
void CheckWholeNumbers(CLI::App& app) {
  for (CLI::App* sub : app.get_subcommands({})) {
    for (CLI::Option* option : sub->get_options()) {
      if (option->check_lname("seed")) {
        option->check(CLI::Validator(
            [](std::string& text) {
              return WholeNumberError(text, std::numeric_limits<std::uint64_t>::max(), "a whole number");
            },
            ""));
      } else if (option->check_lname("threads")) {
        option->check(CLI::Validator(
            [](std::string& text) { return WholeNumberError(text, kMostThreads, "a thread count (0: one per core)"); },
            ""));
      }
    }
  }
}

// --variant-file, of every subcommand that runs variants: once the command
// line is parsed, the files make the catalogue the command runs with.
void AddVariantFileOption(CLI::App& app, std::vector<std::string>& files) {
  for (const char* name : {"list", "run", "fit", "gate", "choose", "speed", "report", "bound"}) {
    app.get_subcommand(name)
        ->add_option("--variant-file", files,
                     "a reconstruction function of your own, in GLSL (.glsl) or HLSL (.hlsl), run as one more "
                     "variant named after the file (repeatable). Its '// depthbench:' line declares what it reads "
                     "and its conventions (docs/variant-files.md). It runs on Vulkan only: with it, the default "
                     "--backend is vulkan")
        ->group("Cells");
  }
}

// Whether the chosen subcommand writes its JSON to standard output
// (--json -).
bool WritesJsonToStandardOutput(const CLI::App& app) {
  for (const CLI::App* sub : app.get_subcommands()) {
    const CLI::Option* json = sub->get_option_no_throw("--json");
    if (json != nullptr && json->count() > 0 && json->results().back() == kStandardOutputName) return true;
  }
  return false;
}

}  // namespace

TableStyle CommandLine::table_style() const {
  const std::map<std::string, TableFormat> formats{{"text", TableFormat::kText},
                                                   {"csv", TableFormat::kCsv},
                                                   {"markdown", TableFormat::kMarkdown},
                                                   {"json", TableFormat::kJson}};
  return {formats.at(table_format), wide ? 0 : kTerminalColumns};
}

std::unique_ptr<CLI::App> MakeDepthbenchApp(CommandLine& line) {
  auto app = std::make_unique<CLI::App>(
      "depthbench: measures how precisely shader code reconstructs view- and world-space position "
      "from a depth buffer, for every variant, depth convention and storage format, on the GPU "
      "(Vulkan) and the CPU",
      "depthbench");
  app->require_subcommand(1);
  // Flags of the whole program, taken after a subcommand's name too.
  app->fallthrough();
  app->add_flag(
      "--wide", line.wide,
      "print tables as wide as their contents; by default they fit 120 columns, leaving secondary columns out "
      "(a line after each table names them)");
  app->add_option("--table-format", line.table_format,
                  "how tables are printed: text (aligned, for people; the default), or csv, markdown or json (every "
                  "column; the tables alone go to standard output, the lines around them to standard error)")
      ->check(CLI::IsMember({"text", "csv", "markdown", "json"}));
  app->set_version_flag("--version", [] {
    const Expected<DataFolder> data = FindDataFolder();
    return fmt::format(
        "depthbench {} (commit {})\ndata folder: {}", BuildVersion(), BuildCommit(),
        data.ok() ? fmt::format("{} ({})", data->root.string(), data->found_by) : data.status().message());
  });
  app->footer(
      "Run 'depthbench SUBCOMMAND --help' for a subcommand's flags.\n"
      "Exit codes: 0 success, 1 a finding (a gate that fails, a fuzz finding), 2 could not run.");
  AddListCommand(*app, line.action);
  AddRunCommand(*app, line.action);
  AddMergeCommand(*app, line.action);
  AddSpeedCommand(*app, line.action);
  AddGateCommand(*app, line.action);
  AddFitCommand(*app, line.action);
  AddChooseCommand(*app, line.action);
  AddReportCommand(*app, line.action);
  AddFuzzCommand(*app, line.action);
  AddBoundCommand(*app, line.action);
  AddVariantFileOption(*app, line.variant_files);
  NameOptionTypes(*app);
  DescribeStandardOutput(*app);
  CheckWholeNumbers(*app);
  return app;
}

ParseOutcome ParseCommandLine(CLI::App& app, int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  // A first word that is neither a flag nor a subcommand gets a message
  // that names it (CLI11 would only say a subcommand is required).
  if (argc > 1 && argv[1][0] != '-' &&
      app.get_subcommands([&](const CLI::App* sub) { return sub->get_name() == argv[1]; }).empty()) {
    std::vector<std::string> names;
    for (const CLI::App* sub : app.get_subcommands({})) names.push_back(sub->get_name());
    err << "depthbench: error: unknown subcommand '" << argv[1]
        << "'; available: " << fmt::format("{}", fmt::join(names, ", ")) << DidYouMean(argv[1], names)
        << " (see depthbench --help)\n";
    return {false, kExitCannotRun};
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // An option that no subcommand knows is named, with the flag it could
    // have been, whatever else CLI11 found wrong (a required flag then
    // looks missing).
    const std::vector<CLI::App*> chosen = app.get_subcommands();
    const std::string unknown = chosen.empty() ? "" : UnknownOptions(*chosen.front(), argc, argv);
    if (e.get_exit_code() != 0 && !unknown.empty()) {
      err << unknown << fmt::format("(see depthbench {} --help)\n", chosen.front()->get_name());
      return {false, kExitCannotRun};
    }
    const int code = app.exit(e, out, err);
    return {false, code == 0 ? kExitOk : kExitCannotRun};
  }
  // An option given an empty value ('--near ""', often an unset shell
  // variable) is refused: read as "not given", it would silently change
  // what runs.
  for (const CLI::App* sub : app.get_subcommands()) {
    for (const CLI::Option* option : sub->get_options()) {
      if (option->get_expected_min() == 0) continue;  // a flag without a value
      for (const std::string& value : option->results()) {
        if (!value.empty()) continue;
        err << fmt::format(
            "depthbench: error: {}: empty value; give a value or leave the option out (see depthbench {} --help)\n",
            option->get_name(), sub->get_name());
        return {false, kExitCannotRun};
      }
    }
  }
  return {true, kExitOk};
}

int RunDepthbench(int argc, const char* const* argv) {
  // First of all: a signal that comes while the program starts is kept too.
  InstallInterruptHandlers();
  // Help and refusals fit 120 columns.
  std::streambuf* const standard_output = std::cout.rdbuf();
  auto wrapped = std::make_unique<WrappedOutput>(std::cout, kTerminalColumns);
  CommandLine line;
  std::unique_ptr<CLI::App> app = MakeDepthbenchApp(line);
  const ParseOutcome parsed = ParseCommandLine(*app, argc, argv, std::cout, std::cerr);
  if (!parsed.run) return parsed.exit_code;
  const Expected<std::unique_ptr<const Catalogue>> catalogue = MakeCatalogue(line.variant_files);
  if (!catalogue.ok()) return ReportError(catalogue.status());
  const TableStyle style = line.table_style();
  const bool tables_for_machines = style.format != TableFormat::kText;
  wrapped.reset();
  if (WritesJsonToStandardOutput(*app) || tables_for_machines) {
    // Standard output carries the JSON or the tables alone (a user pipes
    // them); what is printed for people goes to standard error instead.
    std::cout.rdbuf(std::cerr.rdbuf());
  }
  // Lines for people fit the style's width (none with --wide).
  wrapped = std::make_unique<WrappedOutput>(std::cout, style.max_width);
  // Tables for machines: they alone on standard output.
  std::ostream tables(standard_output);
  const TextOutput output(std::cout, tables_for_machines ? tables : std::cout, style);
  const int code = line.action ? ExitCode(line.action(CommandContext{**catalogue, output})) : kExitCannotRun;
  wrapped.reset();
  std::cout.rdbuf(standard_output);
  if (AbandonedThreads()) {
    // A thread still runs work that cannot be stopped: end here, before
    // the static objects it may use are destroyed.
    std::fflush(nullptr);
    std::_Exit(code);
  }
  return code;
}

}  // namespace depthbench::cli
