// How pass 1 of the raster form puts a sample's triangle on its atlas
// texel, after raster_common.glsl. Every draw of a batch uses one viewport
// (vulkan/raster_pass.cc sets it): it spans the atlas and a guard band of
// ATLAS_GUARD texels on every side, 2 * atlas_width texels wide (from
// -ATLAS_GUARD) and viewport_height high (a power of two, from -ATLAS_GUARD,
// y up as the frames' NDC), so that its half extents are powers of two.
//
// A frame of resolution R drawn at its real pixel P would have its NDC
// origin at framebuffer position R / 2 (y down). Moved by whole pixels so
// that P lands on the sample's texel T, that origin is at T - P + R / 2,
// and a point at frame NDC n lies at (T - P + R / 2) + (n.x, -n.y) * R / 2.
// The atlas viewport puts atlas NDC m at C + (m.x, -m.y) * H (C: its centre,
// H: its half extents), so m = n * R / (2 H) + the origins' offset, an
// affine map of x / w and y / w, which is the same map of clip x and y with
// w kept: perspective-correct interpolation, depth and culling see the
// geometry they would see at the real pixel. The scale and the offset are
// exact in float32 (whole and half pixels over powers of two); the clip
// position's two products and sum round once or twice, which moves a
// vertex by about 2^-24 of the frame's width (1e-4 pixel at 3840), under a
// thirtieth of the 8-bit sub-pixel grid of the rasterizers at hand.

const float ATLAS_GUARD = 128.0f;

vec2 atlas_viewport_centre() { return vec2(float(draw.atlas_width) - ATLAS_GUARD, 0.5f * float(draw.viewport_height) - ATLAS_GUARD); }
vec2 atlas_viewport_half() { return vec2(float(draw.atlas_width), 0.5f * float(draw.viewport_height)); }

vec2 atlas_texel(uint sample_index) {
  uint texel = texel_of(sample_index);
  return vec2(float(texel % draw.atlas_width), float(texel / draw.atlas_width));
}

// `clip`, a clip position of the sample's frame, moved to the atlas.
vec4 place_in_atlas(vec4 clip, uint sample_index) {
  uint pixel = pixels[sample_index];
  vec2 resolution = frames[frame_of(sample_index)].resolution.xy;
  vec2 frame_origin = atlas_texel(sample_index) - vec2(float(pixel & 0xffffu), float(pixel >> 16u)) + 0.5f * resolution;
  vec2 centre = atlas_viewport_centre();
  vec2 half_extent = atlas_viewport_half();
  vec2 scale = resolution / (2.0f * half_extent);
  vec2 offset = vec2(frame_origin.x - centre.x, centre.y - frame_origin.y) / half_extent;
  return vec4(clip.x * scale.x + clip.w * offset.x, clip.y * scale.y + clip.w * offset.y, clip.z, clip.w);
}
