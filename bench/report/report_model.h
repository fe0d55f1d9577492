// The report as a typed model: everything the nightly report shows, built
// once from the measurements (report.h) and then only formatted by its
// writers (report_json.h, report_render.h). Like google/benchmark's Run
// and its reporters: a writer that needs a figure finds it as a member, so
// a renamed field fails to compile instead of rendering "-".
//
// Figures are kept as the report shows them: four significant digits (the
// statistics resolve no more), and no value where the figure is not finite
// (every bit lost, or no quantile to speak of).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bench/base/json_reader.h"
#include "bench/pipeline/device_info.h"

namespace depthbench {

inline constexpr JsonSchema kReportSchema{"depthbench.report", 2,
                                          "a report document (results.json of depthbench report)"};

// A figure as shown: four significant digits; nullopt when not finite.
using Figure = std::optional<double>;
Figure Shown(double x);

// The columns every row about a cell starts with.
struct CellColumns {
  std::string variant, convention, format;
  std::string backend;       // empty in rows that compare backends
  std::string Name() const;  // "variant/convention/format"
};

struct ReportEnvironment {
  std::string version, commit, host, started_at;
  Figure seconds;
  std::vector<std::pair<std::string, Figure>> stages;        // (stage, seconds)
  std::vector<std::pair<std::string, DeviceInfo>> backends;  // (backend, device)
  bool quick = false;
  struct FitSweeps {
    std::uint64_t seed = 0, samples_per_ratio = 0;
    std::vector<std::string> ratios;  // "1e1", "1e1.5", ..., "inf"
    std::vector<double> held_out;
    std::string domain;
  } fit_sweeps;
  struct DefaultSweep {
    std::uint64_t seed = 0, samples = 0, reconstructions = 0;
    std::string domain;
  } default_sweep;
  std::vector<std::string> speed_files;
};

// The far/near ratio at which a budget breaks.
struct BudgetRatio {
  enum class Kind { kNone, kAlways, kNever, kRatio } kind = Kind::kNone;  // kNone: an infinite far plane
  Figure ratio;                                                           // for kRatio
};

// One cell on one backend: its fitted model at p99.9 and, when the
// default-domain sweep ran it, that sweep's figures.
struct HeadlineRow {
  CellColumns cell;
  bool infinite_far = false;
  std::string model;  // the chosen model's name
  int points = 0;
  // Bits lost per doubling of far/near and its 95% interval; none for an
  // infinite far plane.
  Figure slope, slope_low, slope_high;
  std::map<std::string, Figure> predicted_bits;  // "1e2" ... "1e8", "inf"
  // The 95% interval of each prediction: the model's at the same point.
  std::map<std::string, std::pair<Figure, Figure>> predicted_interval;
  BudgetRatio ratio_for_1e3, ratio_for_1e6;
  Figure holdout_max_miss;  // none without held-out points
  struct Measured {
    Figure p999_bits, max_bits;
    std::uint64_t nan = 0, inf = 0;
  };
  std::optional<Measured> measured;  // of the default-domain sweep
};

// A band a model was fitted through, beside what the model says there.
struct ModelPointRow {
  CellColumns cell;
  std::string level;  // "p99.9", "max"
  std::string ratio;  // "1e4", "inf"
  Figure log10_ratio;
  Figure depth;
  // What a band's measured figure is: a figure, none because the outputs
  // were not finite, or none because the error is below what the
  // histograms resolve.
  enum class State : std::uint8_t { kMeasured, kNotFinite, kBelowResolution };
  Figure measured;  // none: see state
  State state = State::kMeasured;
  Figure model, low, high;
  bool held_out = false;
};

// p99.9 bits lost of the total and of its two causes, per sweep.
struct SplitRow {
  CellColumns cell;
  std::string ratio;
  Figure log10_ratio;
  Figure total, production, storage, arith;
};

struct BackendDifferenceRow {
  CellColumns cell;  // without backend
  std::string ratio, metric;
  Figure first, second;  // bits lost on the two backends compared
  Figure difference;
};
struct BackendDifferences {
  std::vector<std::string> backends;  // the two compared, or none
  std::size_t compared = 0, notable = 0;
  Figure largest_bits;
  double threshold_bits = 0.0;
  std::vector<BackendDifferenceRow> rows;  // the largest, largest first
};

// What a non-finite output is: a NaN component, or an infinite one and
// none NaN (stats.h counts them apart); a row can hold both.
enum class NonFiniteKind { kNaN, kInf, kNaNAndInf };
const char* NonFiniteKindName(NonFiniteKind kind);  // "NaN", "Inf", "NaN and Inf"

struct NonFiniteRow {
  CellColumns cell;
  std::string sweep;  // "default domain", "f/n 1e4", "f/n inf"
  NonFiniteKind kind = NonFiniteKind::kNaN;
  std::uint64_t nan = 0, inf = 0, judged = 0, first_index = 0;
  std::string command;  // replays the first
};
// The non-finite findings by cause: one formula (variant) returning one
// kind of non-finite output, wherever it does so.
struct FindingGroup {
  std::string variant;
  NonFiniteKind kind = NonFiniteKind::kNaN;
  std::size_t rows = 0;                        // (cell, backend, sweep) rows of the group
  std::uint64_t outputs = 0;                   // NaN and Inf outputs, all rows together
  std::vector<std::string> encodings, sweeps;  // "standard/d16_unorm"; "f/n 1e7", in order of appearance
  std::vector<std::string> backends;
  std::string command;  // replays the group's first finding
};
struct WorstSampleRow {
  CellColumns cell;
  Figure bits, relative;
  std::uint64_t index = 0;
  std::string command;
};

struct FrontRow {
  CellColumns cell;  // without backend
  std::string source, ratio;
  Figure cost, spread, bits;
  Figure bits_low, bits_high;  // the 95% sampling interval of the p99.9 (stats.h), at most every bit
  std::uint64_t nonfinite = 0;
  bool on_front = false;
};
// Where a front's costs come from, best first: GPU time measured on a
// hardware GPU, GPU time measured on a software rasteriser (llvmpipe,
// lavapipe: a CPU's timing of the shader), or the static cost model.
enum class CostKind { kMeasuredGpu, kMeasuredSoftware, kStaticModel };
const char* CostKindName(CostKind kind);  // "measured on a GPU", ...

struct FrontSource {
  std::string source;  // the name its rows carry
  CostKind kind = CostKind::kStaticModel;
  std::string device;      // the measured device; empty for the static model
  std::string cost_unit;   // what the cost is, in words
  std::string cost_title;  // the cost axis: "GPU time per 1920x1080 frame (µs) on NVIDIA H100"
  std::string accuracy;
};
struct SpeedSection {
  std::vector<FrontSource> sources;
  std::vector<FrontRow> rows;
  std::optional<std::string> error;  // why there is no front
};

struct HistorySection {
  std::string database;
  std::int64_t run = 0, runs_recorded = 0;
  struct Previous {
    std::string backend;
    std::int64_t run = 0;
    std::string made_at, commit;
  };
  std::vector<Previous> previous;
  double tolerance_p999_bits = 0.0, tolerance_max_bits = 0.0;
  std::vector<std::string> notes;
  enum class Direction : std::uint8_t { kWorse, kBetter };
  struct Change {
    Direction direction = Direction::kWorse;
    std::string backend, cell, band;
    std::vector<std::string> reasons;
    Figure before_p999_bits, after_p999_bits;
  };
  std::vector<Change> changes;
  // The changes by cell: each (cell, backend) that got worse in any band,
  // with what got worse in each band ("band: reasons"), in order of cell
  // and backend; a cell worse in one band and better in another is worse.
  struct WorseCell {
    std::string cell, backend;
    std::vector<std::string> bands;
  };
  std::vector<WorseCell> worse_cells;
  std::size_t better_cells = 0;     // better in some band, worse in none
  std::size_t unchanged_cells = 0;  // of the headline's cells
  struct TrendPoint {
    std::int64_t run = 0;
    std::string made_at, commit, backend, cell;
    Figure p999_bits, max_bits;
    std::uint64_t nonfinite = 0;
  };
  std::vector<TrendPoint> trend;

