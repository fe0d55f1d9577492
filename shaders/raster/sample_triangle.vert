#version 450
#extension GL_GOOGLE_include_directive : require
// Pass 1 of the raster form, depth production: sample gl_InstanceIndex's
// small triangle through its point, drawn with the projection of the depth
// slot's convention, as a scene's geometry is. View-space z goes to the
// G-buffer formats' fragment stage (perspective-correct, as a G-buffer
// pass interpolates it).
#include "../common.glsl"
#include "raster_common.glsl"
#include "atlas_placement.glsl"

layout(location = 0) out float view_z;
layout(location = 1) flat out uint drawing_sample;

void main() {
  uint sample_index = uint(gl_InstanceIndex);
  uint frame_index = frame_of(sample_index);
  RasterSample geometry = raster[sample_index];
  vec4 corner = gl_VertexIndex == 0 ? geometry.triangle0 : (gl_VertexIndex == 1 ? geometry.triangle1 : geometry.triangle2);
  gl_Position = place_in_atlas(depth_of(frame_index, draw.convention_slot).view_projection * corner, sample_index);
  view_z = (frames[frame_index].world_view * corner).z;
  drawing_sample = sample_index;
}
