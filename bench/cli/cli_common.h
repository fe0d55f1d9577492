// Flags several subcommands share (domain, cell filters, backends), and the
// conversion of their strings into the bench's types with clear messages.
#pragma once

#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "bench/backends/backend.h"
#include "bench/base/progress.h"
#include "bench/base/status.h"
#include "bench/bound/bound.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/domain.h"

namespace depthbench::cli {

// Exit codes of every subcommand.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFinding = 1;
inline constexpr int kExitCannotRun = 2;

// A named domain (typical, wide, extremes) or the domain of a scene file
// (whose variant names are looked up in `catalogue`).
Expected<Domain> DomainByName(const std::string& name_or_file, const Catalogue& catalogue);
// What --domain says, for the commands that take it.
inline constexpr const char* kDomainHelp =
    "the scenes to sample: typical (the default: what games and viewers render, camera-relative: fov 30-100 deg, "
    "aspect 1-2.4, near 0.01-1, far/near 1e2-1e5 and infinite), wide (fov 1-179, aspect 0.1-10, near 1e-4-10, "
    "far/near 1e1-1e8 and infinite, cameras up to 1e6 from the origin), extremes (near 1e-6-1e-2, far/near 1e6-1e9 "
    "and infinite, cameras 1e5-1e7 out), or a scene file NAME.toml (as choose reads)";

// What --threads says, for the commands that run a sweep.
inline constexpr const char* kThreadsHelp =
    "threads in all (default: one per core); where the device judges, a quarter of them, at most 4, feed it while "
    "the rest build the next batch";

// Whether --domain names a scene file (a path, or NAME.toml) rather than a
// named domain.
bool IsSceneFile(const std::string& name_or_file);

struct DomainFlags {
  std::string domain;  // a named domain or a scene file
  std::string near, far, ratio, fov, aspect, camera_distance, eye_depth, resolution, production, constants, pipeline;
  std::string eye_fov, ortho, jitter, projection;
  void Add(CLI::App& app);
  // What --projection's matrix holds, one line a fact (nothing without it).
  Expected<std::vector<std::string>> DescribeProjection() const;
  // The domain --domain names (or `base`), narrowed by the range flags.
  Expected<Domain> Apply(Domain base, const Catalogue& catalogue) const;
};

struct CellFlags {
  std::vector<std::string> variants, conventions, formats;
  void Add(CLI::App& app);
  // The catalogue's cells the filters keep.
  Expected<std::vector<Cell>> Select(const Catalogue& catalogue) const;
};

// The backends a command runs: owns them, and lists them, in the order the
// flags name them, as the pointers the sweeps take.
class BackendSet {
 public:
  explicit BackendSet(std::vector<std::unique_ptr<Backend>> owned);
  std::span<Backend* const> view() const { return pointers_; }

 private:
  std::vector<std::unique_ptr<Backend>> owned_;
  std::vector<Backend*> pointers_;  // owned_'s, which moves do not invalidate
};

struct BackendFlags {
  std::vector<std::string> backends{"cpu", "vulkan"};
  std::string device;
  std::string shaders;
  bool validate = false;
  // Set by Add: whether --backend was given decides the default when a
  // variant comes from a shader file (vulkan alone, the only backend that
  // runs one).
  const CLI::Option* backend_option = nullptr;
  void Add(CLI::App& app, bool allow_several = true);
  // The backends for the variants of `catalogue`.
  Expected<BackendSet> Make(const Catalogue& catalogue) const;
};

// "1e6", "1000000" -> a positive count.
Expected<std::uint64_t> ParseCount(const std::string& text, const std::string& what);
// Checks that an output file can be created, before a long run starts: the
// path names a file (not a folder) in an existing folder where a file can be
// created right now; symbolic links are followed to the file they name, and
// a target that is not a regular file (a device, a FIFO) is refused. The
// message names `what` (the flag) and the path. For --json, the data output
// a user pipes, "-" (standard output) is accepted.
Status CheckWritable(const std::string& path, const std::string& what);

// The files one command reads and writes, each by the flag that names it.
// Check refuses an output that is one of the inputs (writing it would
// replace what is being read, as a compiler refuses -o x.c x.c), and two
// outputs that are one file (one would be lost). Files are compared as
// files, not as spellings: a relative path, a link or a second name of an
// existing file is that file. Empty paths (a flag not given) and "-"
// (standard output) are left out.
class FileRoles {
 public:
  FileRoles& Input(const std::string& path, std::string flag);
  FileRoles& Output(const std::string& path, std::string flag);
  Status Check() const;

 private:
  struct Named {
    std::string path, flag;
  };
  std::vector<Named> inputs_, outputs_;
};

// A command's Markdown summary for CI: written to `path` (--summary; none
// when empty), and added to the job's summary page when the job has one
// (StepSummaryFile: GitHub Actions' $GITHUB_STEP_SUMMARY).
inline constexpr const char* kSummaryHelp =
    "write a short Markdown summary here (a CI job's page); inside GitHub Actions it is also added to "
    "$GITHUB_STEP_SUMMARY";
Status WriteSummary(const std::string& path, const std::string& markdown);

// True when stderr is a terminal (progress lines are shown only then).
bool StderrIsTerminal();

// What bound::BoundCells reports after each cell, as a progress line.
std::function<void(std::size_t, std::size_t)> CellsBoundProgress(Progress& progress);

// The proven bounds of `cells` over `domain` (bound::BoundCells) from the
// programs of `shaders` (empty: the installed ones), with a progress line
// named `label`.
Expected<std::vector<bound::CellBound>> ProveCells(const Domain& domain, const std::vector<Cell>& cells,
                                                   const std::string& shaders, int splits, bool quiet,
                                                   const char* label);

// Prints a Status as "depthbench: error: ..." and returns its exit code.
// Commands return their Status; app.cc alone reports it with this.
int ReportError(const Status& status);

}  // namespace depthbench::cli
