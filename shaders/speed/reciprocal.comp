#version 450
#extension GL_GOOGLE_include_directive : require
// reciprocal (the engine shader notes), timed: the formula is in shared/variants/reciprocal.h.
#include "../common.glsl"
#include "../../shared/variants/reciprocal.h"
#define RECONSTRUCT reciprocal_world_position
#include "speed_pass.glsl"
