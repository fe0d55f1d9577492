#version 450
// The memory-bandwidth probe of `depthbench speed` (bench/speed/
// gpu_pass_timer.h, MeasureBandwidth): a copy from one storage buffer to
// another, each far larger than the GPU's caches, timed as the
// reconstruction passes are. Bytes read plus bytes written over its time
// is the bandwidth a memory-bound pass can at best use, which makes the
// memory-bound floor of each pass (bytes per pixel over it).
//
// 16 bytes per invocation and step, the widest load and store every device
// has; consecutive invocations touch consecutive elements (coalesced).
// Each invocation steps a whole dispatch at a time (grid-stride), so that
// one dispatch of a bounded number of workgroups copies any size.
layout(local_size_x = 256) in;

layout(std430, set = 0, binding = 0) readonly buffer Source { uvec4 source[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Destination { uvec4 destination[]; };
layout(push_constant) uniform Size {
  uint elements;
} size;

void main() {
  uint stride = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  for (uint i = gl_GlobalInvocationID.x; i < size.elements; i += stride) {
    destination[i] = source[i];
  }
}
