// The device judge's fused pass (bench/device_judge/device_judge.h): a
// variant's reconstruction and the judge of its cells in one program, so
// that no position goes through device memory. The variant's program
// (bench/backends/vulkan/variant_program.cc's VariantPass::kJudged)
// includes common.glsl, the variant's function and RECONSTRUCT as the
// accuracy pass does, then this file: each invocation reconstructs its
// sample as compute_pass.glsl would, from the pixel the backend's buffer
// holds and the texel the storage pass wrote, and judges the float32
// position it holds, as judge.comp judges the one it reads.
//
// A dispatch takes one variant's cells (its rows, from pass.row_order);
// phase 1 reconstructs again only for an accumulator whose candidates
// overflowed.
#define DB_FUSED_PASS
#include "../../shared/judge.h"
#include "../reconstruct_sample.glsl"
#include "judge.glsl"

uvec3 cell_position_bits(uint k, uint i) {
  uint f = frame_of(i);
  DepthParams depth = depth_params[f * DB_JUDGE_HARDWARE_CONVENTIONS + run_layout[pass.cell_conventions + k]];
  uint element = pass.lead + i;
  float stored = uintBitsToFloat(texel_bits[run_layout[k] * pass.slice_length + element]);
  return floatBitsToUint(reconstruct_sample(frame_params[f], depth, pixel_bits[element], stored));
}
