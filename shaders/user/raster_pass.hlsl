// Pass 2b of the raster form for a user's HLSL function: the bindings, push
// constants and specialization constant of ../raster/raster_pass.glsl, so
// that the host draws both alike, and the same fragment work
// (../raster/reconstruct.inc). The including program
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
[[vk::binding(6, 0)]] StructuredBuffer<float4> attributes;
[[vk::push_constant]] ConstantBuffer<RasterConstants> draw;
[[vk::constant_id(0)]] const bool LIGHT_VOLUME = false;

#include "../raster/atlas.inc"
#include "../raster/reconstruct.inc"

void main(float4 frag_coord : SV_Position) {
  float stored = depth_texture.Load(int3(int(frag_coord.x), int(frag_coord.y), 0)).x;
  reconstruct_fragment(frag_coord, stored);
}