  std::size_t worse() const;  // changes for the worse
};
const char* PointStateName(ModelPointRow::State state);          // "measured", "not finite", "below resolution"
const char* DirectionName(HistorySection::Direction direction);  // "worse", "better"

// The first screen: per convention and format, the variant to use (with
// those it ties with), how precise it is at the far plane, what it costs,
// and where it stops meeting the usual budgets.
struct RecommendationRow {
  std::string convention, format, backend;
  std::string ratio;                  // the far/near the bits are predicted at: "1e4", or "inf"
  std::vector<std::string> variants;  // the recommended first, then those tied with it
  std::string cell;                   // the recommended variant's cell, by name
  Figure bits, bits_low, bits_high;   // p99.9 bits lost at the far plane, the model's 95% interval
  // Proven (bench/bound): the most bits the cell can lose anywhere at this
  // far/near (every depth, pixel and lens of the fit sweeps' domain, the
  // camera at the origin) on any conformant Vulkan device; none where no
  // bound holds. A bound, not a p99.9: it is at or above the measured worst.
  Figure proven_bits;
  Figure cost;                        // none: no cost known
  CostKind cost_kind = CostKind::kStaticModel;
  std::string cost_unit;  // "µs per 1920x1080 frame on llvmpipe (...)", "FMA-equivalent slots"
  BudgetRatio ratio_for_1e3, ratio_for_1e6;
  // Nothing survives: even the interval's lower end loses kKeepsNothingBits
  // or more. Such a row says "do not use", never a variant.
  bool keeps_nothing = false;
  std::uint32_t bytes_per_pixel = 0;  // the frame's depth traffic (frame_cost.h), no stencil
  // The far plane's error in world units (metres), at this row's far/near,
  // with the far plane at 100 m and at 10 km.
  Figure error_far_100m, error_far_10km;
};
// A combination whose p99.9 at the far plane keeps less than one bit, even
// at the lower end of its interval, keeps nothing.
inline constexpr double kKeepsNothingBits = 23.0;

// A scene's first screen (report --scene): per convention and format the
// scene's engine allows, its best candidate as `choose` ranks them, whether
// it meets the scene's requirement, in the requirement's own unit.
struct SceneRow {
  std::string convention, format, variant;
  Figure measured;  // the upper end of the 95% interval, at the requirement's level and depth
  Figure far_end;   // measured at the scene's far end
  // With a proven requirement (level = "bound"): the candidate's bound,
  // which decides `meets`; none otherwise, or where no bound holds.
  Figure proven;
  bool meets = false;
  double times_limit = 0.0;  // measured / the requirement's limit
  std::uint32_t bytes_per_pixel = 0;
  Figure cost;
  // The error against eye depth (choose.h DepthFigure), for the chart.
  struct DepthPoint {
    double depth_min, depth_max;
    Figure value;
  };
  std::vector<DepthPoint> by_depth;
};
struct SceneSection {
  std::string name, requirement, backend, cost_unit;
  std::string unit;                // the requirement's
  double limit = 0.0;              // in that unit
  std::optional<double> at_depth;  // where it applies, if anywhere in particular
  std::vector<SceneRow> rows;  // the choice first, then as ranked
  std::vector<std::string> what_ifs, not_candidates;
  // A captured frame's bits lost per pixel (ReportMeasurements::capture_bits),
  // as the picture the page shows.
  struct CapturePicture {
    std::string image;  // the PNG's name beside report.html
    std::string cell, backend, source;
    std::uint64_t pixels = 0;  // judged
    double median_bits = 0.0, p999_bits = 0.0, worst_bits = 0.0;
  };
  std::optional<CapturePicture> capture;
  bool proven = false;  // the requirement is proven (level = "bound")
};

// The PNG of a capture's bits lost per pixel, beside report.html.
inline constexpr const char* kCaptureImageName = "capture-bits.png";

struct Report {
  ReportEnvironment environment;
  std::optional<SceneSection> scene;  // with report --scene
  std::vector<RecommendationRow> recommendations;
  std::vector<HeadlineRow> headline;
  std::vector<ModelPointRow> precision_points;  // deepest decade of each ratio, p99.9 and max
  std::vector<ModelPointRow> depth_points;      // every decade at a few ratios, p99.9, as relative error
  std::vector<SplitRow> split;
  BackendDifferences backend_differences;
  std::vector<NonFiniteRow> nonfinite;
  std::vector<FindingGroup> finding_groups;  // the non-finite rows by cause, most rows first
  std::vector<WorstSampleRow> worst;
  // The headline's cells with measured figures, worst first (p99.9 bits
  // lost, then the maximum), a cell measured the same on several backends
  // once, with every backend named.
  struct WorstCell {
    std::size_t row = 0;  // an index into headline
    std::vector<std::string> backends;
  };
  std::vector<WorstCell> worst_cells;
  SpeedSection speed;
  std::optional<HistorySection> history;  // none with --no-history
};

}  // namespace depthbench
