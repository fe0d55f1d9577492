// Guaranteed bounds: the most bits a cell can lose anywhere in a domain,
// proven rather than sampled.
//
// The shader part is bounded from the cell's compiled program (the module
// the Vulkan backend runs, spirv_eval.h) for two machines (rounding.h): any
// conformant Vulkan device, and an exactly rounded one (the CPU backend).
// The depth part (production and storage) is bounded from the host's
// model of them (encode.h), which is what the compute form's texels hold.
//
// The domain is cut into boxes of frame parameters, pixel and eye depth.
// On each box every input lane is an interval of its exact value with the
// float32 rounding it arrives with, so a box's figure holds for every
// sample in it; the worst box is split where the split lowers its figure
// most, until the budget of splits is spent. The bound is the worst
// remaining box's figure.
//
// Relative rounding bounds do not depend on the scene's scale, so the
// analysis runs with the near plane at 1 (lengths in units of the near
// plane); every other length of the domain is scaled with it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "bench/base/status.h"
#include "bench/bound/rounding.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/domain.h"
#include "bench/pipeline/sampler.h"

namespace depthbench::bound {

// Bits lost of a relative error bound, as the statistics count them
// (stats.h BitsLost), without its cap at 24: a bound is a bound.
double BoundBits(double relative_error);

// What is proven for one cell, as relative errors (the measured metrics'
// units); +infinity where no bound holds (`unbounded` says why).
struct CellBound {
  Cell cell;
  double device_shader = 0.0;  // the shader part on any conformant Vulkan device
  double exact_shader = 0.0;   // the shader part on an exactly rounded machine
  double depth = 0.0;          // production and storage (the host's encode)
  double total = 0.0;          // the whole error on any conformant Vulkan device
  std::uint64_t boxes = 0;     // boxes the device bound was proven over
  std::string unbounded;       // why a part has no bound, or empty
};

struct BoundOptions {
  int splits = 400;  // splits of the worst box per cell and machine
};

// Bounds for `cells` over `domain`, from the programs of `shader_dir`.
// InvalidArgument when the domain is one the analysis does not cover
// (orthographic, a captured frame, constants in float32); an absolute far
// plane or eye-depth range is taken over every near plane it may meet. A
// cell whose program cannot be bounded gets its reason.
// `progress(done, total)` is called after each cell.
Expected<std::vector<CellBound>> BoundCells(const Domain& domain, std::span<const Cell> cells,
                                            const std::filesystem::path& shader_dir, const BoundOptions& options,
                                            const std::function<void(std::size_t, std::size_t)>& progress = {});

// The longest distance from the camera per unit of eye depth that any
// pixel of the domain's frames has (its lens, off-centre or jittered):
// what turns a relative bound into world units at a given eye depth.
double LongestRay(const Domain& domain);

// The shader part's bound for one frame (its camera's rotation and
// position included), one pixel and a range of stored values, relative to
// the nearest depth those values denote. The frame is analysed at its own
// scale, where the floats each operation can give are known (rounding.h):
// at a single stored value the bound follows them rather than assuming
// every rounding at its worst. Projective conventions decode with the
// frame's A and B. Each cell's program is compiled once; not for use from
// several threads at once (the programs' evaluations share state).
class SampleBounds {
 public:
  static Expected<SampleBounds> Make(std::span<const Cell> cells, const std::filesystem::path& shader_dir);
  // One of the cells given to Make; +infinity where the cell's formula
  // assumes a symmetric frustum and the frame's is off-centre.
  Expected<double> At(const Cell& cell, const Frame& frame, std::uint32_t pixel_x, std::uint32_t pixel_y,
                      const Enclosure& stored, const Machine& machine) const;

 private:
  struct State;
  std::shared_ptr<State> state_;
};

// The same for one cell: what a second method can check point by point
// (tests/bound_test.cc enumerates every float32 of a binade).
Expected<double> ShaderBoundAt(const Cell& cell, const Frame& frame, std::uint32_t pixel_x, std::uint32_t pixel_y,
                               const Enclosure& stored, const Machine& machine,
                               const std::filesystem::path& shader_dir);

}  // namespace depthbench::bound
