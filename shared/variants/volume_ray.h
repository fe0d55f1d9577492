// volume_ray (Pettineo 2009, light-volume geometry; docs/sources.md).
// Drawing a light's bounding volume, the vertex stage passes the view-space
// position of the volume's surface; per pixel, scaling it by far / -z turns
// it into the camera->far-plane ray through that pixel, and the linear depth
// (eye depth / far) scales the ray to the stored point. The compute form
// places the surface on a plane at a per-frame depth inside the frustum and
// interpolates its view-space position across the screen.
// Precision traps: far / -z is a per-pixel division, and the ray is again
// far-plane long.
// No include guard: see compat.h. Needs params.h, screen.h.
DB_FN vec3 volume_ray_world_position(FrameParams frame, DepthParams depth, vec2 uv, real stored) {
  vec3 surface = interpolate_screen_attribute(frame.volume_position_origin, frame.volume_position_du,
                                              frame.volume_position_dv, uv);
  vec3 ray = surface * (frame.camera_position.w / -surface.z);
  vec3 view = stored * ray;
  return world_from_view(frame, view);
}
