// Screen-space helpers every variant shares: from a pixel to its texture
// coordinate and normalized device coordinate, what a rasterizer interpolates
// across the screen, and the way back from view space to world space.
// No include guard: see compat.h. Needs params.h.

// The first three components of a vec4 (GLSL would write v.xyz; swizzles are
// not in the shared subset).
DB_FN vec3 db_xyz(vec4 v) { return vec3(v.x, v.y, v.z); }

// Texture coordinate of a pixel's centre, v growing downwards, as a
// full-screen pass computes it from the fragment position (Unity URP divides
// the pixel position by the render-target size). The pixel's integer
// coordinates come as reals (exact below 2^24), so that a SIMD
// instantiation can hold a different pixel in every lane.
DB_FN vec2 uv_from_pixel(real pixel_x, real pixel_y, vec4 resolution) {
  return vec2((pixel_x + 0.5f) / resolution.x, (pixel_y + 0.5f) / resolution.y);
}

// Normalized device coordinates with y up: uv (0, 0) is NDC (-1, 1).
DB_FN vec2 ndc_from_uv(vec2 uv) { return vec2(uv.x * 2.0f - 1.0f, 1.0f - uv.y * 2.0f); }

// The value a rasterizer produces at uv for an attribute that varies
// linearly across a screen-covering primitive: its value at the top-left
// corner plus the barycentric-style steps along u and v. This is how the
// compute form stands in for vertex-stage outputs (Pettineo 2009, the eye-ray post 2011); a raster
// mode gets the same value from the hardware interpolator.
DB_FN vec3 interpolate_screen_attribute(vec4 origin, vec4 du, vec4 dv, vec2 uv) {
  return db_xyz(origin) + db_xyz(du) * uv.x + db_xyz(dv) * uv.y;
}

// A view-space position taken to world space the way a shader does it: the
// camera world matrix (inverse view), applied in the shader's precision.
DB_FN vec3 world_from_view(FrameParams frame, vec3 view) {
  return db_xyz(DB_MUL(frame.camera_world, vec4(view.x, view.y, view.z, 1.0f)));
}

// NDC depth read back from a stored window-space depth value: identical for
// clip depth [0, 1]; remapped to [-1, 1] for GL-style clip depth, the step
// Unity URP performs with lerp(UNITY_NEAR_CLIP_VALUE, 1, depth).
DB_FN real ndc_depth_from_window_depth(DepthParams depth, real window_depth) {
  real ndc_z = window_depth;
  if ((depth.convention & DB_CONVENTION_CLIP_MINUS_ONE) != 0u) {
    ndc_z = -1.0f + window_depth * 2.0f;
  }
  return ndc_z;
}
