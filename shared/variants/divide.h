// divide (the engine shader notes, first form; docs/sources.md).
// From ndc_z = A + B / z it follows 1/z = ndc_z/B - A/B, and the view-space
// position is (ndc.x/H, ndc.y/V, -1) / (ndc_z/B - A/B), with H and V the
// projection's horizontal and vertical scales. The engine shader notes work in a Z-up
// space where y is depth; in our view space depth is -z, hence the -1.
// Precision trap: ndc_z/B - A/B subtracts two nearly equal quotients near
// the far plane of a standard-Z projection.
// No include guard: see compat.h. Needs params.h, screen.h.
DB_FN vec3 divide_world_position(FrameParams frame, DepthParams depth, vec2 uv, real stored) {
  vec2 ndc = ndc_from_uv(uv);
  real ndc_z = ndc_depth_from_window_depth(depth, stored);
  real a = depth.coefficients.x;
  real b = depth.coefficients.y;
  vec3 view = vec3(ndc.x / frame.lens.z, ndc.y / frame.lens.w, -1.0f);
  view = view / (ndc_z / b - a / b);
  return world_from_view(frame, view);
}
