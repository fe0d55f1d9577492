// inverse_vp (Unity URP: ComputeWorldSpacePosition; docs/sources.md).
// Clip-space position (ndc.xy, ndc depth, 1) through the inverse
// view-projection matrix, then the perspective divide by w. With GL-style
// clip depth the stored depth is first remapped to [-1, 1].
// Precision traps: the matrix folds the camera translation and the depth
// mapping together, so near the far plane w is a small difference of large
// float products, and a camera far from the origin puts large values into
// the matrix.
// No include guard: see compat.h. Needs params.h, screen.h.
DB_FN vec3 inverse_vp_world_position(FrameParams frame, DepthParams depth, vec2 uv, real stored) {
  vec2 ndc = ndc_from_uv(uv);
  real ndc_z = ndc_depth_from_window_depth(depth, stored);
  vec4 world = depth.inverse_view_projection * vec4(ndc.x, ndc.y, ndc_z, 1.0f);
  return vec3(world.x, world.y, world.z) / world.w;
}
