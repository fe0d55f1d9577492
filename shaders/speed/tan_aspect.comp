#version 450
#extension GL_GOOGLE_include_directive : require
// tan_aspect (Coluna 2011), timed: the formula is in shared/variants/tan_aspect.h.
#include "../common.glsl"
#include "../../shared/variants/tan_aspect.h"
#define RECONSTRUCT tan_aspect_world_position
#include "speed_pass.glsl"
