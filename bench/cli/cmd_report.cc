// depthbench report: the nightly precision report (HTML page with plots,
// Markdown summary, JSON document) and its history across runs.
#include <filesystem>
#include <memory>

#include <fmt/format.h>

#include "bench/base/environment.h"
#include "bench/base/files.h"
#include "bench/base/interrupt.h"
#include "bench/base/progress.h"
#include "bench/base/resources.h"
#include "bench/capture/depth_capture.h"
#include "bench/cli/cli_common.h"
#include "bench/cli/commands.h"
#include "bench/report/report.h"
#include "bench/report/report_json.h"
#include "bench/report/report_render.h"

namespace depthbench::cli {
namespace {

namespace fs = std::filesystem;

struct ReportFlags {
  std::string out;
  bool quick = false;
  std::string history;  // default: history.sqlite in the user's data folder
  bool no_history = false;
  std::string samples, default_samples;
  std::uint64_t seed = 7;
  std::vector<std::string> speed;
  std::string scene;
  std::string summary;
  bool no_speed = false;
  std::string plot_library;   // default: the data folder's
  std::string page_template;  // default: the data folder's
  bool fail_on_regression = false;
  DomainFlags domain;
  CellFlags cells;
  BackendFlags backends;
};

// The speed files: those named, or every one of the data folder's
// reports/speed (committed under reports/speed in the source tree).
Expected<std::vector<fs::path>> SpeedFiles(const ReportFlags& f) {
  std::vector<fs::path> files;
  if (f.no_speed) return files;
  if (!f.speed.empty()) return std::vector<fs::path>(f.speed.begin(), f.speed.end());
  return CommittedSpeedFiles();
}

// The files a report writes can be written, and none is a file it reads
// (the history is read and written in place; the pages are written).
Status CheckReportFiles(const ReportFlags& f) {
  FileRoles roles;
  roles.Input(f.history, "--history").Input(f.scene, "--scene").Input(f.page_template, "--template");
  for (const std::string& speed : f.speed) roles.Input(speed, "--speed");
  for (const char* name : {"results.json", "report.md", "report.html", kCaptureImageName}) {
    const std::string path = (fs::path(f.out) / name).string();
    DB_RETURN_IF_ERROR(CheckWritable(path, "--out"));
    roles.Output(path, "--out");
  }
  if (!f.summary.empty()) DB_RETURN_IF_ERROR(CheckWritable(f.summary, "--summary"));
  return roles.Output(f.summary, "--summary").Check();
}

// The report's files under `out`: the capture's picture first (before the
// page that shows it), each under a temporary name and renamed.
Status WriteReportFiles(const fs::path& out, const Report& report,
                        const std::optional<ReportMeasurements::CaptureBits>& capture, const std::string& markdown,
                        const std::string& page) {
  if (capture) {
    const fs::path image = out / kCaptureImageName, partial = out / (std::string(kCaptureImageName) + ".partial");
    DB_RETURN_IF_ERROR(WriteBitsLostPng(partial, capture->width, capture->height, capture->bits));
    std::error_code ec;
    fs::rename(partial, image, ec);
    if (ec) return IoError(fmt::format("--out: cannot write '{}': {}", image.string(), ec.message()));
  }
  for (const auto& [name, text] :
       {std::pair<const char*, std::string>{"results.json", ReportToJson(report).dump(1) + "\n"},
        {"report.md", markdown},
        {"report.html", page}}) {
    DB_RETURN_IF_ERROR(WriteFileAtomically(out / name, text));
  }
  return Status::Ok();
}

Expected<int> RunReport(const ReportFlags& f, const CommandContext& context) {
  ReportPlan plan = f.quick ? ReportPlan::Quick() : ReportPlan::Nightly();
  if (!f.samples.empty()) {
    DB_ASSIGN_OR_RETURN(plan.fit.samples_per_ratio, ParseCount(f.samples, "--samples"));
  }
  if (!f.default_samples.empty()) {
    DB_ASSIGN_OR_RETURN(plan.main_samples, ParseCount(f.default_samples, "--default-samples"));
  }
  plan.fit.seed = f.seed;
  // The default-domain sweep's domain; the fit sweeps take its lens,
  // planes and targets, with the camera at the origin and their own ratios.
  DB_ASSIGN_OR_RETURN(plan.main_domain, f.domain.Apply(plan.main_domain, context.catalogue));
  plan.fit.domain = plan.main_domain;
  plan.fit.domain.camera_distance = {0.0, 0.0};
  plan.shader_dir = f.backends.shaders;
  DB_ASSIGN_OR_RETURN(plan.cells, f.cells.Select(context.catalogue));
  plan.catalogue = &context.catalogue;
  DB_ASSIGN_OR_RETURN(plan.speed_files, SpeedFiles(f));
  plan.speed_files_named = !f.speed.empty();
  for (const fs::path& file : plan.speed_files) {
    DB_RETURN_IF_ERROR(CheckReadableFile(file, kMaxJsonFileBytes).WithContext("--speed"));
  }
  // A scene file given as the domain is the scene the report opens on too.
  const std::string& scene_file = !f.scene.empty() || !IsSceneFile(f.domain.domain) ? f.scene : f.domain.domain;
  if (!scene_file.empty()) {
    DB_ASSIGN_OR_RETURN(plan.scene, LoadScene(scene_file, context.catalogue));
  }

  // Everything that can be refused is refused before the sweeps run.
  if (f.out.empty()) return InvalidArgument("--out: give the folder to write the report into");
  std::error_code ec;
  const bool out_existed = fs::exists(f.out, ec);
  fs::create_directories(f.out, ec);
  if (ec || !fs::is_directory(f.out)) {
    return IoError(fmt::format("--out: cannot create folder '{}': {}", f.out, ec.message()));
  }
  // A folder made here and left empty by a failure is removed again.
  struct RemoveIfLeftEmpty {
    fs::path folder;
    ~RemoveIfLeftEmpty() {
      std::error_code ignored;
      if (!folder.empty() && fs::is_empty(folder, ignored)) fs::remove(folder, ignored);
    }
  } made_out{out_existed ? fs::path() : fs::path(f.out)};
  DB_RETURN_IF_ERROR(CheckReportFiles(f));
  PlotLibrary library{f.plot_library};
  if (library.node_modules.empty())
    DB_RETURN_IF_ERROR(StoreInto(DataPath("reports/node_modules"), library.node_modules));
  fs::path page_template = f.page_template;
  if (page_template.empty()) DB_RETURN_IF_ERROR(StoreInto(DataPath("reports/report_template.html"), page_template));
  DB_RETURN_IF_ERROR(CheckReadableFile(page_template, kMaxSourceFileBytes).WithContext("--template"));
  DB_RETURN_IF_ERROR(CheckReportTemplate(page_template).WithContext("--template"));
  DB_RETURN_IF_ERROR(library.Check());
  std::optional<History> history;
  if (!f.no_history) {
    const fs::path path = f.history.empty() ? UserDataFolder() / "history.sqlite" : fs::path(f.history);
    DB_RETURN_IF_ERROR(StoreInto(History::Open(path), history).WithContext("--history"));
  }
  DB_ASSIGN_OR_RETURN(const BackendSet made, f.backends.Make(context.catalogue));
  const std::span<Backend* const> backends = made.view();

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
  // A report is made of whole sweeps: one cut short by a signal would be
  // written as if whole and compared with the history as if it were.
  if (Interrupted()) {
    return InterruptedError("nothing was written or recorded: the report's sweeps were cut short");
  }
  if (!measured.ok()) return measured.status();

  progress.begin("write");
  Report report = BuildReport(plan, *measured);
  // A page with no fitted cell would pass for a report: nothing is written
  // or recorded.
  if (report.headline.empty()) {
    return InvalidArgument(
        fmt::format("--samples: no cell could be fitted at p99.9 from {} samples per far/near ratio (a model needs "
                    "bands of {} samples or more at each ratio); try 1e5",
                    plan.fit.samples_per_ratio, MinimumSamples(Level::kP999)));
  }
  if (history) {
    HistoryRun run;
    run.made_at = started_at;
    run.commit = measured->main.run.commit;
    run.host = measured->main.run.host;
    run.version = measured->main.run.version;
    run.quick = plan.quick;
    run.seconds = report.environment.seconds.value_or(0.0);
    DB_RETURN_IF_ERROR(
        AddHistory(report, *history, run, HistoryFigures(*measured), plan.trend_runs).WithContext("--history"));
  }
  const std::size_t worse = report.history ? report.history->worse() : 0;
  DB_ASSIGN_OR_RETURN(const std::string page, RenderHtml(report, page_template, library));
  const std::string markdown = RenderMarkdown(report);
  const fs::path out(f.out);
  DB_RETURN_IF_ERROR(WriteReportFiles(out, report, measured->capture_bits, markdown, page));
  DB_RETURN_IF_ERROR(WriteSummary(f.summary, markdown));
  // The run is kept in the history only now that its report is written.
  if (history) DB_RETURN_IF_ERROR(history->Commit().WithContext("--history"));
  progress.end(fmt::format("{} (report.html, report.md, results.json)", out.string()));
  // Writing takes a moment and is not cut short by a first signal (a
  // second one removes what is being written); a signal that came during
  // it stops nothing that was left.
  if (Interrupted()) {
    return InterruptedError(fmt::format("the report was whole: it is written to {}{}", out.string(),
                                        history ? " and recorded in the history" : ""));
  }

  context.output.text << markdown;
  return worse > 0 && f.fail_on_regression ? kExitFinding : kExitOk;
}

}  // namespace

void AddReportCommand(CLI::App& app, CommandAction& action) {
  auto flags = std::make_shared<ReportFlags>();
  CLI::App* cmd = app.add_subcommand(
      "report", "The nightly precision report: HTML page with plots, Markdown summary, JSON, and history");
  cmd->footer(
      "Runs every cell on every backend at far/near 10^1, 10^1.5, ..., 10^8 and with an infinite far plane (camera "
      "at the origin), fits the error models, runs the default domain (every projection, pose and depth), reads "
      "the speed files, and writes into --out:\n"
      "  report.html   one self-contained page (opens offline): first, what to use per convention and format "
      "(the recommended variant or tied set, its p99.9 bits at the far plane with its interval, its cost on the best "
      "device measured, the far/near where it stops meeting 1e-3 and 1e-6); then bits lost against far/near for "
      "every convention and format on one scale with theory lines; error against eye depth; the storage/arithmetic "
      "split; GPU against CPU; the speed/accuracy front per convention and format; the trend across runs; findings "
      "grouped by cause, with the command that replays each; the environment\n"
      "  report.md     a CI job summary of at most about 40 lines: a verdict line (worse/better/unchanged since the "
      "last run), what to use, the worst cells and finding causes, a pointer to report.html\n"
      "  results.json  everything the page shows (schema depthbench.report v2, reports/report.schema.json)\n"
      "Each run is recorded in the history database (per cell and band: bits lost at p99.9 and max, NaN and Inf), "
      "and compared with the previous run of the same sample plan on the same device with the gate's tolerances.\n\n"
      "Examples:\n"
      "  depthbench report --out reports/out\n"
      "  depthbench report --quick --out /tmp/report --history /tmp/history.sqlite\n"
      "  depthbench report --out out --backend vulkan --device nvidia --speed reports/speed/nvidia-h200.json");
  cmd->add_option("--out", flags->out, "folder to write report.html, report.md and results.json into (created)")
      ->required();
  cmd->add_option("--summary", flags->summary,
                  std::string(kSummaryHelp) + " (the same text as report.md)");
  cmd->add_flag("--quick", flags->quick,
                "fewer samples (4e4 per far/near ratio, 1e5 default-domain), same page: seconds, not minutes");
  cmd->add_option("--history", flags->history,
                  "SQLite history database, created if missing (default: history.sqlite in $XDG_DATA_HOME/depthbench, "
                  "else ~/.local/share/depthbench)");
  cmd->add_flag("--no-history", flags->no_history, "neither read nor record history");
  cmd->add_option("--samples", flags->samples, "samples per far/near ratio (default 3e5; quick 4e4)");
  cmd->add_option("--default-samples", flags->default_samples,
                  "samples of the default-domain sweep (default 1e6; quick 1e5)");
  cmd->add_option("--seed", flags->seed, "seed of the far/near sweeps (default 7)");
  cmd->add_option("--speed", flags->speed,
                  "speed files (depthbench speed --json) for the speed/accuracy front and the first screen's costs, "
                  "each labelled with the device it was measured on (default: the reports/speed/*.json committed "
                  "with depthbench that were measured on a device this report runs on)");
  cmd->add_flag("--no-speed", flags->no_speed, "no speed files: the front uses the static cost model only");
  cmd->add_option("--scene", flags->scene,
                  "a scene file (TOML, see bench/scenes/): the first screen opens on its choice, as depthbench "
                  "choose makes it: per convention and format its engine allows, whether the requirement is met. "
                  "--domain SCENE.toml opens on that scene too, and sweeps its domain");
  cmd->add_option("--plot-library", flags->plot_library,
                  "node_modules folder holding vega, vega-lite and vega-embed (default: the data folder's "
                  "reports/node_modules, which ./setup.sh installs with npm ci --prefix reports)");
  cmd->add_option("--template", flags->page_template,
                  "the page's HTML template (default: the data folder's reports/report_template.html)");
  cmd->add_flag("--fail-on-regression", flags->fail_on_regression,
                "exit 1 when a cell got worse since the previous comparable run");
  flags->domain.Add(*cmd);
  flags->cells.Add(*cmd);
  flags->backends.Add(*cmd);
  cmd->callback(
      [flags, &action] { action = [flags](const CommandContext& context) { return RunReport(*flags, context); }; });
}

}  // namespace depthbench::cli
