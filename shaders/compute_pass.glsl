// The compute form of a reconstruction pass: the ray-based variants'
// interpolated inputs computed per pixel (screen.h). The including shader
// defines RECONSTRUCT as its variant's <variant>_world_position function
// from shared/variants/.
//
// Whole frames per workgroup: a frame's constants are the same for every
// invocation, as a real pass's are across a draw. Each invocation handles
// SAMPLES_PER_INVOCATION samples of its frame, and the host sets the
// workgroup size (specialization constant 0) so that the two multiply to
// the samples per frame; a workgroup takes FRAMES_PER_WORKGROUP frames in
// turn. A GPU gets one sample per invocation and one frame per workgroup.
//
// One dispatch runs all the cells of its variant: workgroup row y
// (gl_WorkGroupID.y) runs the cell that CellSlice entry first_cell + y
// describes. On lavapipe every dispatch is a fork and join of its threads,
// so fewer, larger dispatches leave the cores idle less.
//
// A software implementation runs the invocations in SIMD groups, and its
// cost is in memory access, not arithmetic: Mesa 22.3's lavapipe loads and
// stores storage buffers lane by lane, in a loop with a branch per lane
// (unless the index is built from constants alone), but moves a vector's
// components within one lane's turn. So there:
//   - each invocation loops over several samples and reads its frame's
//     constants once for them;
//   - each workgroup takes several frames (lavapipe calls the C allocator
//     at the start of every workgroup);
//   - where the samples per invocation are a multiple of four, an
//     invocation takes consecutive samples, and the per-sample inputs come
//     in and the positions go out as four-component vectors: one lane loop
//     per four samples instead of four. The host aligns the batch's slices
//     to quads (PassConstants.first_in_frame and slice_length).
// (Uniform texel buffers, which lavapipe fetches for all lanes at once,
// measured slower than this: its texel fetch runs the whole sampler.)
layout(local_size_x_id = 0) in;
layout(constant_id = 1) const uint SAMPLES_PER_INVOCATION = 1u;
layout(constant_id = 2) const uint FRAMES_PER_WORKGROUP = 1u;

layout(std430, set = 0, binding = 0) readonly buffer Frames { FrameParams frames[]; };
layout(std430, set = 0, binding = 1) readonly buffer Depths { DepthParams depth_params[]; };
// The per-sample buffers, each also seen as quads of four samples.
layout(std430, set = 0, binding = 2) readonly buffer Pixels { uint pixels[]; };  // x | y << 16
layout(std430, set = 0, binding = 2) readonly buffer PixelQuads { uvec4 pixel_quads[]; };
layout(std430, set = 0, binding = 3) readonly buffer StoredDepths { float stored_depths[]; };
layout(std430, set = 0, binding = 3) readonly buffer StoredDepthQuads { vec4 stored_depth_quads[]; };
layout(std430, set = 0, binding = 4) readonly buffer CellSlices { CellSlice cell_slices[]; };
layout(std430, set = 0, binding = 5) writeonly buffer Positions { float positions[]; };
layout(std430, set = 0, binding = 5) writeonly buffer PositionQuads { vec4 position_quads[]; };
layout(push_constant) uniform Pass { PassConstants pass; };

#include "reconstruct_sample.glsl"

// The slice element of the sample at `in_frame` within frame `frame_index`;
// negative or >= slice_length when the batch starts or ends inside the frame.
int slice_element(uint frame_index, uint in_frame) {
  return int(frame_index * pass.samples_per_frame + in_frame) - int(pass.first_in_frame);
}

// One frame of the batch, reconstructed by this workgroup for one cell.
void reconstruct_frame(uint frame_index, CellSlice cell) {
  FrameParams frame = frames[frame_index];
  DepthParams depth = depth_params[frame_index * pass.conventions_per_frame + cell.convention_slot];
  uint n = pass.slice_length;
  // Chosen at pipeline creation: the other branch compiles away.
  if (SAMPLES_PER_INVOCATION % 4u == 0u) {
    // Quads: consecutive samples per invocation, four at a time. The host
    // starts and pads the slices so that quads never straddle their ends.
    for (uint q = 0u; q < SAMPLES_PER_INVOCATION; q += 4u) {
      int e = slice_element(frame_index, gl_LocalInvocationID.x * SAMPLES_PER_INVOCATION + q);
      if (e < 0 || e >= int(n)) {
        continue;
      }
      uint i = uint(e);
      uvec4 px = pixel_quads[i / 4u];
      vec4 sd = stored_depth_quads[(cell.depth_offset + i) / 4u];
      mat4x3 p = mat4x3(reconstruct_sample(frame, depth, px.x, sd.x), reconstruct_sample(frame, depth, px.y, sd.y),
                        reconstruct_sample(frame, depth, px.z, sd.z), reconstruct_sample(frame, depth, px.w, sd.w));
      mat3x4 t = transpose(p);  // rows: x, y, z of the four samples
      uint o = (cell.output_offset + i) / 4u;
      position_quads[o] = t[0];
      position_quads[o + n / 4u] = t[1];
      position_quads[o + n / 2u] = t[2];
    }
  } else {
    for (uint k = 0u; k < SAMPLES_PER_INVOCATION; ++k) {
      int e = slice_element(frame_index, k * gl_WorkGroupSize.x + gl_LocalInvocationID.x);
      if (e < 0 || e >= int(n)) {
        continue;
      }
      uint i = uint(e);
      vec3 p = reconstruct_sample(frame, depth, pixels[i], stored_depths[cell.depth_offset + i]);
      uint o = cell.output_offset + i;
      positions[o] = p.x;
      positions[o + n] = p.y;
      positions[o + 2u * n] = p.z;
    }
  }
}

void main() {
  CellSlice cell = cell_slices[pass.first_cell + gl_WorkGroupID.y];
  for (uint f = 0u; f < FRAMES_PER_WORKGROUP; ++f) {
    uint frame_index = gl_WorkGroupID.x * FRAMES_PER_WORKGROUP + f;
    if (frame_index < pass.frame_count) {
      reconstruct_frame(frame_index, cell);
    }
  }
}
