// What every shader of the raster form shares, after ../common.glsl: the
// buffers of the one descriptor set both passes draw with, the draw's push
// constants, and where a sample's frame is.
//
// The atlas: sample i of the batch is drawn into texel (i % atlas_width,
// i / atlas_width) of an image as wide as atlas_width, instance i of a draw,
// through a viewport of its own that the host places so that the frame's
// pixel of the sample lands on that texel (vulkan/raster_pass.cc). The
// geometry then rasterizes as it would at its real pixel, and a fragment
// finds its sample from gl_FragCoord alone.
layout(std430, set = 0, binding = 0) readonly buffer Frames { FrameParams frames[]; };
layout(std430, set = 0, binding = 1) readonly buffer Depths { DepthParams depth_params[]; };
layout(std430, set = 0, binding = 2) readonly buffer Pixels { uint pixels[]; };  // x | y << 16
layout(std430, set = 0, binding = 3) readonly buffer Samples { RasterSample raster[]; };
layout(push_constant) uniform Draw { RasterConstants draw; };

// The viewports a draw sets: its instances take them in turn, so the host
// starts every draw at a multiple of this.
const int VIEWPORTS_PER_DRAW = 16;

#include "atlas.inc"
