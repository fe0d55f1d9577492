#version 450
#extension GL_GOOGLE_include_directive : require
// The fragment row of the stage probe (stage_probe.glsl): one invocation per
// pixel of a width * height full-screen triangle, drawn with no attachment
// (the count is its only output).
#include "stage_probe.glsl"

void main() {
  const uvec2 pixel = uvec2(gl_FragCoord.xy);
  ProbeStage(pixel.y * probe.width + pixel.x);
}
