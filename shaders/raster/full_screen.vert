#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_ARB_shader_viewport_layer_array : require
// Pass 2a of the raster form: the frame's full-screen triangle, per sample
// (vertices 3k to 3k + 2 draw drawn_sample[k]), through the frame's own
// viewport at the sample's real pixel, its scissor keeping that pixel
// alone (raster_common.glsl).
// Each vertex emits the screen attributes at its own uv, computed from the
// frame's constants in float32 as the engines' vertex stages do (Pettineo
// 2009's frustum ray; the eye-ray post's view- and world-space rays); the
// rasterizer interpolates them to the pixel.
#include "../common.glsl"
#include "raster_common.glsl"

layout(location = 0) out vec3 frustum_ray;
layout(location = 1) out vec3 eye_ray_view;
layout(location = 2) out vec3 eye_ray_world;
layout(location = 3) out vec3 volume_position;  // the light-volume form's; none here
layout(location = 4) flat out uint sample_index;

void main() {
  uint slot = uint(gl_VertexIndex) / 3u;
  uint vertex = uint(gl_VertexIndex) % 3u;
  uint i = drawn_sample[slot];
  FrameParams frame = frames[frame_of(i)];
  // uv (0, 0), (2, 0), (0, 2): a triangle whose inside covers the screen.
  vec2 uv = vec2(vertex == 1u ? 2.0f : 0.0f, vertex == 2u ? 2.0f : 0.0f);
  vec2 ndc = ndc_from_uv(uv);
  gl_Position = vec4(ndc.x, ndc.y, 0.0f, 1.0f);
  frustum_ray = interpolate_screen_attribute(frame.frustum_ray_origin, frame.frustum_ray_du, frame.frustum_ray_dv, uv);
  eye_ray_view = interpolate_screen_attribute(frame.eye_ray_view_origin, frame.eye_ray_view_du, frame.eye_ray_view_dv, uv);
  eye_ray_world =
      interpolate_screen_attribute(frame.eye_ray_world_origin, frame.eye_ray_world_du, frame.eye_ray_world_dv, uv);
  volume_position = vec3(0.0f);
  sample_index = i;
  gl_ViewportIndex = int(slot % uint(VIEWPORTS_PER_DRAW));
}
