// The device judge's layout (bench/device_judge/, shaders/judge/judge.comp):
// what the judge shader and the host agree on. The host checks these
// numbers against the accumulator's (bench/pipeline/stats.h, bands.h) at
// compile time.
// No include guard: see compat.h.

// Bins of one metric: underflow, the kept quarter octaves, overflow.
DB_CONST_UINT(DB_JUDGE_BINS, 258u)
// The metrics an accumulator holds, three at most. A cell's: total, arith
// (the shader's part), absolute. A depth slot's (its encoding's, whatever
// reads it): storage, production.
DB_CONST_UINT(DB_JUDGE_METRICS, 3u)
// Slots of one cell, as CellAccumulator numbers them: camera-distance
// bands, then joint (ratio x depth) bands, then coverage bands.
DB_CONST_UINT(DB_JUDGE_DISTANCE_SLOTS, 5u)
DB_CONST_UINT(DB_JUDGE_JOINT_SLOTS, 110u)
DB_CONST_UINT(DB_JUDGE_SLOTS, 123u)
// Counts of one slot after its bins: NaN, Inf, stored non-finite,
// degenerate, outside, and undrawn (the raster form's texels the
// rasterizer left as cleared): a slot is a whole number of 64-bit words.
DB_CONST_UINT(DB_JUDGE_COUNTS, 6u)
DB_CONST_UINT(DB_JUDGE_SLOT_UINTS, 780u)  // DB_JUDGE_METRICS * DB_JUDGE_BINS + DB_JUDGE_COUNTS

// The reference pass's inputs: doubles per frame (near, far, largest eye
// depth, eye depths of interest), words per frame (far/near band, the
// linear mapping's far plane, A and B of each hardware convention), and the
// bands it computes (bench/pipeline/bands.h).
DB_CONST_UINT(DB_JUDGE_FRAME_DEPTHS, 5u)
DB_CONST_UINT(DB_JUDGE_HARDWARE_CONVENTIONS, 8u)
DB_CONST_UINT(DB_JUDGE_FRAME_WORDS, 18u)  // 2 + 2 * DB_JUDGE_HARDWARE_CONVENTIONS
DB_CONST_UINT(DB_JUDGE_DEPTH_BANDS, 10u)
// The sample pass's inputs: doubles per frame (shared/draw.h's DrawFrame).
DB_CONST_UINT(DB_JUDGE_FRAME_DRAWS, 18u)
// What a depth slot's format stores (bench/pipeline/cells.h's DepthInput).
DB_CONST_UINT(DB_JUDGE_STORES_WINDOW_DEPTH, 0u)
DB_CONST_UINT(DB_JUDGE_STORES_LINEAR, 1u)
DB_CONST_UINT(DB_JUDGE_STORES_VIEW_Z, 2u)
// How a depth slot's format keeps a value (bench/pipeline/cells.h's TexelKind).
DB_CONST_UINT(DB_JUDGE_TEXEL_UNORM, 0u)
DB_CONST_UINT(DB_JUDGE_TEXEL_FLOAT32, 1u)
DB_CONST_UINT(DB_JUDGE_TEXEL_FLOAT16, 2u)
DB_CONST_UINT(DB_JUDGE_INFINITE_RATIO_BAND, 10u)

// Reference status (bench/pipeline/reference.h) as the judge reads it.
DB_CONST_UINT(DB_JUDGE_STATUS_JUDGED, 0u)
DB_CONST_UINT(DB_JUDGE_STATUS_DEGENERATE, 1u)
DB_CONST_UINT(DB_JUDGE_STATUS_OUTSIDE, 2u)
DB_CONST_UINT(DB_JUDGE_STATUS_UNDRAWN, 3u)

// How the batch's depths were produced (bench/pipeline/batch.h's
// ProductionModel): in float32 by the storage pass, exactly by the host,
// or by the backend's rasterizer (the raster form: its texels, and per
// texel whether it was drawn, come from the backend).
DB_CONST_UINT(DB_JUDGE_PRODUCTION_FLOAT32, 0u)
DB_CONST_UINT(DB_JUDGE_PRODUCTION_EXACT, 1u)
DB_CONST_UINT(DB_JUDGE_PRODUCTION_RASTER, 2u)

// The 32-bit words the host and the passes exchange. Each is built and
// read here alone, so that C++ and GLSL cannot disagree about a field's
// place: a word is packed by db_*_word and its fields read back by the
// functions that follow it. Packing keeps each field to its own bits, so
// that no field can spill into the next; the values given must fit them
// (each word states its fields' ranges; device_judge.cc checks at compile
// time those the host's types bound).

