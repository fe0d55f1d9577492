// One sample of the compute form, from its pixel (x | y << 16) and the
// value its depth texel holds: the variant's function at the pixel's
// centre. The including program defines RECONSTRUCT as that function; the
// accuracy pass (compute_pass.glsl) stores what it returns, the device
// judge's fused pass (judge/fused.comp) judges it where it is.
vec3 reconstruct_sample(FrameParams frame, DepthParams depth, uint pixel, float stored) {
  vec2 uv = uv_from_pixel(float(pixel & 0xffffu), float(pixel >> 16u), frame.resolution);
  return RECONSTRUCT(frame, depth, uv, stored);
}
