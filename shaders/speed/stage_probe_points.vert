#version 450
#extension GL_GOOGLE_include_directive : require
// The vertex row of the stage probe (stage_probe.glsl): width * height
// points, drawn with the rasterizer discarding them, so that the vertex
// stage alone runs.
#include "stage_probe.glsl"

void main() {
  ProbeStage(uint(gl_VertexIndex));
  gl_Position = vec4(0.0, 0.0, 0.5, 1.0);
  gl_PointSize = 1.0;
}
