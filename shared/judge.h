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
// degenerate, outside, and one unused, so that a slot is a whole number of
// 64-bit words.
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
DB_CONST_UINT(DB_JUDGE_FRAME_DRAWS, 16u)
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
               // pipelines' floats, 1 the texels
  uint record_distances;  // 1: natural samples also go to their camera-distance band
  uint cells;
  uint depth_slots;       // slices of the reference buffers, and the depth slots' accumulators
  uint accumulators;      // cells, or cells + depth_slots when the encodings' errors are recorded too
  uint exact_production;  // 1: depths are produced exactly (ProductionModel::kExact), 0: in float32
  uint seed_lo;           // the sampler's seed (the sample pass's)
  uint seed_hi;
  uint row_order;  // where the judge's order of accumulators starts in the run's layout
};
