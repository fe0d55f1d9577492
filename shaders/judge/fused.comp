// The device judge's fused pass (bench/device_judge/device_judge.h): a
// variant's reconstruction and the judge of its cells in one program, so
// that no position goes through device memory. The variant's program
// (bench/backends/vulkan/variant_program.cc's JudgedProgram) includes
// common.glsl and the variants' functions as the accuracy pass does, then
// this file: each invocation reconstructs its
// sample as compute_pass.glsl would, from the pixel the backend's buffer
// holds and the texel the storage pass wrote, and judges the float32
// position it holds, as judge.comp judges the one it reads.
//
// One program holds the functions of several variants (every built-in
// variant of the run, or one user's), and each cell's word in the run's
// layout says which it reads. A dispatch takes the program's cells in the
// order of their depth slots (its rows, from pass.row_order), so that the
// rows running at once share a slot's reference in the device's cache, as
// judge.comp's do; phase 1 reconstructs again only for an accumulator
// whose candidates overflowed.
#define DB_FUSED_PASS
#include "../../shared/judge.h"
// The case of the program's switch that reconstructs the cell being
// judged: RECONSTRUCT passes it on (variant_program.cc's JudgedProgram).
uint db_fused_case;
#include "../reconstruct_sample.glsl"
#include "judge.glsl"

uvec3 cell_position_bits(uint k, uint i) {
  uint f = frame_of(i);
  uint cell = run_layout[pass.fused_cells + k];
  db_fused_case = db_fused_cell_case(cell);
  DepthParams depth = depth_params[f * DB_JUDGE_HARDWARE_CONVENTIONS + db_fused_cell_convention(cell)];
  uint element = pass.lead + i;
  float stored = uintBitsToFloat(texel_bits[run_layout[k] * pass.slice_length + element]);
  return floatBitsToUint(reconstruct_sample(frame_params[f], depth, pixel_bits[element], stored));
}
