// Judge: compares backends' raw outputs with the reference and records the
// errors. It works on host memory and knows nothing of backends.
#pragma once

#include <array>
#include <span>
#include <vector>

#include "bench/base/isa.h"
#include "bench/pipeline/batch.h"
#include "bench/pipeline/stats.h"

namespace depthbench {

// One cell's outputs to judge: world x, y and z of every sample of the
// batch, and where its errors go.
struct JudgedCell {
  std::span<const float> positions;
  CellAccumulator* accumulator;
};

// Judges every listed cell that reads depth slot `depth_slot` (they share
// the slot's reference, read once). Records total, arithmetic (the
// shader's part) and absolute errors, and non-finite outputs by cause;
// storage and production errors belong to the encoding
// (RecordEncodingErrors). `isa` must be one the processor runs.
void JudgeSlot(const Batch& batch, std::uint32_t depth_slot, std::span<const JudgedCell> cells, Isa isa = Isa::kWidest);

// Records the storage and production errors of one depth slot's samples.
void RecordEncodingErrors(const Batch& batch, std::uint32_t depth_slot, CellAccumulator& accumulator,
                          Isa isa = Isa::kWidest);

// The squared errors of one output (for reproducers and tests): relative
// total, relative arithmetic, absolute total. `offset` is the sample's
// point at eye depth 0 (Batch::Offset; 0 unless orthographic).
struct SampleErrors {
  double total_sq = 0.0;
  double arith_sq = 0.0;
  double absolute_sq = 0.0;
};
SampleErrors ErrorsOf(const ReferenceSample& reference, const glm::dvec3& ray, const glm::dvec3& offset,
                      const glm::dvec3& camera, const float* position);

}  // namespace depthbench
