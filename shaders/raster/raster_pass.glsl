// Pass 2 of the raster form, the reconstruction, as a fragment program:
// one fragment per sample, at its atlas texel (reconstruct.inc says what it
// does). The including program defines RECONSTRUCT as its variant's function
// (shared/variants/, or the user's, through ../user/contract.inc), exactly
// as ../compute_pass.glsl has it. The depth slot's atlas is read by texel,
// as a full-screen pass reads its depth buffer.
#include "raster_common.glsl"

// The atlas of the cell's depth slot (the host binds the slot's set).
layout(set = 0, binding = 4) uniform sampler2D depth_texture;
layout(std430, set = 0, binding = 5) writeonly buffer Positions { float positions[]; };
layout(std430, set = 0, binding = 6) readonly buffer Attributes { vec4 attributes[]; };

layout(constant_id = 0) const bool LIGHT_VOLUME = false;

#include "reconstruct.inc"

void main() {
  float stored = texelFetch(depth_texture, ivec2(gl_FragCoord.xy), 0).r;
  reconstruct_fragment(gl_FragCoord, stored);
}
