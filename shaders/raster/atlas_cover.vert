#version 450
#extension GL_GOOGLE_include_directive : require
// Pass 2b of the raster form: one triangle over the whole atlas viewport,
// so that every texel's fragment runs the cell's reconstruction.
#include "../common.glsl"
#include "raster_common.glsl"

void main() {
  vec2 ndc = vec2(gl_VertexIndex == 1 ? 3.0f : -1.0f, gl_VertexIndex == 2 ? 3.0f : -1.0f);
  gl_Position = vec4(ndc, 0.0f, 1.0f);
}
