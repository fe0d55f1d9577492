// frustum_ray (Pettineo 2009, full-screen pass; docs/sources.md).
// The vertex stage rotates the view-space far-plane frustum corners into world
// space with the camera world matrix (rotation only); the rasterizer
// interpolates them, so each pixel receives the ray from the camera to the far
// plane through its centre. The pixel stage scales that ray by the linear
// depth it reads (eye depth / far, in [0, 1]) and adds the camera position.
// Precision traps: the ray is far-plane long, so its float rounding is
// relative to the far distance, not to the depth of the point; and the final
// add to the camera position rounds in world space.
// No include guard: see compat.h. Needs params.h, screen.h.
DB_FN vec3 frustum_ray_world_position(FrameParams frame, DepthParams depth, vec2 uv, real stored) {
  vec3 ray = interpolate_screen_attribute(frame.frustum_ray_origin, frame.frustum_ray_du, frame.frustum_ray_dv, uv);
  return db_xyz(frame.camera_position) + stored * ray;
}
