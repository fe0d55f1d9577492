// The device judge's storage buffers (bench/device_judge/device_judge.cc's
// Binding names them in this order), shared by its three passes: the
// storage (store.comp), the reference (reference.comp) and the judge
// (judge.comp). Sample i of a
// batch lies in frame (i + pass.first_offset) / 64.

// The run's layout: per cell, the depth slot it reads; then per depth slot
// its encoding word (what the format stores, the convention, the hardware
// convention, a far plane at infinity, the pipeline: shared/judge.h's
// db_encoding_*); then per depth slot its texel word (how the format keeps
// a value, a unorm's bits: db_texel_*); then per depth slot the next slot
// of its pipeline (kNoDepthSlot after the last); then per pipeline its first
// depth slot; then, from pass.row_order, the accumulator each workgroup
// row of the judge takes.
layout(std430, set = 0, binding = 0) readonly buffer Layout { uint run_layout[]; };
// Float32 values are read as their bits and made doubles by float_value:
// a device may flush float32 subnormals to zero in arithmetic and
// conversions (NVIDIA's does), and the host does not.
// The positions the reconstruction pass wrote (the Vulkan backend's).
layout(std430, set = 0, binding = 1) readonly buffer Positions { uint position_bits[]; };
// Per frame: the camera (float32 bits) and its camera-distance band.
layout(std430, set = 0, binding = 2) readonly buffer Frames { uvec4 frames[]; };
// What was drawn of each sample: uploaded, or written by the sample pass
// (sample.comp). The world-space ray at unit eye depth, x then y then z
// slices of `count` values; per sample its coverage kind and depth pick (0
// for an eye depth, else the stored value: sampler.h's DepthPick), packed
// by shared/judge.h's db_coverage_word.
#ifdef DB_SAMPLE_PASS
#define DB_DRAWN_ACCESS writeonly
#else
#define DB_DRAWN_ACCESS readonly
#endif
layout(std430, set = 0, binding = 3) DB_DRAWN_ACCESS buffer Rays { double rays[]; };
layout(std430, set = 0, binding = 4) DB_DRAWN_ACCESS buffer Coverage { uint coverage[]; };
// Per frame, five doubles: near, far (0 for an infinite far plane), the
// largest eye depth, and the eye depths of interest (lowest, highest).
layout(std430, set = 0, binding = 5) readonly buffer FrameDepths { double frame_depths[]; };
// Per frame, DB_JUDGE_FRAME_WORDS words: the far/near band, the linear
// mapping's float32 far plane, then A and B (float32) of each hardware
// convention.
layout(std430, set = 0, binding = 6) readonly buffer FrameConstants { uint frame_constants[]; };
// Per sample: the eye depth (the near plane for a stored-value pick).
layout(std430, set = 0, binding = 7) DB_DRAWN_ACCESS buffer EyeDepths { double eye_depths[]; };
// Per (pipeline, sample): the float32 the pipeline produced (uploaded, or
// written by the storage pass).
#ifdef DB_STORE_PASS
layout(std430, set = 0, binding = 8) buffer PipelineFloats { uint pipeline_float_bits[]; };
#else
layout(std430, set = 0, binding = 8) readonly buffer PipelineFloats { uint pipeline_float_bits[]; };
#endif
// Per (depth slot, sample): the value a texture fetch returns, in the
// backend's buffer, laid out as the positions are. The storage pass
// (store.comp) writes them; the others read them.
#ifdef DB_STORE_PASS
layout(std430, set = 0, binding = 9) writeonly buffer Texels { uint texel_bits[]; };
#else
layout(std430, set = 0, binding = 9) readonly buffer Texels { uint texel_bits[]; };
#endif

// Written by the reference pass, read by the judge. Per (depth slot,
// sample): true depth, denoted depth, inverse squared distance, squared
// relative storage and production errors, each a slice of slots * count
// values; and per (depth slot, sample) its joint band, status and whether
// the stored value's depth is holdable, packed by shared/judge.h's
// db_reference_info_word.
layout(std430, set = 0, binding = 10) buffer Reference { double reference[]; };
layout(std430, set = 0, binding = 11) buffer ReferenceInfo { uint reference_info[]; };

