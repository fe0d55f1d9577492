// tan_aspect (Coluna 2011, similar triangles; docs/sources.md).
// With linear depth in [0, 1] (0 at the camera, 1 at the far plane) the
// view-space position follows from the field of view alone:
//   view.xy = (tan(fovY/2)*aspect, tan(fovY/2)) * ndc.xy * eye depth,
//   view.z  = -eye depth,
// no matrix and no per-pixel division, only multiplies.
// Coluna 2011 negates tan(fovY/2) on the host to absorb its flipped texture v;
// here uv_from_pixel/ndc_from_uv already give y up, so no negation is needed.
// No include guard: see compat.h. Needs params.h, screen.h.
DB_FN vec3 tan_aspect_world_position(FrameParams frame, DepthParams depth, vec2 uv, real stored) {
  vec2 ndc = ndc_from_uv(uv);
  real eye_depth = stored * frame.camera_position.w;
  vec3 view = vec3(frame.lens.x * ndc.x * eye_depth, frame.lens.y * ndc.y * eye_depth, -eye_depth);
  return world_from_view(frame, view);
}
