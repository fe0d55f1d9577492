// The nightly precision report: what it measures (MeasureReport) and the
// typed model of everything it shows (BuildReport, report_model.h), which
// its writers only format: the JSON document (report_json.h), the page and
// the Markdown summary (report_render.h).
//
// Measurements:
//   - the fit sweeps (precision_fit.h): every cell at far/near 10^1, 10^1.5,
//     ..., 10^8 and with an infinite far plane, camera at the origin, on
//     every backend; the error models fitted to them;
//   - the default-domain sweep (every projection, pose and depth the
//     sampler draws, cameras up to 1e6 from the origin): NaN/Inf findings,
//     the worst samples, and the per-band figures kept in the history;
//   - speed files (`depthbench speed --json`) where they exist, joined with
//     this run's accuracy into the speed/accuracy front; the static
//     instruction mix of every variant, which always exists.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "bench/backends/backend.h"
#include "bench/base/status.h"
#include "bench/bound/bound.h"
#include "bench/choose/choose.h"
#include "bench/fit/precision_fit.h"
#include "bench/gate/baseline.h"
#include "bench/report/history.h"
#include "bench/report/report_model.h"
#include "bench/results/results.h"
#include "bench/speed/speed_results.h"
#include "bench/sweep/sweep.h"

namespace depthbench {

struct ReportPlan {
  bool quick = false;
  FitPlan fit;                  // the fixed-ratio sweeps and their models
  std::uint64_t main_seed = 1;  // the default-domain sweep
  std::uint64_t main_samples = 0;
  Domain main_domain;
  std::vector<Cell> cells;  // empty: all the built-in ones
  // The catalogue of `cells` and of the speed files' variants (it outlives
  // the report); null: the built-in one.
  const Catalogue* catalogue = nullptr;
  std::vector<std::filesystem::path> speed_files;
  // Whether the user named `speed_files` (--speed): then each is used,
  // labelled with the device it was measured on. Otherwise they are the
  // committed ones, and only those measured on a device this report runs
  // on are used: a cost measured on another GPU is not this one's.
  bool speed_files_named = false;
  std::filesystem::path shader_dir;  // for the instruction mix
  int trend_runs = 60;               // runs of the history the trend shows
  // A scene (--scene): its choice (choose.h) leads the first screen.
  std::optional<Scene> scene;
  // Splits per cell for the first screen's proven bounds (bound.h).
  int bound_splits = 200;

  // The nightly plan, and the quick one (same sweeps, fewer samples).
  static ReportPlan Nightly();
  static ReportPlan Quick();
};

// Progress of the measuring stages, for the command line to show.
struct ReportProgress {
  std::function<void(const std::string& stage)> begin;
  std::function<void(const SweepProgress&)> sweep;
  std::function<void(std::size_t done, std::size_t total)> fits;
  std::function<void(const std::string& summary)> end;
};

struct ReportMeasurements {
  FitSweeps sweeps;
  std::vector<PrecisionFit> fits;
  Results main;
  std::vector<std::pair<std::filesystem::path, SpeedResults>> speed;
  // The committed speed files left out: measured on none of this report's
  // devices (ReportPlan::speed_files_named).
  std::vector<std::filesystem::path> speed_of_other_devices;
  // The instruction-mix cost of every variant (compiled from the plan's
  // shaders), or why there is none.
  CostLookup static_costs;
  Status static_costs_status;
  std::vector<std::pair<std::string, double>> stage_seconds;
  std::optional<ChooseResult> scene_choice;  // with ReportPlan::scene
  // With a captured frame as the scene's population: bits lost per pixel
  // by the scene's choice (or, when nothing meets the requirement, the
  // closest candidate), on the backend the choice was made on.
  struct CaptureBits {
    Cell cell;
    std::string backend;
    std::uint32_t width = 0, height = 0;
    std::vector<float> bits;  // row by row from the top; NaN: background or outside the frustum
  };
  std::optional<CaptureBits> capture_bits;
  // The proven bounds of the first screen's recommended cells
  // (ProveRecommended), or why there are none.
  std::vector<bound::CellBound> recommended_bounds;
  Status bounds_status;
};


Expected<ReportMeasurements> MeasureReport(const ReportPlan& plan, std::span<Backend* const> backends,
                                           const ReportProgress& progress = {});

// The report, without its history part.
Report BuildReport(const ReportPlan& plan, const ReportMeasurements& measured);

// The parts of the model that group or order other parts: the history's
// changes by cell (worse_cells, better_cells, unchanged_cells, of `cells`
// compared) and the headline's worst cells (Report::worst_cells). The
// writers only loop over them.
void CountChangedCells(std::size_t cells, HistorySection& history);
std::vector<Report::WorstCell> WorstCells(const std::vector<HeadlineRow>& headline);

// The headline figures of each backend, as the history keeps them.
std::vector<Baseline> HistoryFigures(const ReportMeasurements& measured);

// Records the run in the history and adds the history part to the report:
// the trend of every cell, the previous comparable run, and what got worse
// (or better) since it, by the gate's tolerances.
Status AddHistory(Report& report, History& history, const HistoryRun& run, std::span<const Baseline> figures,
                  int trend_runs);

}  // namespace depthbench
