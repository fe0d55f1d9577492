#version 450
#extension GL_GOOGLE_include_directive : require
// After pass 1, for every sample's texel of one depth slot's atlas: the
// value a texel fetch returns, as pass 2's fragments will read it, and
// whether the texel holds the sample's depth (shared/params.h's
// DB_RASTER_TEXEL_*). The reference decodes these fetched values (on the
// host, or on the device where the device judges), so that a device's own
// conversion of a unorm code to float (which the Vulkan specification does
// not require to be correctly rounded) is counted as storage, not as the
// shader's arithmetic.
#include "../common.glsl"
#include "raster_common.glsl"

layout(local_size_x = 64) in;
layout(set = 0, binding = 4) uniform sampler2D depth_texture;
layout(std430, set = 0, binding = 7) writeonly buffer Fetched { float fetched[]; };
layout(std430, set = 0, binding = 8) writeonly buffer TexelStatus { uint texel_status[]; };
// The copy of pass 1's coverage attachments the host reads too: one byte a
// texel, 1 where the rasterizer drew, laid out as the whole atlas from
// word draw.coverage_word.
layout(std430, set = 0, binding = 9) readonly buffer CoverageCopy { uint coverage_words[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= draw.sample_count) {
    return;
  }
  uint t = texel_of(i);
  fetched[draw.output_offset + i] = texelFetch(depth_texture, ivec2(int(t % draw.atlas_width), int(t / draw.atlas_width)), 0).r;
  uint covered = (coverage_words[draw.coverage_word + t / 4u] >> (8u * (t % 4u))) & 0xffu;
  texel_status[draw.output_offset + i] = !has_geometry(i) ? DB_RASTER_TEXEL_NO_GEOMETRY
                                         : covered == 0u  ? DB_RASTER_TEXEL_UNDRAWN
                                                          : DB_RASTER_TEXEL_DRAWN;
}
