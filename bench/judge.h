// Judge: compares a backend's raw outputs for one cell with the reference
// and records the errors. It works on host memory and knows nothing of
// backends.
#pragma once

#include <span>
#include <vector>

#include "bench/batch.h"
#include "bench/stats.h"

namespace depthbench {

// Reusable per-thread buffers of the judge.
struct JudgeScratch {
  std::vector<double> total, arith, absolute;
  std::vector<std::int16_t> total_bin, arith_bin, absolute_bin;
};

// `positions` holds 3 floats (world x, y, z) per sample of the batch.
// Records total, arithmetic and absolute errors (storage errors belong to
// the encoding: RecordStorage).
void JudgeCell(const Batch& batch, const CellPlan& plan, std::span<const float> positions,
               CellAccumulator& accumulator, JudgeScratch& scratch);

// Records the storage error of one depth slot's samples.
void RecordStorage(const Batch& batch, std::uint32_t depth_slot, CellAccumulator& accumulator);

// The squared errors of one output (for reproducers and tests): relative
// total, relative arithmetic, absolute total. NaN when the output is not
// finite.
struct SampleErrors {
  double total_sq = 0.0;
  double arith_sq = 0.0;
  double absolute_sq = 0.0;
};
SampleErrors ErrorsOf(const ReferenceSample& reference, const glm::dvec3& ray, const glm::dvec3& camera,
                      const float* position);

}  // namespace depthbench
