#version 450
#extension GL_GOOGLE_include_directive : require
// Pass 1 of the raster form, depth production: sample i's small triangle
// (vertices 3i to 3i + 2) through its point, drawn with the projection of
// the depth slot's convention, as a scene's geometry is. View-space z goes to the
// G-buffer formats' fragment stage (perspective-correct, as a G-buffer
// pass interpolates it).
#include "../common.glsl"
#include "raster_common.glsl"
#include "atlas_placement.glsl"

layout(location = 0) out float view_z;
layout(location = 1) flat out uint drawing_sample;

void main() {
  uint sample_index = uint(gl_VertexIndex) / 3u;
  uint vertex = uint(gl_VertexIndex) % 3u;
  uint frame_index = frame_of(sample_index);
  RasterSample geometry = raster[sample_index];
  vec4 corner = vertex == 0u ? geometry.triangle0 : (vertex == 1u ? geometry.triangle1 : geometry.triangle2);
  gl_Position = place_in_atlas(depth_of(frame_index, draw.convention_slot).view_projection * corner, sample_index);
  view_z = (frames[frame_index].world_view * corner).z;
  drawing_sample = sample_index;
}
