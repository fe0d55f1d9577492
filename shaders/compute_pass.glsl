// The compute form of a reconstruction pass: the ray-based variants'
// interpolated inputs computed per pixel (screen.h). The including shader
// defines RECONSTRUCT as its variant's <variant>_world_position function
// from shared/variants/.
//
// One frame per workgroup: the frame's constants are the same for every
// invocation, as a real pass's are across a draw. Each invocation handles
// SAMPLES_PER_INVOCATION samples of its frame, and the host sets the
// workgroup size (specialization constant 0) so that the two multiply to
// the samples per frame. A GPU gets one sample per invocation. A software
// implementation runs a workgroup's invocations in SIMD groups and reads
// storage-buffer constants lane by lane (lavapipe does), so there each
// invocation loops over several samples and reads its frame's constants
// once for all of them.
layout(local_size_x_id = 0) in;
layout(constant_id = 1) const uint SAMPLES_PER_INVOCATION = 1u;

layout(std430, set = 0, binding = 0) readonly buffer Frames { FrameParams frames[]; };
layout(std430, set = 0, binding = 1) readonly buffer Depths { DepthParams depth_params[]; };
layout(std430, set = 0, binding = 2) readonly buffer Pixels { uint pixels[]; };
layout(std430, set = 0, binding = 3) readonly buffer StoredDepths { float stored_depths[]; };
layout(std430, set = 0, binding = 4) writeonly buffer Positions { float positions[]; };
layout(push_constant) uniform Pass { PassConstants pass; };

void main() {
  uint frame_index = gl_WorkGroupID.x;
  FrameParams frame = frames[frame_index];
  DepthParams depth = depth_params[frame_index * pass.conventions_per_frame + pass.convention_slot];
  for (uint k = 0u; k < SAMPLES_PER_INVOCATION; ++k) {
    // The batch may start and end inside a frame.
    uint in_frame = k * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
    int index = int(frame_index * pass.samples_per_frame + in_frame) - int(pass.first_sample_in_frame);
    if (index < 0 || index >= int(pass.sample_count)) {
      continue;
    }
    uint i = uint(index);
    uint pixel = pixels[i];
    vec2 uv = uv_from_pixel(float(pixel & 0xffffu), float(pixel >> 16u), frame.resolution);
    vec3 p = RECONSTRUCT(frame, depth, uv, stored_depths[pass.depth_offset + i]);
    // Component by component: x of every sample, then y, then z.
    uint o = pass.output_offset + i;
    positions[o] = p.x;
    positions[o + pass.sample_count] = p.y;
    positions[o + 2u * pass.sample_count] = p.z;
  }
}
