// Shader constants of a frame: the FrameParams and DepthParams of
// shared/params.h, computed exactly (double-double) from the frame's
// parameters and then rounded once to float32. That is the best an engine
// can hand its shaders, so what remains is the error of the reconstruction
// itself, not of a sloppy host-side matrix inverse.
#pragma once

#include "bench/numerics/formulas.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/sampler.h"

namespace depthbench {

hp::FrameParams BuildFrameParams(const Frame& frame);
// Only for the projective conventions (Info(c).hardware); `frame_params` is
// BuildFrameParams(frame).
hp::DepthParams BuildDepthParams(const Frame& frame, const hp::FrameParams& frame_params, Convention convention);

f32::FrameParams RoundToFloat(const hp::FrameParams& params);
f32::DepthParams RoundToFloat(const hp::DepthParams& params);

}  // namespace depthbench
