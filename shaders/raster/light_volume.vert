#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_ARB_shader_viewport_layer_array : require
// Pass 2a of the raster form for volume_ray cells (Pettineo 2009, light-volume
// geometry): the sample's cube, twelve triangles, of which the pipeline
// draws the back faces (the camera may be inside a light's volume; its
// back faces are always in view). Each vertex emits its view-space
// position, which the rasterizer interpolates (perspective-correct) to the
// surface point on the pixel's ray. The depth convention does not matter:
// this pass writes no depth, and depth clamping keeps the near and far
// planes from clipping the cube.
#include "../common.glsl"
#include "raster_common.glsl"

layout(location = 0) out vec3 frustum_ray;  // the full-screen form's; none here
layout(location = 1) out vec3 eye_ray_view;
layout(location = 2) out vec3 eye_ray_world;
layout(location = 3) out vec3 volume_position;
layout(location = 4) flat out uint sample_index;

// Vertex c is corner c of the cube: the centre plus (c & 1, c & 2, c & 4 ?
// +half : -half) along x, y, z. The draw is indexed (vulkan/raster_pass.cc's
// kCubeIndices), so the eight corners are shaded once a cube; vertices 8k
// to 8k + 7 are the cube of drawn_sample[k].

float corner_coordinate(float centre, float half_edge, uint corner, uint bit) {
  return (corner & bit) != 0u ? centre + half_edge : centre - half_edge;
}

void main() {
  uint slot = uint(gl_VertexIndex) / 8u;
  uint i = drawn_sample[slot];
  uint frame_index = frame_of(i);
  vec4 volume = raster[i].volume;
  uint corner = uint(gl_VertexIndex) % 8u;
  vec4 world = vec4(corner_coordinate(volume.x, volume.w, corner, 1u), corner_coordinate(volume.y, volume.w, corner, 2u),
                    corner_coordinate(volume.z, volume.w, corner, 4u), 1.0f);
  gl_Position = depth_of(frame_index, 0u).view_projection * world;
  volume_position = (frames[frame_index].world_view * world).xyz;
  frustum_ray = vec3(0.0f);
  eye_ray_view = vec3(0.0f);
  eye_ray_world = vec3(0.0f);
  sample_index = i;
  gl_ViewportIndex = int(slot % uint(VIEWPORTS_PER_DRAW));
}
