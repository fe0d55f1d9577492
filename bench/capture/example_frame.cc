#include "bench/capture/example_frame.h"

#include <array>
#include <cmath>
#include <vector>

#include "bench/pipeline/raster_model.h"
#include "bench/pipeline/shader_constants.h"

namespace depthbench {
namespace {

using Triangle = std::array<glm::vec3, 3>;

// Two triangles of the rectangle with corners a, b, c and a + c - b.
void Quad(glm::vec3 a, glm::vec3 b, glm::vec3 c, std::vector<Triangle>& out) {
  out.push_back({a, b, c});
  out.push_back({a, c, a + c - b});
}

// The six faces of a box of half edge `half`, turned by `yaw` radians
// about the vertical through its centre.
void Box(glm::vec3 centre, float half, float yaw, std::vector<Triangle>& out) {
  const float c = std::cos(yaw), s = std::sin(yaw);
  const auto corner = [&](int x, int y, int z) {
    const float dx = x ? half : -half, dz = z ? half : -half;
    return centre + glm::vec3(c * dx + s * dz, y ? half : -half, -s * dx + c * dz);
  };
  Quad(corner(0, 0, 1), corner(1, 0, 1), corner(1, 1, 1), out);
  Quad(corner(0, 0, 0), corner(0, 1, 0), corner(1, 1, 0), out);
  Quad(corner(0, 0, 0), corner(0, 0, 1), corner(0, 1, 1), out);
  Quad(corner(1, 0, 0), corner(1, 1, 0), corner(1, 1, 1), out);
  Quad(corner(0, 1, 0), corner(0, 1, 1), corner(1, 1, 1), out);
  Quad(corner(0, 0, 0), corner(1, 0, 0), corner(1, 0, 1), out);
}

// The scene in world space (the camera's view space: it stands at the
// origin looking down -z, y up). Nothing faces the camera square on, so
// that no surface puts one eye depth under many pixels: the ground rolls
// a little across the view, the wall and the boxes are turned. Every
// corner lies between the near and far planes, so no triangle is clipped.
std::vector<Triangle> ExampleScene() {
  std::vector<Triangle> scene;
  const auto ground = [](float x, float z) { return glm::vec3(x, -1.7f + 0.01f * x, z); };
  Quad(ground(-300.0f, -0.5f), ground(300.0f, -0.5f), ground(300.0f, -900.0f), scene);
  Quad({-500.0f, -6.0f, -950.0f}, {500.0f, -6.0f, -550.0f}, {500.0f, 60.0f, -550.0f}, scene);
  struct Placed {
    glm::vec3 centre;
    float half, yaw;
  };
  for (const Placed& b : {Placed{{-1.5f, -1.2f, -4.0f}, 0.5f, 0.5f}, Placed{{2.0f, -0.7f, -9.0f}, 1.0f, 0.3f},
                          Placed{{-6.0f, 0.3f, -25.0f}, 2.0f, 0.7f}, Placed{{15.0f, 3.3f, -70.0f}, 5.0f, 0.2f},
                          Placed{{-40.0f, 8.3f, -200.0f}, 10.0f, 0.6f}, Placed{{80.0f, 28.3f, -420.0f}, 30.0f, 0.4f}}) {
    Box(b.centre, b.half, b.yaw, scene);
  }
  return scene;
}

}  // namespace

Frame ExampleCaptureFrame() {
  Frame f;
  f.fov_y_degrees = 60.0;
  f.width = 320;
  f.height = 180;
  f.aspect = 320.0 / 180.0;
  f.near = 0.1;
  f.far = 1000.0;
  CompleteFrame(f, std::nullopt);
  f.volume_depth = 10.0;
  return f;
}

glm::mat4 ExampleCaptureProjection() {
  return EngineProjectionMatrix(ExampleCaptureFrame(), kExampleCaptureEncoding.convention);
}

CaptureImage RenderExampleCapture() {
  const Frame frame = ExampleCaptureFrame();
  f32::FrameParams frame_params;
  std::array<f32::DepthParams, kHardwareConventionCount> depth_params;
  BuildShaderConstants(frame, ConstantsModel::kFloat32, frame_params, depth_params);
  const f32::DepthParams& depth = depth_params[static_cast<int>(kExampleCaptureEncoding.convention)];
  const std::vector<Triangle> scene = ExampleScene();

  CaptureImage image;
  image.width = frame.width;
  image.height = frame.height;
  image.channel = "Z";
  image.channel_type = "float";
  image.values.assign(static_cast<std::size_t>(frame.width) * frame.height, 0.0f);  // reversed Z's clear value
  for (const Triangle& t : scene) {
    f32::RasterSample geometry{};
    geometry.triangle0 = glm::vec4(t[0], 1.0f);
    geometry.triangle1 = glm::vec4(t[1], 1.0f);
    geometry.triangle2 = glm::vec4(t[2], 1.0f);
    for (std::uint32_t y = 0; y < frame.height; ++y) {
      for (std::uint32_t x = 0; x < frame.width; ++x) {
        const float d = RasterPipelineFloat(kExampleCaptureEncoding, frame_params, depth, x, y, geometry);
        float& stored = image.values[static_cast<std::size_t>(y) * frame.width + x];
        if (d > stored && d <= 1.0f) stored = d;  // reversed Z: the nearer surface has the greater depth
      }
    }
  }
  return image;
}

}  // namespace depthbench
