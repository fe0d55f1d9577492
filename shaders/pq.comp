#version 450
#extension GL_GOOGLE_include_directive : require
// pq (the engine shader notes): the formula is in shared/variants/pq.h.
#include "common.glsl"
#include "../shared/variants/pq.h"
#define RECONSTRUCT pq_world_position
#include "compute_pass.glsl"
