#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
// The sampler on the device (bench/device_judge/device_judge.h): each
// invocation draws one sample of the batch from (seed, index) and its
// frame, as the host's sampler would (shared/draw.h, the same code in
// C++), and writes what the other passes read of it: its pixel, into the
// buffer the reconstruction pass reads, and for the storage and reference
// passes its eye depth, coverage kind and depth pick, and world-space ray.
// The host then uploads per frame what the draw needs, and nothing per
// sample. Invocation e covers element e of the pixels' slice: the lead and
// the padding get zeros, as the backend's own upload gives them.
#include "../../shared/compat.h"
#include "../../shared/params.h"
#include "../../shared/judge.h"
#include "../../shared/random.h"
#include "../../shared/draw.h"

layout(local_size_x = 64) in;

#define DB_SAMPLE_PASS
#include "bindings.glsl"

DrawFrame frame_draw(uint frame) {
  uint at = frame * DB_JUDGE_FRAME_DRAWS;
  DrawFrame f;
  f.eye_depth_min = frame_draws[at];
  f.eye_depth_max = frame_draws[at + 1u];
  f.log2_eye_depth_span = frame_draws[at + 2u];
  f.tan_x = frame_draws[at + 3u];
  f.tan_y = frame_draws[at + 4u];
  f.width = uint(frame_draws[at + 5u]);
  f.height = uint(frame_draws[at + 6u]);
  for (int column = 0; column < 3; ++column) {
    for (int row = 0; row < 3; ++row) {
      f.rotation[column][row] = frame_draws[at + 7u + uint(3 * column + row)];
    }
  }
  f.centre_x = frame_draws[at + 16u];
  f.centre_y = frame_draws[at + 17u];
  return f;
}

void main() {
  uint element = gl_GlobalInvocationID.x;
  if (element >= pass.slice_length) {
    return;
  }
  if (element < pass.lead || element >= pass.lead + pass.count) {
    pixel_bits[element] = 0u;
    return;
  }
  uint i = element - pass.lead;
  uint64_t index = packUint2x32(uvec2(pass.first_index_lo, pass.first_index_hi)) + uint64_t(i);
  uvec2 index_words = unpackUint2x32(index);
  uint state = random_state(pass.seed_lo, pass.seed_hi, index_words.x, index_words.y);
  uint frame = frame_of(i);
  DrawFrame f = frame_draw(frame);
  DrawnSample s = draw_sample(draw_units(state), f);
  pixel_bits[element] = s.x | (s.y << 16u);
  // A stored-value pick's eye depth is its frame's near plane (as the
  // host's SampleArrays hold it).
  eye_depths[i] = s.pick == 0u ? s.eye_depth : frame_depths[frame * DB_JUDGE_FRAME_DEPTHS];
  coverage[i] = db_coverage_word(s.coverage, s.pick);
  dvec3 ray = draw_pixel_ray(s.x, s.y, f);
  rays[i] = ray.x;
  rays[pass.count + i] = ray.y;
  rays[2u * pass.count + i] = ray.z;
}
