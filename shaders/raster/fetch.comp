#version 450
#extension GL_GOOGLE_include_directive : require
// After pass 1, the value a texel fetch returns for every sample's texel of
// one depth slot's atlas, as pass 2's fragments will read it: the host
// takes these as the stored values its reference decodes, so that a
// device's own conversion of a unorm code to float (which the Vulkan
// specification does not require to be correctly rounded) is counted as
// storage, not as the shader's arithmetic.
#include "../common.glsl"
#include "raster_common.glsl"

layout(local_size_x = 64) in;
layout(set = 0, binding = 4) uniform sampler2D depth_texture;
layout(std430, set = 0, binding = 5) writeonly buffer Fetched { float fetched[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= draw.sample_count) {
    return;
  }
  ivec2 texel = ivec2(int(i % draw.atlas_width), int(i / draw.atlas_width));
  fetched[draw.output_offset + i] = texelFetch(depth_texture, texel, 0).r;
}
