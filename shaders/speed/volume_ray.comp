#version 450
#extension GL_GOOGLE_include_directive : require
// volume_ray (Pettineo 2009), timed: the formula is in shared/variants/volume_ray.h.
#include "../common.glsl"
#include "../../shared/variants/volume_ray.h"
#define RECONSTRUCT volume_ray_world_position
#include "speed_pass.glsl"
