// The accuracy pass for a user's HLSL function: the same bindings, push
// constants and sample placement as ../compute_pass.glsl takes in its
// one-sample-at-a-time form, so the host drives both alike. Its workgroup is
// one whole frame (64 samples, one per invocation; the host's workgroup-size
// and samples-per-invocation constants have no counterpart here, and
// Vulkan ignores them), and a workgroup takes FRAMES_PER_WORKGROUP frames.
// The including program defines RECONSTRUCT.

[[vk::constant_id(2)]] const uint FRAMES_PER_WORKGROUP = 1;
static const uint kSamplesPerWorkgroup = 64;

[[vk::binding(0, 0)]] StructuredBuffer<FrameParams> frames;
[[vk::binding(1, 0)]] StructuredBuffer<DepthParams> depth_params;
[[vk::binding(2, 0)]] StructuredBuffer<uint> pixels;  // x | y << 16
[[vk::binding(3, 0)]] StructuredBuffer<float> stored_depths;
[[vk::binding(4, 0)]] StructuredBuffer<CellSlice> cell_slices;
[[vk::binding(5, 0)]] RWStructuredBuffer<float> positions;
[[vk::push_constant]] ConstantBuffer<PassConstants> pass;

[numthreads(64, 1, 1)]
void main(uint3 local : SV_GroupThreadID, uint3 group : SV_GroupID) {
  CellSlice cell = cell_slices[pass.first_cell + group.y];
  uint n = pass.slice_length;
  for (uint f = 0; f < FRAMES_PER_WORKGROUP; ++f) {
    uint frame_index = group.x * FRAMES_PER_WORKGROUP + f;
    if (frame_index >= pass.frame_count) {
      return;
    }
    FrameParams frame = frames[frame_index];
    DepthParams depth = depth_params[frame_index * pass.conventions_per_frame + cell.convention_slot];
    for (uint in_frame = local.x; in_frame < pass.samples_per_frame; in_frame += kSamplesPerWorkgroup) {
      int e = int(frame_index * pass.samples_per_frame + in_frame) - int(pass.first_in_frame);
      if (e < 0 || e >= int(n)) {
        continue;
      }
      uint i = uint(e);
      uint pixel = pixels[i];
      float2 uv = uv_from_pixel(float(pixel & 0xffffu), float(pixel >> 16u), frame.resolution);
      float3 p = RECONSTRUCT(frame, depth, uv, stored_depths[cell.depth_offset + i]);
      uint o = cell.output_offset + i;
      positions[o] = p.x;
      positions[o + n] = p.y;
      positions[o + 2u * n] = p.z;
    }
  }
}
