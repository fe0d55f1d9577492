// Judge: compares backends' raw outputs with the reference and records the
// errors. It works on host memory and knows nothing of backends.
#pragma once

#include <array>
#include <span>
#include <vector>

#include "bench/batch.h"
#include "bench/stats.h"

namespace depthbench {

// One cell's outputs to judge: world x, y and z of every sample of the
// batch, and where its errors go.
struct JudgedCell {
  std::span<const float> positions;
  CellAccumulator* accumulator;
};

// The instruction sets JudgeSlot is compiled for: the build's baseline,
// and AVX-512 (chosen at run time where the processor has it). Both give
// identical results.
enum class JudgeIsa { kWidest, kBaseline, kAvx512 };
bool ProcessorRuns(JudgeIsa isa);

// Judges every listed cell that reads depth slot `depth_slot` (they share
// the slot's reference, read once). Records total, arithmetic and absolute
// errors; storage errors belong to the encoding (RecordStorage). `isa` must
// be one the processor runs.
void JudgeSlot(const Batch& batch, std::uint32_t depth_slot, std::span<const JudgedCell> cells,
               JudgeIsa isa = JudgeIsa::kWidest);

// Records the storage error of one depth slot's samples.
void RecordStorage(const Batch& batch, std::uint32_t depth_slot, CellAccumulator& accumulator,
                   JudgeIsa isa = JudgeIsa::kWidest);

// The squared errors of one output (for reproducers and tests): relative
// total, relative arithmetic, absolute total.
struct SampleErrors {
  double total_sq = 0.0;
  double arith_sq = 0.0;
  double absolute_sq = 0.0;
};
SampleErrors ErrorsOf(const ReferenceSample& reference, const glm::dvec3& ray, const glm::dvec3& camera,
                      const float* position);

}  // namespace depthbench
