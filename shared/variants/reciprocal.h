// reciprocal (the engine shader notes, second form; docs/sources.md).
// Multiply by the inverse of w instead of dividing: invW = B / (ndc_z - A),
// view = (ndc.x/H, ndc.y/V, -1) * invW.
// Precision trap: ndc_z - A cancels near the far plane of a standard-Z
// projection, where both are close to 1.
// No include guard: see compat.h. Needs params.h, screen.h.
DB_FN vec3 reciprocal_world_position(FrameParams frame, DepthParams depth, vec2 uv, real stored) {
  vec2 ndc = ndc_from_uv(uv);
  real ndc_z = ndc_depth_from_window_depth(depth, stored);
  real inverse_w = depth.coefficients.y / (ndc_z - depth.coefficients.x);
  vec3 view = vec3(ndc.x / frame.lens.z, ndc.y / frame.lens.w, -1.0f) * inverse_w;
  return world_from_view(frame, view);
}
