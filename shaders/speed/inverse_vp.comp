#version 450
#extension GL_GOOGLE_include_directive : require
// inverse_vp (Unity URP), timed: the formula is in shared/variants/inverse_vp.h.
#include "../common.glsl"
#include "../../shared/variants/inverse_vp.h"
#define RECONSTRUCT inverse_vp_world_position
#include "speed_pass.glsl"
