// Pass 2 of the raster form, the reconstruction, as a fragment program:
// one fragment per sample, at its atlas texel. The including program
// defines RECONSTRUCT as its variant's function (shared/variants/, or the
// user's, through ../user/contract.inc), exactly as ../compute_pass.glsl
// has it, and the function runs unchanged: the attributes the compute form
// interpolates from a frame's origin and steps come here from the vertex
// stage, as the origin of a frame whose steps are zero (origin + 0 * u +
// 0 * v is the varying, exactly).
//
// The depth slot's atlas is read by texel, as a full-screen pass reads its
// depth buffer; the positions go where the compute form puts them (slices
// of x, y, z per cell, sample_count long).
#include "raster_common.glsl"

// The atlas of the cell's depth slot (the host binds the slot's set).
layout(set = 0, binding = 4) uniform sampler2D depth_texture;
layout(std430, set = 0, binding = 5) writeonly buffer Positions { float positions[]; };

layout(location = 0) in vec3 frustum_ray;
layout(location = 1) in vec3 eye_ray_view;
layout(location = 2) in vec3 eye_ray_world;
layout(location = 3) in vec3 volume_position;

vec4 as_origin(vec3 varying_value) { return vec4(varying_value, 0.0f); }

void main() {
  uint i = sample_at(gl_FragCoord);
  uint frame_index = frame_of(i);
  FrameParams frame = frames[frame_index];
  DepthParams depth = depth_of(frame_index, draw.convention_slot);
  float stored = texelFetch(depth_texture, ivec2(gl_FragCoord.xy), 0).r;
  uint pixel = pixels[i];
  vec2 uv = uv_from_pixel(float(pixel & 0xffffu), float(pixel >> 16u), frame.resolution);

  vec4 none = vec4(0.0f);
  frame.frustum_ray_origin = as_origin(frustum_ray);
  frame.frustum_ray_du = none;
  frame.frustum_ray_dv = none;
  frame.volume_position_origin = as_origin(volume_position);
  frame.volume_position_du = none;
  frame.volume_position_dv = none;
  frame.eye_ray_view_origin = as_origin(eye_ray_view);
  frame.eye_ray_view_du = none;
  frame.eye_ray_view_dv = none;
  frame.eye_ray_world_origin = as_origin(eye_ray_world);
  frame.eye_ray_world_du = none;
  frame.eye_ray_world_dv = none;

  vec3 p = RECONSTRUCT(frame, depth, uv, stored);
  uint o = draw.output_offset + i;
  positions[o] = p.x;
  positions[o + draw.sample_count] = p.y;
  positions[o + 2u * draw.sample_count] = p.z;
}
