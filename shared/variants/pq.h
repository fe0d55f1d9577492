// pq (the engine shader notes, multiply-add form; docs/sources.md).
// invW = 1 / (ndc_z * P + Q) with P = 1/B and Q = -A/B precomputed on the
// host: one multiply-add and one reciprocal per pixel.
// Precision trap: ndc_z * P and Q are large and of opposite sign near the
// far plane of a standard-Z projection, and P, Q are themselves rounded.
// No include guard: see compat.h. Needs params.h, screen.h.
DB_FN vec3 pq_world_position(FrameParams frame, DepthParams depth, vec2 uv, real stored) {
  vec2 ndc = ndc_from_uv(uv);
  real ndc_z = ndc_depth_from_window_depth(depth, stored);
  real inverse_w = 1.0f / (ndc_z * depth.coefficients.z + depth.coefficients.w);
  vec3 view = vec3(ndc.x / frame.lens.z, ndc.y / frame.lens.w, -1.0f) * inverse_w;
  return world_from_view(frame, view);
}
