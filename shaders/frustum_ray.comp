#version 450
#extension GL_GOOGLE_include_directive : require
// frustum_ray (Pettineo 2009): the formula is in shared/variants/frustum_ray.h.
#include "common.glsl"
#include "../shared/variants/frustum_ray.h"
#define RECONSTRUCT frustum_ray_world_position
#include "compute_pass.glsl"
