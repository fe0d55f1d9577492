// Shader constants of a frame: the FrameParams and DepthParams of
// shared/params.h, computed one of two ways (ConstantsModel, domain.h):
//   exact    in double-double from the frame's parameters, then rounded
//            once to float32: the best an engine can hand its shaders, so
//            what remains is the error of the reconstruction itself;
//   float32  as an engine computes them: the camera's parameters rounded
//            to float32, the view and projection matrices built from them
//            in float32, multiplied in float32, the view-projection
//            inverted by a general float 4x4 inverse (glm::inverse, the
//            cofactor expansion), and every other constant derived from
//            those floats in float32.
// The frame itself (the truth the reference judges against) is the same
// either way.
#pragma once

#include <cstddef>
#include <span>

#include "bench/numerics/formulas.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/sampler.h"

namespace depthbench {

// The frame parameters the constant formulas read, in one arithmetic. The
// far plane is 0 where a frame has none, as FrameParams.camera_position.w
// reads.
template <class Real>
struct FrameValues {
  Real tan_half_fov_y, aspect, centre_x, centre_y, near, far, volume_depth, width, height;
  glm::vec<3, Real> camera_position;
  glm::mat<3, 3, Real> rotation;
};

hp::FrameParams BuildFrameParams(const Frame& frame);
// Only for the projective conventions (Info(c).hardware); `frame_params` is
// BuildFrameParams(frame).
hp::DepthParams BuildDepthParams(const Frame& frame, const hp::FrameParams& frame_params, Convention convention);

// The same formulas over a box of frames: every field encloses the exact
// constant of every frame whose parameters lie in `box` (bench/bound/).
iv::FrameParams EncloseFrameParams(const FrameValues<Enclosure>& box);
iv::DepthParams EncloseDepthParams(const FrameValues<Enclosure>& box, Convention convention);

f32::FrameParams RoundToFloat(const hp::FrameParams& params);
f32::DepthParams RoundToFloat(const hp::DepthParams& params);

// The float32 path: the engine's view and projection matrices (right-handed
// view looking down -Z; the projection maps view z to clip depth
// A * z + B over w = z, so ndc = A + B / z; glm::ortho's for an
// orthographic convention, ndc = A + B * z at w = 1), and the constants an engine
// derives from them.
glm::mat4 EngineViewMatrix(const Frame& frame);
glm::mat4 EngineProjectionMatrix(const Frame& frame, Convention convention);
f32::FrameParams EngineFrameParams(const Frame& frame);
f32::DepthParams EngineDepthParams(const Frame& frame, Convention convention);

// What the shaders of `frame` receive under `model`: its FrameParams, and
// in depth_params[c] the DepthParams of hardware convention c (zero for
// the finite-far conventions when the frame has no finite far plane: their
// cells do not run on it).
void BuildShaderConstants(const Frame& frame, ConstantsModel model, f32::FrameParams& frame_params,
                          std::span<f32::DepthParams, kHardwareConventionCount> depth_params);

// BuildShaderConstants for each of `frames`, with bit for bit the same
// results: frame i's in frame_params[i] and in depth_params from
// i * kHardwareConventionCount on (the spans are as long as that asks).
// Exact constants are computed for kShaderConstantsLanes frames at once, in
// the lanes of DoubleDouble4 (a few times as fast as one by one: this is
// most of a batch's frame work); a caller that splits its frames among
// threads keeps the groups whole by splitting at multiples of it.
inline constexpr std::size_t kShaderConstantsLanes = 4;
void BuildShaderConstants(std::span<const Frame> frames, ConstantsModel model, std::span<f32::FrameParams> frame_params,
                          std::span<f32::DepthParams> depth_params);

}  // namespace depthbench
