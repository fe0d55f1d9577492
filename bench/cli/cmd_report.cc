// depthbench report: the nightly precision report (HTML page with plots,
// Markdown summary, JSON document) and its history across runs.
#include <filesystem>
#include <iostream>
#include <memory>

#include <fmt/format.h>

#include "bench/base/environment.h"
#include "bench/base/files.h"
#include "bench/base/progress.h"
#include "bench/cli/cli_common.h"
#include "bench/cli/commands.h"
#include "bench/report/report.h"
#include "bench/report/report_render.h"

namespace depthbench::cli {
namespace {

namespace fs = std::filesystem;

const fs::path kSourceDir = DEPTHBENCH_SOURCE_DIR;

struct ReportFlags {
  std::string out;
  bool quick = false;
  std::string history = (kSourceDir / "reports" / "history.sqlite").string();
  bool no_history = false;
  std::string samples, default_samples;
  std::uint64_t seed = 7;
  std::vector<std::string> speed;
  bool no_speed = false;
  std::string plot_library = (kSourceDir / "reports" / "node_modules").string();
  std::string page_template = (kSourceDir / "reports" / "report_template.html").string();
  bool fail_on_regression = false;
  CellFlags cells;
  BackendFlags backends;
};

// The speed files: those named, or every one committed under reports/speed.
std::vector<fs::path> SpeedFiles(const ReportFlags& f) {
  std::vector<fs::path> files;
  if (f.no_speed) return files;
  if (!f.speed.empty()) return {f.speed.begin(), f.speed.end()};
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(kSourceDir / "reports" / "speed", ec)) {
    const std::string name = entry.path().filename().string();
    // "x.repeat.json" files repeat "x.json" (a repeatability check): one is enough.
    if (entry.path().extension() == ".json" && name.find(".repeat.") == std::string::npos) {
      files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

int Report(const ReportFlags& f) {
  ReportPlan plan = f.quick ? ReportPlan::Quick() : ReportPlan::Nightly();
  if (!f.samples.empty()) {
    auto samples = ParseCount(f.samples, "--samples");
    if (!samples.ok()) return ReportError(samples.status());
    plan.fit.samples_per_ratio = *samples;
  }
  if (!f.default_samples.empty()) {
    auto samples = ParseCount(f.default_samples, "--default-samples");
    if (!samples.ok()) return ReportError(samples.status());
    plan.main_samples = *samples;
  }
  plan.fit.seed = f.seed;
  plan.shader_dir = f.backends.shaders;
  auto cells = f.cells.Select();
  if (!cells.ok()) return ReportError(cells.status());
  if (cells->size() != AllCells().size()) plan.cells = *cells;
  plan.speed_files = SpeedFiles(f);
  for (const fs::path& file : plan.speed_files) {
    if (!fs::is_regular_file(file))
      return ReportError(NotFound(fmt::format("--speed: {} does not exist", file.string())));
  }

  // Everything that can be refused is refused before the sweeps run.
  if (f.out.empty()) return ReportError(InvalidArgument("--out: give the folder to write the report into"));
  std::error_code ec;
  fs::create_directories(f.out, ec);
  if (ec || !fs::is_directory(f.out)) {
    return ReportError(IoError(fmt::format("--out: cannot create folder '{}': {}", f.out, ec.message())));
  }
  Status writable = CheckWritable((fs::path(f.out) / "results.json").string(), "--out");
  if (!writable.ok()) return ReportError(writable);
  const PlotLibrary library{f.plot_library};
  Status library_ok = library.Check();
  if (!library_ok.ok()) return ReportError(library_ok);
  if (!fs::is_regular_file(f.page_template)) {
    return ReportError(NotFound(fmt::format("--template: {} does not exist", f.page_template)));
  }
  std::optional<History> history;
  if (!f.no_history) {
    auto opened = History::Open(f.history);
    if (!opened.ok()) return ReportError(opened.status().WithContext("--history"));
    history = std::move(*opened);
  }
  auto made = f.backends.Make();
  if (!made.ok()) return ReportError(made.status());
  std::vector<Backend*> backends;
  for (auto& b : *made) backends.push_back(b.get());

  const bool terminal = StderrIsTerminal();
  std::unique_ptr<Progress> stage;
  ReportProgress progress;
  progress.begin = [&](const std::string& name) { stage = std::make_unique<Progress>(name, terminal); };
  progress.sweep = [&](const SweepProgress& p) { stage->Update(p.fraction(), p.Describe()); };
  progress.fits = [&](std::size_t done, std::size_t total) {
    stage->Update(total == 0 ? 1.0 : static_cast<double>(done) / static_cast<double>(total),
                  fmt::format("{}/{} cells fitted", done, total));
  };
  progress.end = [&](const std::string& summary) { stage->Finish(summary); };

  const std::string started_at = CurrentTimeUtc();
  auto measured = MeasureReport(plan, backends, progress);
  if (!measured.ok()) return ReportError(measured.status());

  progress.begin("write");
  nlohmann::json report = ReportJson(plan, *measured);
  int worse = 0;
  if (history) {
    HistoryRun run;
    run.made_at = started_at;
    run.commit = measured->main.run.commit;
    run.host = measured->main.run.host;
    run.version = measured->main.run.version;
    run.quick = plan.quick;
    run.seconds = report["environment"].value("seconds", 0.0);
    Status added = AddHistory(report, *history, run, HistoryFigures(*measured), plan.trend_runs);
    if (!added.ok()) return ReportError(added.WithContext("--history"));
    for (const auto& change : report["history"]["changes"]) worse += change.value("direction", "") == "worse";
  }
  auto page = RenderHtml(report, f.page_template, library);
  if (!page.ok()) return ReportError(page.status());
  const std::string markdown = RenderMarkdown(report);
  const fs::path out(f.out);
  for (const auto& [name, text] : {std::pair<const char*, std::string>{"results.json", report.dump(1) + "\n"},
                                   {"report.md", markdown},
                                   {"report.html", *page}}) {
    Status written = WriteFileAtomically(out / name, text);
    if (!written.ok()) return ReportError(written);
  }
  progress.end(fmt::format("{} (report.html, report.md, results.json)", out.string()));

  std::cout << markdown;
  return worse > 0 && f.fail_on_regression ? kExitFinding : kExitOk;
}

}  // namespace

void AddReportCommand(CLI::App& app, std::function<int()>& action) {
  auto flags = std::make_shared<ReportFlags>();
  CLI::App* cmd = app.add_subcommand(
      "report", "The nightly precision report: HTML page with plots, Markdown summary, JSON, and history");
  cmd->footer(
      "Runs every cell on every backend at far/near 10^1, 10^1.5, ..., 10^8 and with an infinite far plane (camera "
      "at the origin), fits the error models, runs the default domain (every projection, pose and depth), reads "
      "the speed files, and writes into --out:\n"
      "  report.html   one self-contained page (opens offline) with interactive Vega-Lite plots: bits lost against "
      "far/near with the fitted model and its confidence band; error against eye depth with the 1e-3 and 1e-6 "
      "guide lines; the storage/arithmetic split; GPU against CPU; the speed/accuracy front; the trend across runs; "
      "NaN/Inf findings and the worst samples with the command that replays each; the environment\n"
      "  report.md     a short summary for a CI job page: what changed since the last run, the headline per "
      "convention and format, the worst cells\n"
      "  results.json  everything the page shows (schema depthbench.report v1, reports/report.schema.json)\n"
      "Each run is recorded in the history database (per cell and band: bits lost at p99.9 and max, NaN and Inf), "
      "and compared with the previous run of the same sample plan on the same device with the gate's tolerances.\n\n"
      "Examples:\n"
      "  depthbench report --out reports/out\n"
      "  depthbench report --quick --out /tmp/report --history /tmp/history.sqlite\n"
      "  depthbench report --out out --backend vulkan --device nvidia --speed reports/speed/nvidia-h200.json");
  cmd->add_option("--out", flags->out, "folder to write report.html, report.md and results.json into (created)")
      ->required();
  cmd->add_flag("--quick", flags->quick,
                "fewer samples (4e4 per far/near ratio, 1e5 default-domain), same page: seconds, not minutes");
  cmd->add_option("--history", flags->history, "SQLite history database (created if missing)")->capture_default_str();
  cmd->add_flag("--no-history", flags->no_history, "neither read nor record history");
  cmd->add_option("--samples", flags->samples, "samples per far/near ratio (default 3e5; quick 4e4)");
  cmd->add_option("--default-samples", flags->default_samples,
                  "samples of the default-domain sweep (default 1e6; quick 1e5)");
  cmd->add_option("--seed", flags->seed, "seed of the far/near sweeps (default 7)");
  cmd->add_option("--speed", flags->speed,
                  "speed files (depthbench speed --json) for the speed/accuracy front (default: every "
                  "reports/speed/*.json)");
  cmd->add_flag("--no-speed", flags->no_speed, "no speed files: the front uses instruction counts only");
  cmd->add_option("--plot-library", flags->plot_library,
                  "node_modules folder holding vega, vega-lite and vega-embed (npm ci --prefix reports)")
      ->capture_default_str();
  cmd->add_option("--template", flags->page_template, "the page's HTML template")->capture_default_str();
  cmd->add_flag("--fail-on-regression", flags->fail_on_regression,
                "exit 1 when a cell got worse since the previous comparable run");
  flags->cells.Add(*cmd);
  flags->backends.Add(*cmd);
  cmd->callback([flags, &action] { action = [flags] { return Report(*flags); }; });
}

}  // namespace depthbench::cli