// The judge's counters. Per (accumulator, slot): DB_JUDGE_SLOT_UINTS
// counters (bins, then counts).
layout(std430, set = 0, binding = 12) buffer Counts { uint counts[]; };
// Per (accumulator, slot): the smallest index of a non-finite finding.
layout(std430, set = 0, binding = 13) buffer FirstNonFinite { uint64_t first_nonfinite[]; };
// Per (accumulator, slot, metric): this batch's largest square's bits;
// then, in the same order, the smallest index that reached it.
layout(std430, set = 0, binding = 14) buffer Maxima { uint64_t maxima[]; };
// Per cell: samples with a component the reconstruction never wrote.
layout(std430, set = 0, binding = 15) buffer Unwritten { uint unwritten[]; };
// Per (frame, depth slot, stored-value pick): the value a fetch returns
// (its bits, as the host stored it), at (frame * depth_slots + slot) * 4 +
// pick - 1.
layout(std430, set = 0, binding = 16) readonly buffer EdgeTexels { uint edge_texel_bits[]; };
// Per frame, DB_JUDGE_FRAME_DRAWS doubles: what the sample pass draws from
// (shared/draw.h's DrawFrame): the eye-depth range and its log2 span,
// tan_x, tan_y, width, height, the rotation's columns, and the lens's
// centre (x, y).
layout(std430, set = 0, binding = 17) readonly buffer FrameDraws { double frame_draws[]; };
// The pixels the reconstruction pass reads (the Vulkan backend's: x | y <<
// 16 at element lead + i), written by the sample pass.
#ifdef DB_SAMPLE_PASS
layout(std430, set = 0, binding = 18) writeonly buffer Pixels { uint pixel_bits[]; };
#endif

// The judge's candidates for the index of each maximum: per accumulator,
// judge.comp's kCandidatesPerRow entries (the maximum's place, the sample,
// its square's bits: low word, high word), and how many phase 0 listed
// (more than fit, when the row overflowed).
layout(std430, set = 0, binding = 19) buffer Candidates { uvec4 candidates[]; };
layout(std430, set = 0, binding = 20) buffer CandidateCounts { uint candidate_counts[]; };

#ifdef DB_FUSED_PASS
// What the fused pass reconstructs from (fused.comp): the Vulkan backend's
// per frame FrameParams, per (frame, hardware convention) DepthParams and
// per sample pixel (laid out as the backend has it), copied on the device
// at the start of each batch, so that the backend's buffers are free for
// the next batch's upload while this one is judged.
layout(std430, set = 0, binding = 21) readonly buffer FrameParamsBuffer { FrameParams frame_params[]; };
layout(std430, set = 0, binding = 22) readonly buffer DepthParamsBuffer { DepthParams depth_params[]; };
layout(std430, set = 0, binding = 23) readonly buffer FusedPixels { uint pixel_bits[]; };
#endif

// Per (depth slot, sample), laid out as the texels, where the backend's
// rasterizer produced them (DB_JUDGE_PRODUCTION_RASTER): whether the texel
// was drawn (shared/params.h's DB_RASTER_TEXEL_*). Unread otherwise.
layout(std430, set = 0, binding = 24) readonly buffer TexelStatus { uint texel_status[]; };

layout(push_constant) uniform Pass { JudgePass pass; };

uint frame_of(uint i) { return (i + pass.first_offset) / 64u; }

// The run's layout (Layout above): pipeline p's first depth slot, and the
// slot after s in its pipeline (kNoDepthSlot after the last).
const uint kNoDepthSlot = 0xffffffffu;
uint pipeline_first_slot(uint p) { return run_layout[pass.cells + 3u * pass.depth_slots + p]; }
uint pipeline_next_slot(uint s) { return run_layout[pass.cells + 2u * pass.depth_slots + s]; }

// The float32 with these bits, exactly, subnormals included.
double float_value(uint bits) {
  if ((bits & 0x7f800000u) != 0u) {
    return double(uintBitsToFloat(bits));  // normal, infinite or NaN
  }
  double magnitude = double(bits & 0x7fffffu) * 1.401298464324817e-45lf;  // 2^-149
  return (bits >> 31u) != 0u ? -magnitude : magnitude;
}
