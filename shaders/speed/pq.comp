#version 450
#extension GL_GOOGLE_include_directive : require
// pq (seed 004), timed: the formula is in shared/variants/pq.h.
#include "../common.glsl"
#include "../../shared/variants/pq.h"
#define RECONSTRUCT pq_world_position
#include "speed_pass.glsl"
