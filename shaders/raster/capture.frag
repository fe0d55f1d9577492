#version 450
#extension GL_GOOGLE_include_directive : require
// Pass 2a of the raster form: what the rasterizer interpolated at the
// sample's pixel, from the full-screen triangle (the three rays) or from
// the light volume's back faces (LIGHT_VOLUME: the view-space position),
// stored as float32, exactly, for the sample's reconstructions to read
// (raster_pass.glsl). The sample's scissor keeps the primitive to its own
// texel.
#include "../common.glsl"
#include "raster_common.glsl"

layout(constant_id = 0) const bool LIGHT_VOLUME = false;

layout(std430, set = 0, binding = 6) buffer Attributes { vec4 attributes[]; };

layout(location = 0) in vec3 frustum_ray;
layout(location = 1) in vec3 eye_ray_view;
layout(location = 2) in vec3 eye_ray_world;
layout(location = 3) in vec3 volume_position;

void main() {
  uint base = ATTRIBUTES_PER_SAMPLE * sample_at(gl_FragCoord);
  // w = 1: written (a light volume whose back faces missed the pixel
  // leaves its entry as cleared, w = 0).
  if (LIGHT_VOLUME) {
    attributes[base + 3u] = vec4(volume_position, 1.0f);
  } else {
    attributes[base] = vec4(frustum_ray, 1.0f);
    attributes[base + 1u] = vec4(eye_ray_view, 1.0f);
    attributes[base + 2u] = vec4(eye_ray_world, 1.0f);
  }
}
