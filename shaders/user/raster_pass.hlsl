// Pass 2 of the raster form for a user's HLSL function: the bindings, push
// constants and attribute locations of ../raster/raster_pass.glsl, so that
// the host draws both alike and the same GLSL vertex stages feed it, and the
// same fragment work (../raster/reconstruct.inc). The including program
// defines RECONSTRUCT.
//
// The depth atlas is a Texture2D here; the compiler turns it into the
// combined image sampler the host binds (glslang's texture-sampler
// upgrade), which a texel fetch (Load) ignores the sampler of.

[[vk::binding(0, 0)]] StructuredBuffer<FrameParams> frames;
[[vk::binding(1, 0)]] StructuredBuffer<DepthParams> depth_params;
[[vk::binding(2, 0)]] StructuredBuffer<uint> pixels;  // x | y << 16
[[vk::binding(4, 0)]] Texture2D<float4> depth_texture;
[[vk::binding(5, 0)]] RWStructuredBuffer<float> positions;
[[vk::push_constant]] ConstantBuffer<RasterConstants> draw;

#include "../raster/atlas.inc"
#include "../raster/reconstruct.inc"

void main(float4 frag_coord : SV_Position, [[vk::location(0)]] float3 frustum_ray : FRUSTUM_RAY,
          [[vk::location(1)]] float3 eye_ray_view : EYE_RAY_VIEW,
          [[vk::location(2)]] float3 eye_ray_world : EYE_RAY_WORLD,
          [[vk::location(3)]] float3 volume_position : VOLUME_POSITION) {
  float stored = depth_texture.Load(int3(int(frag_coord.x), int(frag_coord.y), 0)).x;
  reconstruct_fragment(frag_coord, stored, frustum_ray, eye_ray_view, eye_ray_world, volume_position);
}
