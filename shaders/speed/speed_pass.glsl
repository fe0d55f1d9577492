// The timed full-screen pass of `depthbench speed`: one invocation per
// pixel, reading a real depth image of the format under test with
// texelFetch (a depth format is bound as a sampled depth image, a linear
// format as a colour image), rebuilding the world position with the
// variant's formula as the accuracy pass does (uv from the pixel centre,
// the ray-based variants' rays interpolated per pixel), and writing one
// value per pixel so that nothing can be optimized away.
//
// TAPS (specialization constant 0) reconstructions per pixel: 1 is the
// memory-bound regime; more is the ALU-bound regime an SSAO kernel makes,
// each tap reading a neighbour on a 4-wide grid of step 2 pixels (tap 0 is
// the pixel itself), clamped to the image.
// The depth convention is specialization constant 1, as an engine compiles
// its shaders for the one convention it uses: the formulas' convention
// branch folds away as it would there.
// The including shader defines RECONSTRUCT as its variant's
// <variant>_world_position function from shared/variants/.
layout(local_size_x = 16, local_size_y = 16) in;
layout(constant_id = 0) const uint TAPS = 1u;
layout(constant_id = 1) const uint CONVENTION = 0u;

// std140 lays FrameParams and DepthParams out as std430 does (vec4, mat4
// and groups of four uints only: see shared/params.h).
layout(std140, set = 0, binding = 0) uniform Constants {
  FrameParams frame;
  DepthParams depth_constants;
};
layout(set = 0, binding = 1) uniform sampler2D depth_image;
layout(std430, set = 0, binding = 2) writeonly buffer Results { float results[]; };
layout(push_constant) uniform Size {
  uint width;
  uint height;
} size;

void main() {
  uint x = gl_GlobalInvocationID.x;
  uint y = gl_GlobalInvocationID.y;
  if (x >= size.width || y >= size.height) {
    return;
  }
  DepthParams depth = depth_constants;
  depth.convention = CONVENTION;
  ivec2 last = ivec2(int(size.width) - 1, int(size.height) - 1);
  vec3 sum = vec3(0.0f);
  for (uint tap = 0u; tap < TAPS; ++tap) {
    ivec2 pixel = min(ivec2(int(x + (tap & 3u) * 2u), int(y + (tap >> 2u) * 2u)), last);
    float stored = texelFetch(depth_image, pixel, 0).x;
    vec2 uv = uv_from_pixel(float(pixel.x), float(pixel.y), frame.resolution);
    sum = sum + RECONSTRUCT(frame, depth, uv, stored);
  }
  results[y * size.width + x] = sum.x + sum.y + sum.z;
}
