// Pass 2 of the raster form, the reconstruction, as a fragment program of
// every built-in cell that reads one depth slot: the host draws it once
// over the slot's atlas instead of once per cell. Each fragment fetches
// its texel once and runs each cell's function as raster_pass.glsl runs
// one (reconstruct.inc's DB_RASTER_CELL): the same inputs, the same
// function, its own position slices. The including program (generated:
// vulkan/variant_program.cc) includes the variants' headers and this
// file, then writes main():
//
//   void main() {
//     DB_RASTER_CELLS_BEGIN
//     DB_RASTER_CELL_AT(divide_world_position, false, 3u)
//     ...
//   }
//
// naming each cell's function, whether its rays come from the light
// volume, and its index in the run's list of cells.
#include "fragment_bindings.glsl"
// Per cell of the run's list, the slice its positions go to in this run
// (where the host listed it), or NO_SLICE (a run of other cells).
layout(std430, set = 0, binding = 11) readonly buffer CellSlices { uint cell_slices[]; };
const uint NO_SLICE = 0xffffffffu;

#include "reconstruct.inc"

#define DB_RASTER_CELLS_BEGIN                                                 \
  uint i = sample_at(gl_FragCoord);                                           \
  if (i >= draw.sample_count) {                                               \
    return;                                                                   \
  }                                                                           \
  real stored = texelFetch(depth_texture, ivec2(gl_FragCoord.xy), 0).r;      \
  DepthParams depth = depth_of(frame_of(i), draw.convention_slot);            \
  vec2 uv = sample_uv(i);

#define DB_RASTER_CELL_AT(function, light_volume, cell)                                    \
  if (cell_slices[cell] != NO_SLICE) {                                                  \
    DB_RASTER_CELL(function, light_volume, 3u * cell_slices[cell] * draw.sample_count) \
  }
