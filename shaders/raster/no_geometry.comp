#version 450
#extension GL_GOOGLE_include_directive : require
// After pass 2: a sample the host had no geometry for was never drawn and
// has no position. Pass 2b's fragment still ran at its texel (on the
// cleared value) or, for the light volume, wrote nothing; every slice of
// the run gets a quiet NaN there instead, so that what a judge reads is
// "nothing drawn", not an unwritten output or a position from nothing.
#include "../common.glsl"
#include "raster_common.glsl"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 5) writeonly buffer Positions { uint position_bits[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= draw.sample_count || has_geometry(i)) {
    return;
  }
  for (uint slice = 0u; slice < draw.slices; ++slice) {
    position_bits[slice * draw.sample_count + i] = 0x7fc00000u;
  }
}
