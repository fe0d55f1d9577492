// The compute form of a reconstruction pass: one invocation per sample, the
// ray-based variants' interpolated inputs computed per pixel (screen.h).
// The including shader defines RECONSTRUCT as its variant's
// <variant>_world_position function from shared/variants/.
//
// Whole frames per workgroup: the host sets the workgroup size
// (specialization constant 0) to a multiple of the samples per frame, so a
// frame's constants are uniform across each of its invocations' SIMD
// groups, as a real pass's are across a draw.
layout(local_size_x_id = 0) in;

layout(std430, set = 0, binding = 0) readonly buffer Frames { FrameParams frames[]; };
layout(std430, set = 0, binding = 1) readonly buffer Depths { DepthParams depth_params[]; };
layout(std430, set = 0, binding = 2) readonly buffer Pixels { uint pixels[]; };
layout(std430, set = 0, binding = 3) readonly buffer StoredDepths { float stored_depths[]; };
layout(std430, set = 0, binding = 4) writeonly buffer Positions { float positions[]; };
layout(push_constant) uniform Pass { PassConstants pass; };

void main() {
  // The batch may start inside its first frame.
  int index = int(gl_GlobalInvocationID.x) - int(pass.first_sample_in_frame);
  uint frame_index = gl_GlobalInvocationID.x / pass.samples_per_frame;
  if (index < 0 || index >= int(pass.sample_count)) {
    return;
  }
  uint i = uint(index);
  FrameParams frame = frames[frame_index];
  DepthParams depth = depth_params[frame_index * pass.conventions_per_frame + pass.convention_slot];
  uint pixel = pixels[i];
  vec2 uv = uv_from_pixel(float(pixel & 0xffffu), float(pixel >> 16u), frame.resolution);
  vec3 p = RECONSTRUCT(frame, depth, uv, stored_depths[pass.depth_offset + i]);
  // Component by component: x of every sample, then y, then z.
  uint o = pass.output_offset + i;
  positions[o] = p.x;
  positions[o + pass.sample_count] = p.y;
  positions[o + 2u * pass.sample_count] = p.z;
}
