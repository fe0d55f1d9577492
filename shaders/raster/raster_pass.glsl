// Pass 2 of the raster form, the reconstruction, as a fragment program of
// one cell: one fragment per sample, at its atlas texel (reconstruct.inc
// says what it does). The including program defines RECONSTRUCT as its
// variant's function (shared/variants/, or the user's, through
// ../user/contract.inc), exactly as ../compute_pass.glsl has it. The
// built-in variants run in raster_cells.glsl's programs, several cells of
// a depth slot in one; this one runs a user's.
#include "fragment_bindings.glsl"

layout(constant_id = 0) const bool LIGHT_VOLUME = false;

#include "reconstruct.inc"

void main() {
  float stored = texelFetch(depth_texture, ivec2(gl_FragCoord.xy), 0).r;
  reconstruct_fragment(gl_FragCoord, stored);
}
