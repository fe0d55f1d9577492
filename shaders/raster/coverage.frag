#version 450
#extension GL_GOOGLE_include_directive : require
// Pass 1 into a depth attachment: the rasterizer writes the depth itself;
// the fragment only marks the texel covered, so that the host can tell a
// texel the triangle missed from one it drew.
#include "../common.glsl"
#include "raster_common.glsl"

layout(location = 0) in float view_z;  // what the G-buffer form reads; unused here
layout(location = 1) flat in uint drawing_sample;
layout(location = 0) out uint coverage;

void main() {
  if (!on_own_texel(gl_FragCoord, drawing_sample)) {
    discard;
  }
  coverage = 1u;
}
