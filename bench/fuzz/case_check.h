// The fuzzer's invariants, checked on explicit inputs through real backends.
//
// For every (cell, backend, sample): where the reference is finite (the
// sample is judged or lies outside the frustum) and the texel does not
// denote a point at infinity, the output must be finite,
// and its arithmetic error (the error of the reconstruction from the value
// the texel really holds; storage rounding is the format's, not the
// shader's) must stay within ArithmeticBound. Anything else is a finding:
// NaN, Inf, or beyond the bound.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "bench/backends/backend.h"
#include "bench/base/status.h"
#include "bench/base/thread_pool.h"
#include "bench/pipeline/batch.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/sampler.h"

namespace depthbench {

// kBeyondProven: the shader part beyond the bound `depthbench bound`
// proved for the cell and domain (bench/bound/): a wrong bound, or a device
// outside the rules it was proven under.
enum class FindingKind : std::uint8_t { kNaN, kInf, kBeyondBound, kBeyondProven };
// "nan", "inf", "beyond_bound", "beyond_proven_bound"
const char* FindingKindName(FindingKind kind);

// The documented theoretical bound on the relative arithmetic error of one
// reconstruction, until fitted models replace it. First-order rounding
// analysis: a float32 evaluation of a few dozen operations errs by at most
// kRoundings * 2^-24 times the sum of the condition numbers of its three
// steps:
//   depth: ndc_z = A + B / z inverted as B / (ndc_z - A): (|ndc_z| + |A|) /
//          |ndc_z - A| + 1, plus 2 / |ndc_z - A| where ndc_z = 2d - 1 is
//          computed first ([-1, 1] conventions); 1 for linear depth;
//   ray:   the pixel's NDC offset 2(x + 0.5)/w - 1 carries an absolute
//          rounding of ~2^-24, scaled by the lens: 1 + 2 tan(fov/2) (aspect + 1);
//   world: adding the camera position: 1 + |camera| / |point - camera|
//          (inverse_vp: times the depth condition, see the .cc).
// The bound is relative to the distance of the point the texel denotes;
// CaseChecker rescales it to the true point's, as the judge measures.
// kRoundings = 32: the longest path (inverse_vp: a 4x4 matrix-vector
// product, a divide, the camera) rounds about 16 times, doubled for margin.
inline constexpr double kRoundings = 32.0;
double ArithmeticBound(const Cell& cell, const Frame& frame, const f32::DepthParams& depth, float fetched,
                       double distance_from_camera);

struct Judgement {
  double total = 0.0;  // relative errors (NaN when the output is not finite)
  double arith = 0.0;
  double bound = 0.0;    // ArithmeticBound
  bool checked = false;  // the reference is finite and the cell runs on the frame
  bool judged = false;   // and the point lies inside the frustum (errors count, as in a sweep)
  bool nan = false, inf = false;
  // The cell's proven bound for this backend (CaseChecker::SetProvenBounds;
  // infinite where none was given): it covers judged samples.
  double proven = INFINITY;
  bool beyond_proven() const { return judged && !nan && !inf && arith > proven; }
  bool violates() const {
    return checked && (nan || inf || (std::isfinite(bound) && arith > bound) || beyond_proven());
  }
  FindingKind kind() const {
    return nan               ? FindingKind::kNaN
           : inf             ? FindingKind::kInf
           : beyond_proven() ? FindingKind::kBeyondProven
                             : FindingKind::kBeyondBound;
  }
};

// The shader part's proven bound at one judged sample: the cell, the
// backend's name, the sample's exact frame, pixel and fetched stored value;
// relative to the distance of the point that value denotes, +infinity where
// none is proven.
using SampleBound = std::function<double(const Cell& cell, std::string_view backend, const Frame& frame,
                                         std::uint32_t pixel_x, std::uint32_t pixel_y, float stored)>;

class CaseChecker {
 public:
  // Prepares every backend for the cells (shaders compiled once).
  static Expected<CaseChecker> Make(std::vector<Cell> cells, std::vector<Backend*> backends, unsigned threads = 0);

  // The proven bound of cell c on backend b at [c * backends + b] (relative
  // shader errors, bench/bound/), for the samples of the domain it was
  // proven over; every judged sample is held against it.
  void SetProvenBounds(std::vector<double> proven) { proven_ = std::move(proven); }
  // The proven bound at single samples' own inputs (bound::SampleBounds),
  // which is tighter than a domain's: each batch's worst judged sample of
  // every cell and backend, by its error and by its error over
  // ArithmeticBound, is held against it too.
  void SetSampleBound(SampleBound bound) { sample_bound_ = std::move(bound); }
  // How far the sample bounds reached, since Make: the samples held
  // against them, those of them whose bound is under 24 bits (less than
  // the distance), how many of the latter lie within one bit of their
  // bound (an error at least half of it), and the largest shader error
  // over its sample bound among them (with its cell's name). At a single
  // sample the bound follows the floats the machine may compute, so the
  // largest is often 1; the count within a bit says how many come close.
  struct SampleBoundReach {
    std::uint64_t held = 0;
    std::uint64_t below_24_bits = 0;
    std::uint64_t within_one_bit = 0;
    double closest = 0.0;
    std::string closest_cell;
  };
  const SampleBoundReach& sample_bound_reach() const { return reach_; }

  // Runs samples [first, first + count) of `source` through every backend
  // and judges each output.
  Status Evaluate(const SampleSource& source, std::uint64_t first, std::uint32_t count);

  const std::vector<Cell>& cells() const { return cells_; }
  std::span<Backend* const> backends() const { return backends_; }
  const Batch& batch() const { return batch_; }
  const Judgement& At(std::size_t cell, std::size_t backend, std::uint32_t sample) const {
    return judgements_[(cell * backends_.size() + backend) * batch_.count + sample];
  }

 private:
  CaseChecker(std::vector<Cell> cells, std::vector<Backend*> backends, unsigned threads);
  // Lowers the proven bound of backend b's worst judged samples to their
  // sample bounds.
  void HoldWorstAgainstSampleBounds(std::size_t b, std::uint32_t count);

  std::vector<Cell> cells_;
  std::vector<double> proven_;  // per (cell, backend), or empty
  SampleBound sample_bound_;    // or empty
  SampleBoundReach reach_;
  std::vector<Backend*> backends_;
  RunLayout layout_;
  std::unique_ptr<ThreadPool> pool_;
  Batch batch_;
  std::vector<float> scratch_;
  std::vector<Judgement> judgements_;
};

}  // namespace depthbench
