// The timed pass of `depthbench speed` for a user's HLSL function: the
// bindings, constants and work of ../speed/speed_pass.glsl (read it for
// what is measured). The including program defines RECONSTRUCT.

[[vk::constant_id(0)]] const uint TAPS = 1;
[[vk::constant_id(1)]] const uint CONVENTION = 0;

struct SpeedConstants {
  FrameParams frame;
  DepthParams depth_constants;
};
[[vk::binding(0, 0)]] ConstantBuffer<SpeedConstants> constants;
[[vk::binding(1, 0)]] Texture2D<float4> depth_image;
[[vk::binding(2, 0)]] RWStructuredBuffer<float> results;
struct Size {
  uint width;
  uint height;
};
[[vk::push_constant]] ConstantBuffer<Size> size;

[numthreads(8, 8, 1)]
void main(uint3 id : SV_DispatchThreadID) {
  if (id.x >= size.width || id.y >= size.height) {
    return;
  }
  FrameParams frame = constants.frame;
  DepthParams depth = constants.depth_constants;
  depth.convention = CONVENTION;
  int2 last = int2(int(size.width) - 1, int(size.height) - 1);
  float3 sum = float3(0.0f, 0.0f, 0.0f);
  for (uint tap = 0; tap < TAPS; ++tap) {
    int2 pixel = min(int2(int(id.x + (tap & 3u) * 2u), int(id.y + (tap >> 2u) * 2u)), last);
    float stored = depth_image.Load(int3(pixel, 0)).x;
    float2 uv = uv_from_pixel(float(pixel.x), float(pixel.y), frame.resolution);
    sum = sum + RECONSTRUCT(frame, depth, uv, stored);
  }
  results[id.y * size.width + id.x] = sum.x + sum.y + sum.z;
}
