// Renders the example capture (example_frame.h) to the file named on the
// command line, and prints the projection matrix its scene file gives.
//   depthbench_example_capture bench/scenes/captured_frame.exr
#include <cstdio>

#include <fmt/format.h>

#include "bench/capture/example_frame.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUT.exr\n", argv[0]);
    return 2;
  }
  const depthbench::Status written = depthbench::WriteDepthExr(argv[1], depthbench::RenderExampleCapture());
  if (!written.ok()) {
    std::fprintf(stderr, "%s\n", written.message().c_str());
    return 1;
  }
  const glm::mat4 m = depthbench::ExampleCaptureProjection();
  std::string numbers;
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) numbers += fmt::format("{}{:.9g}", numbers.empty() ? "" : ", ", m[c][r]);
  }
  fmt::print("matrix = [{}]  # column-major\n", numbers);
  return 0;
}
