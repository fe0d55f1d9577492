// What every shader of the raster form shares, after ../common.glsl: the
// buffers of the one descriptor set both passes draw with, the draw's push
// constants, and where a sample's frame is.
//
// The atlas: sample i of the batch is drawn into texel texel_of(i)
// (atlas.inc) of an image as wide as atlas_width, as instance i of a
// draw, its geometry moved by whole pixels so that its frame's pixel lands
// on that texel; the geometry then rasterizes as it would at its real
// pixel, and a fragment finds its sample from gl_FragCoord alone. Two ways
// to move it (vulkan/raster_pass.cc):
// - pass 1's small triangles, a few pixels across: the vertex stage moves
//   them into one viewport over the atlas (atlas_placement.glsl), and a
//   fragment off the sample's texel is discarded; one draw a depth slot;
// - pass 2a's full-screen triangle and light volume, which span the frame:
//   each sample through a viewport of its own, placed by the host, with a
//   one-texel scissor. A scissor is the only way to keep such a primitive
//   to one texel and leave its interpolation as it is (clipping it to the
//   texel makes new vertices, whose attributes the clipper rounds afresh,
//   and the fragment no longer gets the full-screen interpolation); the
//   draws are VIEWPORTS_PER_DRAW samples each, once a run, not per cell.
layout(std430, set = 0, binding = 0) readonly buffer Frames { FrameParams frames[]; };
layout(std430, set = 0, binding = 1) readonly buffer Depths { DepthParams depth_params[]; };
layout(std430, set = 0, binding = 2) readonly buffer Pixels { uint pixels[]; };  // x | y << 16
layout(std430, set = 0, binding = 3) readonly buffer Samples { RasterSample raster[]; };
layout(push_constant) uniform Draw { RasterConstants draw; };

// Pass 2a's viewports a draw sets: its instances take them in turn, so the
// host starts every such draw at a multiple of this.
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
