#version 450
#extension GL_GOOGLE_include_directive : require
// ortho_lerp (Unity, orthographic), timed: the formula is in shared/variants/ortho_lerp.h.
#include "../common.glsl"
#include "../../shared/variants/ortho_lerp.h"
#define RECONSTRUCT ortho_lerp_world_position
#include "speed_pass.glsl"
