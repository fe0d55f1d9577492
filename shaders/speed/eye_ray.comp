#version 450
#extension GL_GOOGLE_include_directive : require
// eye_ray (the eye-ray post 2011), timed: the formula is in shared/variants/eye_ray.h.
#include "../common.glsl"
#include "../../shared/variants/eye_ray.h"
#define RECONSTRUCT eye_ray_world_position
#include "speed_pass.glsl"
