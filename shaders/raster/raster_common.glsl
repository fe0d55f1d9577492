// What every shader of the raster form shares, after ../common.glsl: the
// buffers of the one descriptor set both passes draw with, the draw's push
// constants, and where a sample's frame is.
//
// Where sample i of the batch is drawn (vulkan/raster_pass.cc); every draw
// is one instance of many vertices, as a mesh's, where instances of a few
// vertices each would leave most of a GPU's vertex lanes idle:
// - pass 1's small triangle, vertices 3i to 3i + 2, a few pixels across, into texel texel_of(i)
//   (atlas.inc) of an atlas image as wide as atlas_width: the vertex stage
//   moves it by whole pixels into one viewport over the atlas
//   (atlas_placement.glsl), so that its frame's pixel lands on that
//   texel, and a fragment off the sample's texel is discarded; one draw a
//   depth slot. Pass 2b's fragments then find their sample from
//   gl_FragCoord alone;
// - pass 2a's full-screen triangle and light volume, which span the frame:
//   through the frame's own viewport, at the sample's real pixel, with a
//   one-pixel scissor there; the vertex stage names the sample to the
//   fragment (a flat input). A device's interpolation rounds differently
//   at other window positions (on lavapipe, moving every sample onto its
//   atlas texel moved the ray variants' median error by 0.15 bit), and a
//   scissor is the only way to keep such a primitive to one pixel and
//   leave its interpolation as it is (clipping it to the pixel makes new
//   vertices, whose attributes the clipper rounds afresh); the draws are
//   VIEWPORTS_PER_DRAW samples each, once a run, not per cell.
layout(std430, set = 0, binding = 0) readonly buffer Frames { FrameParams frames[]; };
layout(std430, set = 0, binding = 1) readonly buffer Depths { DepthParams depth_params[]; };
layout(std430, set = 0, binding = 2) readonly buffer Pixels { uint pixels[]; };  // x | y << 16
layout(std430, set = 0, binding = 3) readonly buffer Samples { RasterSample raster[]; };
layout(push_constant) uniform Draw { RasterConstants draw; };
// Pass 2a: the sample that primitive k of the run's draws draws (its
// samples go block by block of the window, vulkan/raster_pass.cc's
// OrderCaptures).
layout(std430, set = 0, binding = 10) readonly buffer DrawOrder { uint drawn_sample[]; };

// Pass 2a's viewports a draw sets: primitive k takes viewport k modulo
// this, so the host starts every such draw at a multiple of it.
const int VIEWPORTS_PER_DRAW = 16;

#include "atlas.inc"

// Pass 1's triangles are a few pixels across and are not clipped (a clip
// would re-derive the depth it stores): a fragment that is not on the
// drawing sample's own texel is another sample's, and is discarded.
bool on_own_texel(vec4 frag_coord, uint drawing_sample) { return sample_at(frag_coord) == drawing_sample; }

// Whether the host gave sample i anything to draw (all zero: nothing, the
// rule of vulkan/raster_pass.cc's HasGeometry).
bool has_geometry(uint i) {
  RasterSample g = raster[i];
  vec4 zero = vec4(0.0f);
  return g.triangle0 != zero || g.triangle1 != zero || g.triangle2 != zero;
}
