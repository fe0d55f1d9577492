// What pass 2b's fragment programs of the raster form read and write
// beyond raster_common.glsl: the depth slot's atlas (the host binds the
// slot's set; read by texel, as a full-screen pass reads its depth
// buffer), the positions and pass 2a's captured attributes.
#include "raster_common.glsl"

layout(set = 0, binding = 4) uniform sampler2D depth_texture;
layout(std430, set = 0, binding = 5) writeonly buffer Positions { float positions[]; };
layout(std430, set = 0, binding = 6) readonly buffer Attributes { vec4 attributes[]; };
