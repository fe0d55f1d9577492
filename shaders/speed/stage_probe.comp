#version 450
#extension GL_GOOGLE_include_directive : require
// The compute row of the stage probe (stage_probe.glsl): one invocation per
// pixel of the width * height the other rows draw.
#include "stage_probe.glsl"
layout(local_size_x = 64) in;

void main() { ProbeStage(gl_GlobalInvocationID.x); }
