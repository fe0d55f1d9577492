// The example capture (bench/scenes/captured_frame.exr): a small synthetic
// scene rendered by the host's model of the raster pipeline
// (raster_model.h) into a reversed-Z float32 depth buffer, as a Vulkan
// engine would render it, so that a user without a frame of their own can
// try a capture, and the tests can hold the committed file to what the
// tool renders.
#pragma once

#include <glm/glm.hpp>

#include "bench/capture/depth_capture.h"
#include "bench/pipeline/sampler.h"

namespace depthbench {

// The example's frame: 320x180, vertical fov 60 degrees, near 0.1, far
// 1000, the camera at the origin looking down -z.
Frame ExampleCaptureFrame();
// Its convention and format: reversed Z in D32_SFLOAT, cleared to 0.
inline constexpr Encoding kExampleCaptureEncoding{Convention::kReversed, Format::kD32Sfloat};
// The projection matrix the scene file gives, column-major as GLM holds it.
glm::mat4 ExampleCaptureProjection();
// The depth buffer: a ground plane, a far wall and boxes from 4 to 500
// units away, each pixel the nearest surface's window depth as the host's
// raster model computes it; the sky keeps the clear value.
CaptureImage RenderExampleCapture();

}  // namespace depthbench
