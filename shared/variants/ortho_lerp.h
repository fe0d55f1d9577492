// ortho_lerp (Unity's render pipelines, orthographic cameras; docs/sources.md).
// An orthographic view volume's depth buffer is linear in eye depth, so the
// engine undoes it with a linear interpolation between the clip planes, eye
// depth = lerp(near, far, raw) (raw = 1 - depth under reversed Z), and puts
// the pixel at NDC xy times the volume's half extents: no ray, no divide.
// The window depth is read as stored, for [0, 1] and [-1, 1] clip depth
// alike (a depth buffer holds window depth either way).
// Precision traps: under reversed Z, 1 - depth cancels near the near plane,
// where depth is close to 1 and its float32 spacing is 2^-24; and far -
// near is rounded in float32 each time it is formed.
// No include guard: see compat.h. Needs params.h, screen.h.
DB_FN vec3 ortho_lerp_world_position(FrameParams frame, DepthParams depth, vec2 uv, real stored) {
  vec2 ndc = ndc_from_uv(uv);
  real raw = stored;
  if ((depth.convention & DB_CONVENTION_REVERSED) != 0u) {
    raw = 1.0f - raw;
  }
  real near = frame.clip_planes.x;
  real far = frame.clip_planes.y;
  real eye_depth = near + (far - near) * raw;
  vec3 view = vec3(ndc.x * frame.lens.x + frame.lens_centre.x, ndc.y * frame.lens.y + frame.lens_centre.y, -eye_depth);
  return world_from_view(frame, view);
}
