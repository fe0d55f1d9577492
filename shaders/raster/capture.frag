#version 450
#extension GL_GOOGLE_include_directive : require
// Pass 2a of the raster form: what the rasterizer interpolated at the
// sample's pixel, from the full-screen triangle (the three rays) or from
// the light volume's back faces (LIGHT_VOLUME: the view-space position),
// stored as float32, exactly, for the sample's reconstructions to read
// (raster_pass.glsl). The sample's scissor keeps the primitive to one
// pixel, and the vertex stage names the sample. With COMPUTE_ATTRIBUTES (the compute-attributes probe,
// vulkan/arithmetic_probe.h) it stores instead what the compute form
// computes at the pixel from the frame's constants: the run then differs
// from one without it by what the interpolation does alone.
#include "../common.glsl"
#include "raster_common.glsl"

layout(constant_id = 0) const bool LIGHT_VOLUME = false;
layout(constant_id = 1) const bool COMPUTE_ATTRIBUTES = false;

layout(std430, set = 0, binding = 6) buffer Attributes { vec4 attributes[]; };

layout(location = 0) in vec3 frustum_ray;
layout(location = 1) in vec3 eye_ray_view;
layout(location = 2) in vec3 eye_ray_world;
layout(location = 3) in vec3 volume_position;
layout(location = 4) flat in uint sample_index;

void main() {
  uint i = sample_index;
  uint base = ATTRIBUTES_PER_SAMPLE * i;
  vec3 rays[3] = vec3[](frustum_ray, eye_ray_view, eye_ray_world);
  vec3 volume = volume_position;
  if (COMPUTE_ATTRIBUTES) {
    FrameParams frame = frames[frame_of(i)];
    uint pixel = pixels[i];
    vec2 uv = uv_from_pixel(float(pixel & 0xffffu), float(pixel >> 16u), frame.resolution);
    rays[0] = interpolate_screen_attribute(frame.frustum_ray_origin, frame.frustum_ray_du, frame.frustum_ray_dv, uv);
    rays[1] = interpolate_screen_attribute(frame.eye_ray_view_origin, frame.eye_ray_view_du, frame.eye_ray_view_dv, uv);
    rays[2] =
        interpolate_screen_attribute(frame.eye_ray_world_origin, frame.eye_ray_world_du, frame.eye_ray_world_dv, uv);
    volume = interpolate_screen_attribute(frame.volume_position_origin, frame.volume_position_du,
                                          frame.volume_position_dv, uv);
  }
  // w = 1: written (a light volume whose back faces missed the pixel
  // leaves its entry as cleared, w = 0).
  if (LIGHT_VOLUME) {
    attributes[base + 3u] = vec4(volume, 1.0f);
  } else {
    attributes[base] = vec4(rays[0], 1.0f);
    attributes[base + 1u] = vec4(rays[1], 1.0f);
    attributes[base + 2u] = vec4(rays[2], 1.0f);
  }
}
