#version 450
#extension GL_GOOGLE_include_directive : require
// divide (the engine shader notes), timed: the formula is in shared/variants/divide.h.
#include "../common.glsl"
#include "../../shared/variants/divide.h"
#define RECONSTRUCT divide_world_position
#include "speed_pass.glsl"
