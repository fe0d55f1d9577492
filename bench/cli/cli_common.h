// Flags several subcommands share (domain, cell filters, backends), and the
// conversion of their strings into the bench's types with clear messages.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "bench/backends/backend.h"
#include "bench/base/status.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/domain.h"

namespace depthbench::cli {

// Exit codes of every subcommand.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFinding = 1;
inline constexpr int kExitCannotRun = 2;

struct DomainFlags {
  std::string domain;  // a named domain or a scene file
  std::string near, far, ratio, fov, aspect, camera_distance, eye_depth, resolution, production;
  void Add(CLI::App& app);
  // The domain --domain names (or `base`), narrowed by the range flags.
  Expected<Domain> Apply(Domain base) const;
};

struct CellFlags {
  std::vector<std::string> variants, conventions, formats;
  void Add(CLI::App& app);
  Expected<std::vector<Cell>> Select() const;  // the catalog's cells the filters keep
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
  void Add(CLI::App& app, bool allow_several = true);
  Expected<BackendSet> Make() const;
};

// "1e6", "1000000" -> a positive count.
Expected<std::uint64_t> ParseCount(const std::string& text, const std::string& what);
// Checks that an output file can be created, before a long run starts: the
// path names a file (not a folder) in an existing folder where a file can be
// created right now. The message names `what` (the flag) and the path.
Status CheckWritable(const std::string& path, const std::string& what);

// True when stderr is a terminal (progress lines are shown only then).
bool StderrIsTerminal();

// Prints a Status as "depthbench: error: ..." and returns its exit code.
// Commands return their Status; app.cc alone reports it with this.
int ReportError(const Status& status);

}  // namespace depthbench::cli
