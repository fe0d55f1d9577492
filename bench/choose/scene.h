// Scene files: one scene's ranges and requirement, in TOML, so that the
// bench samples and models only what that scene needs. Example (every
// table but [cost] is required):
//
//   name = "open world"
//   [projection]
//   near = 0.5                # world units
//   far = 50000               # or "inf"
//   fov_degrees = [60, 90]    # a value or [min, max]
//   aspect = [1.33, 2.39]
//   resolution = [2560, 1440]
//   jitter = 0.5              # TAA: pixels the projection moves each frame (default 0)
//   # Instead of fov_degrees and aspect, an off-centre VR eye (OpenXR's
//   # XrFovf order, degrees): eye_fov = [-50, 45, 48, -52]  # left, right, up, down
//   # Or instead of near, far and the lens, the engine's matrix (16 numbers):
//   # matrix = [...]; api = "vulkan"; layout = "column-major"
//   # (projection_matrix.h; it also fixes the depth convention)
//   [camera]
//   distance_from_origin = [0, 20000]
//   [depth]
//   range = [1, 50000]        # eye depths that matter (default: near to far)
//   [engine]
//   conventions = "any"       # or a list: ["standard", "reversed"]
//   formats = ["x8_d24_unorm", "d32_sfloat"]
//   variants = "any"
//   stencil = true            # the depth attachment holds stencil (default false)
//   [requirement]             # exactly one of absolute_error, relative_error, bits_lost
//   absolute_error = 0.01     # world units ...
//   at_depth = 50000          # ... at this eye depth ("1 cm at 50 km")
//   level = "p99.9"           # or "max", or "bound": proven for any
//                             # conformant Vulkan device (bench/bound)
//   [cost]
//   max_cost = 60             # in the cost unit choose uses
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bench/base/status.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/domain.h"
#include "bench/pipeline/projection_matrix.h"
#include "bench/pipeline/stats.h"

namespace depthbench {

struct Requirement {
  enum class Kind { kAbsolute, kRelative, kBitsLost };
  Kind kind = Kind::kRelative;
  double value = 0.0;
  std::optional<double> at_depth;  // eye depth the requirement applies at
  Level level = Level::kP999;
  // level = "bound": the candidate's proven bound over the requirement's
  // population (bound.h) decides, not a measurement; `level` is then kMax,
  // the measured figure shown beside it.
  bool proven = false;

  // The largest relative error that meets it at eye depth z (bits lost
  // and relative errors ignore z).
  double RelativeLimit() const;
  std::string Describe() const;  // "absolute error <= 0.01 at eye depth 50000 (p99.9)"
};

struct Scene {
  // The catalogue `variants` are of (it outlives the scene); null: the
  // built-in one.
  const Catalogue* catalogue = nullptr;
  std::string source;  // the file it came from
  std::string name;
  Domain domain;
  std::vector<Variant> variants;        // empty: any
  std::vector<Convention> conventions;  // empty: any
  std::vector<Format> formats;          // empty: any
  bool stencil = false;                 // the depth attachment holds stencil (frame_cost.h)
  std::optional<Resolution> resolution;  // projection.resolution, the frame a cost is for
  Requirement requirement;
  std::optional<double> max_cost;
  // projection.matrix's API and what the matrix holds (projection_matrix.h),
  // one line a fact; empty without a matrix.
  std::optional<GraphicsApi> api;
  std::vector<std::string> projection_facts;

  // The catalogue's cells this scene's engine can use and its domain allows.
  std::vector<Cell> Candidates() const;
  // The catalogue's cells of the engine's variants under `conventions` and
  // `formats` (empty: any), whatever the domain: what the engine could use
  // with those choices changed.
  std::vector<Cell> CellsWith(std::vector<Convention> conventions, std::vector<Format> formats) const;
  // Each listed format that no candidate has, in words: which conventions
  // would read it ("r16_sfloat: read only under linear, which
  // engine.conventions does not list"), or why the domain rules it out.
  std::vector<std::string> UnusableFormats() const;
};

// Errors name the file, line and column, the field, and what is allowed.
// Variant names are looked up in `catalogue`, which the scene then refers to.
Expected<Scene> ParseScene(std::string_view text, const std::string& source,
                           const Catalogue& catalogue = Catalogue::BuiltIn());
Expected<Scene> LoadScene(const std::filesystem::path& path, const Catalogue& catalogue = Catalogue::BuiltIn());

}  // namespace depthbench