// A depth slot's encoding (bindings.glsl's Layout, written by the host):
//   bits 0-3    what the format stores (DB_JUDGE_STORES_*);
//   bits 4-7    the convention's DB_CONVENTION_* bits;
//   bits 8-11   the hardware convention's index, below
//               DB_JUDGE_HARDWARE_CONVENTIONS (0 for a non-hardware one),
//               which picks the frame's A and B;
//   bit 12      1 for a hardware convention whose far plane is at infinity;
//   bits 16-31  the pipeline that produces the slot's floats.
DB_FN uint db_encoding_word(uint stores, uint convention, uint hardware, bool infinite_far, uint pipeline) {
  return (stores & 0xfu) | ((convention & 0xfu) << 4u) | ((hardware & 0xfu) << 8u) | ((infinite_far ? 1u : 0u) << 12u) |
         (pipeline << 16u);
}
DB_FN uint db_encoding_stores(uint word) { return word & 0xfu; }
DB_FN uint db_encoding_convention(uint word) { return (word >> 4u) & 0xfu; }
DB_FN uint db_encoding_hardware(uint word) { return (word >> 8u) & 0xfu; }
DB_FN bool db_encoding_infinite_far(uint word) { return ((word >> 12u) & 1u) != 0u; }
DB_FN uint db_encoding_pipeline(uint word) { return word >> 16u; }

// A depth slot's texel (bindings.glsl's Layout, written by the host):
//   bits 0-7    how the format keeps a value (DB_JUDGE_TEXEL_*);
//   bits 8-31   a unorm format's bits (16 or 24), 0 for the others.
DB_FN uint db_texel_word(uint kind, uint unorm_bits) { return (kind & 0xffu) | (unorm_bits << 8u); }
DB_FN uint db_texel_kind(uint word) { return word & 0xffu; }
DB_FN uint db_texel_unorm_bits(uint word) { return word >> 8u; }

// A sample's coverage word (bindings.glsl's Coverage: uploaded by the host,
// or written by the sample pass):
//   bits 0-7    the coverage kind (bands.h's Coverage, 0 for a natural
//               sample; a targeted pick's kind picks its coverage band);
//   bits 8-31   the depth pick (sampler.h's DepthPick): 0 for an eye depth,
//               else which stored value (1-4) the sample takes.
DB_FN uint db_coverage_word(uint kind, uint pick) { return (kind & 0xffu) | (pick << 8u); }
DB_FN uint db_coverage_kind(uint word) { return word & 0xffu; }
DB_FN uint db_coverage_pick(uint word) { return word >> 8u; }

// A (depth slot, sample)'s reference info (bindings.glsl's ReferenceInfo:
// written by the reference pass, read by the judge and by the host):
//   bits 0-7    the joint (ratio x depth) band, below DB_JUDGE_JOINT_SLOTS;
//   bits 8-15   the reference status (DB_JUDGE_STATUS_*);
//   bit 16      1 when the depth the stored value denotes is holdable (its
//               squared extent is a finite float), so that the arithmetic
//               error is recorded.
DB_FN uint db_reference_info_word(uint joint_band, uint status, bool stored_holdable) {
  return (joint_band & 0xffu) | ((status & 0xffu) << 8u) | ((stored_holdable ? 1u : 0u) << 16u);
}
DB_FN uint db_reference_info_joint_band(uint word) { return word & 0xffu; }
DB_FN uint db_reference_info_status(uint word) { return (word >> 8u) & 0xffu; }
DB_FN bool db_reference_info_stored_holdable(uint word) { return ((word >> 16u) & 1u) != 0u; }

// Accumulators: one per cell of the run, then (where the dispatch records
// them) one per depth slot; workgroup row y judges accumulator y.
// Push constants of one dispatch of either pass. Sample i of the batch (index
// first_index + i) is element lead + i of the positions' slices, which are
// `slice_length` elements long; it lies in frame (i + first_offset) / 64.
struct JudgePass {
  uint count;
  uint lead;
  uint slice_length;
  uint first_offset;
  uint first_index_lo;
  uint first_index_hi;
  uint phase;  // judge: 0 bins, counts, maxima and their candidates, 1 the index of each maximum; storage: 0 the
               // pipelines' floats made and stored, 1 the uploaded floats stored
  uint record_distances;  // 1: natural samples also go to their camera-distance band
  uint cells;
  uint depth_slots;       // slices of the reference buffers, and the depth slots' accumulators
  uint accumulators;      // cells, or cells + depth_slots when the encodings' errors are recorded too
  uint production;        // DB_JUDGE_PRODUCTION_*
  uint seed_lo;           // the sampler's seed (the sample pass's)
  uint seed_hi;
  uint row_order;  // where the judge's order of accumulators starts in the run's layout
  // Where each cell's convention slot within a frame's DepthParams lies in
  // the run's layout (the fused pass's: shaders/judge/fused.comp).
  uint cell_conventions;
};
