// eye_ray (the eye-ray post 2011; docs/sources.md).
// The G-buffer stores view-space z. The vertex stage emits the eye ray
// (clip.x*tan(fovY/2)*aspect, clip.y*tan(fovY/2), w) and that ray rotated to
// world space by the inverse view matrix; the pixel stage divides the
// interpolated view-space ray by its z and multiplies by the stored view z.
// Restated for our right-handed view space (camera looking down -Z), the
// ray's third component is -w and the stored view z is negative. The eye-ray post 2011
// multiplies the world-space ray by the depth without the division, which is
// only right when the ray's z is +1 everywhere (its left-handed full-screen
// quad); dividing the world-space ray by the same view-space z is the
// general form and makes the signs come out right in our space.
// No include guard: see compat.h. Needs params.h, screen.h.
DB_FN vec3 eye_ray_world_position(FrameParams frame, DepthParams depth, vec2 uv, real stored) {
  vec3 ray_view =
      interpolate_screen_attribute(frame.eye_ray_view_origin, frame.eye_ray_view_du, frame.eye_ray_view_dv, uv);
  vec3 ray_world =
      interpolate_screen_attribute(frame.eye_ray_world_origin, frame.eye_ray_world_du, frame.eye_ray_world_dv, uv);
  return ray_world * (stored / ray_view.z) + db_xyz(frame.camera_position);
}
