#version 450
#extension GL_GOOGLE_include_directive : require
// Pass 1 into a G-buffer channel: the fragment writes what the format
// stores, as a G-buffer pass does, from the interpolated view-space z:
// linear depth (eye depth / far) or view z itself (VIEW_Z). The channel
// converts the float (to float16, or to 16-bit unorm) as it stores it.
#include "../common.glsl"
#include "raster_common.glsl"

layout(constant_id = 0) const bool VIEW_Z = false;

layout(location = 0) in float view_z;
layout(location = 1) flat in uint drawing_sample;
layout(location = 0) out uint coverage;
layout(location = 1) out float stored;

void main() {
  if (!on_own_texel(gl_FragCoord, drawing_sample)) {
    discard;
  }
  coverage = 1u;
  if (VIEW_Z) {
    stored = view_z;
  } else {
    stored = -view_z / frames[frame_of(sample_at(gl_FragCoord))].camera_position.w;
  }
}
