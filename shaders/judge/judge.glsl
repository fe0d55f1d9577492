// The device judge's rows (bench/device_judge/device_judge.h), shared by
// the two programs that judge cells: judge.comp, which reads the positions
// a reconstruction pass left in device memory, and fused.comp, which
// reconstructs them in the same invocation. The includer defines
// cell_position_bits and includes shared/compat.h and shared/judge.h
// first. judge.comp's opening comment says what a row does.
// The workgroup's shape, which the host chooses for the device
// (device_judge.cc's JudgeGroups): its invocations, the consecutive
// samples of one accumulator it judges, and the entries of its table of
// bins (a power of two).
layout(local_size_x_id = 0) in;
layout(constant_id = 1) const uint kGroupSamples = 16384u;
layout(constant_id = 2) const uint kTableEntries = 4096u;
layout(constant_id = 3) const bool kUseTable = true;  // false: bins go straight to the device's counters
// Candidates listed per accumulator (device_judge.h's DeviceJudgeTuning).
layout(constant_id = 4) const uint kCandidatesPerRow = 4096u;

#include "bindings.glsl"

// What the reconstruction pass leaves where it wrote nothing (the Vulkan
// backend's kUnwrittenBits).
const uint kUnwrittenBits = 0x7fa00badu;
const int kLowestOctave[3] = int[3](-56, -56, -48);  // stats.h's kLowestOctave of total, arith, absolute
const uint kNoSlot = 0xffffffffu;

// The workgroup's table of bins, one word per entry: 0 while empty, else
// the bin's place in the accumulator plus one (slot * DB_JUDGE_SLOT_UINTS
// + metric * DB_JUDGE_BINS + bin + 1, below 2^17) over 15 bits that count
// this workgroup's samples in it (at most one per sample: the host keeps
// kGroupSamples below 2^15).
const uint kTableProbes = 16u;
const uint kCountBits = 15u;
shared uint table[kTableEntries];
// The high word of the largest square this workgroup has met in each
// (slot, metric) of its row: a square whose high word is below it cannot
// raise or meet the row's running maximum, so it skips the device's copy
// (device_judge.cc's ChooseJudgeGroups counts these words in the shared
// memory it allows the table).
shared uint group_high[DB_JUDGE_SLOTS * DB_JUDGE_METRICS];

// One more sample in bin `key` of accumulator k.
void add_to_bin(uint k, uint key) {
  if (!kUseTable) {
    atomicAdd(counts[k * DB_JUDGE_SLOTS * DB_JUDGE_SLOT_UINTS + key], 1u);
    return;
  }
  uint tag = key + 1u;
  uint home = (key * 2654435761u) >> (32u - uint(findMSB(kTableEntries)));  // Knuth's multiplicative hash
  for (uint probe = 0u; probe < kTableProbes; ++probe) {
    uint entry = (home + probe) & (kTableEntries - 1u);
    uint held = table[entry];
    if (held == 0u) {
      held = atomicCompSwap(table[entry], 0u, (tag << kCountBits) | 1u);
      if (held == 0u) {
        return;
      }
    }
    if ((held >> kCountBits) == tag) {
      atomicAdd(table[entry], 1u);
      return;
    }
  }
  atomicAdd(counts[k * DB_JUDGE_SLOTS * DB_JUDGE_SLOT_UINTS + key], 1u);
}

// The dense bin of a square (stats.h's DenseBinsOfSquares): 0 for zero,
// subnormal or NaN, else floor(4 log2 sqrt(q)) from q's exponent and a
// comparison of its significand with sqrt(2)'s, shifted and clamped.
uint dense_bin(double q, int lowest_octave) {
  if (!(q >= 2.2250738585072014e-308lf)) {  // 2^-1022
    return 0u;
  }
  uvec2 words = unpackDouble2x32(q);  // x: low word, y: high word
  int exponent = int(words.y >> 20u) - 1023;
  uint fraction_high = words.y & 0xfffffu;
  bool upper = fraction_high > 0x6a09eu || (fraction_high == 0x6a09eu && words.x >= 0x667f3bcdu);
  int slot = 2 * exponent + (upper ? 1 : 0) - lowest_octave * 4 + 1;
  return uint(clamp(slot, 0, int(DB_JUDGE_BINS) - 1));
}

uint64_t sample_index(uint i) {
  uint64_t first = (uint64_t(pass.first_index_hi) << 32) | uint64_t(pass.first_index_lo);
  return first + uint64_t(i);
}

// One value of metric m in slot `slot` of accumulator k for sample i: a
// cell's 0 total, 1 arith, 2 absolute; a depth slot's 0 storage, 1
// production.
void record(uint k, uint slot, uint m, double square, uint i) {
  uint at = k * DB_JUDGE_SLOTS + slot;
  uint64_t bits = doubleBitsToUint64(square);
  uint max_at = at * DB_JUDGE_METRICS + m;
  // As the host's `square > max_square`: zero never sets a maximum, nor
  // does NaN (an encoding's square can be one, and its bits would order
  // above every number's).
  bool candidate = square > 0.0lf;
  if (pass.phase == 0u) {
    add_to_bin(k, slot * DB_JUDGE_SLOT_UINTS + m * DB_JUDGE_BINS + dense_bin(square, kLowestOctave[m]));
    // Each filter lets through every square that raises or meets the
    // running maximum: the group's high word and the device's maximum only
    // grow, so a stale read of either is never above it. The square that
    // ends as the maximum, at its first index, passes both, and is listed.
    uint high = uint(bits >> 32u);
    uint group_at = slot * DB_JUDGE_METRICS + m;
    if (candidate && high >= group_high[group_at]) {
      atomicMax(group_high[group_at], high);
      if (bits >= maxima[max_at] && bits >= atomicMax(maxima[max_at], bits)) {
        uint listed = atomicAdd(candidate_counts[k], 1u);
        if (listed < kCandidatesPerRow) {
          candidates[k * kCandidatesPerRow + listed] = uvec4(max_at, i, unpackUint2x32(bits));
        }
      }
    }
  } else if (candidate && bits == maxima[max_at]) {
    atomicMin(maxima[pass.accumulators * DB_JUDGE_SLOTS * DB_JUDGE_METRICS + max_at], sample_index(i));
  }
}

// Phase 1 over accumulator k's candidates, where they all were listed:
// true when it was.
bool search_candidates(uint k) {
  uint listed = candidate_counts[k];
  if (listed > kCandidatesPerRow) {
    return false;
  }
  uint stride = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  for (uint j = gl_WorkGroupID.x * gl_WorkGroupSize.x + gl_LocalInvocationID.x; j < listed; j += stride) {
    uvec4 c = candidates[k * kCandidatesPerRow + j];
    if (packUint2x32(c.zw) == maxima[c.x]) {
      atomicMin(maxima[pass.accumulators * DB_JUDGE_SLOTS * DB_JUDGE_METRICS + c.x], sample_index(c.y));
    }
  }
  return true;
}

// A sample the judge does not measure: counted by cause.
void count(uint k, uint slot, uint status, bool holdable, bool is_nan, uint64_t index) {
  if (pass.phase != 0u) {
    return;
  }
  uint at = k * DB_JUDGE_SLOTS + slot;
  uint base = at * DB_JUDGE_SLOT_UINTS + DB_JUDGE_METRICS * DB_JUDGE_BINS;
  if (status == DB_JUDGE_STATUS_DEGENERATE) {
    atomicAdd(counts[base + 3u], 1u);
  } else if (status == DB_JUDGE_STATUS_OUTSIDE) {
    atomicAdd(counts[base + 4u], 1u);
  } else if (status == DB_JUDGE_STATUS_UNDRAWN) {
    atomicAdd(counts[base + 5u], 1u);
  } else if (!holdable) {
    atomicAdd(counts[base + 2u], 1u);
  } else {
    atomicAdd(counts[base + (is_nan ? 0u : 1u)], 1u);
    atomicMin(first_nonfinite[at], index);
  }
}

// The slot of a sample's figures: its joint band, or its coverage band if
// it is a targeted pick (kind > 0).
uint band_slot(uint info, uint kind) {
  return kind == 0u ? DB_JUDGE_DISTANCE_SLOTS + db_reference_info_joint_band(info)
                    : DB_JUDGE_DISTANCE_SLOTS + DB_JUDGE_JOINT_SLOTS + kind - 1u;
}

// The storage and production errors of depth slot s's sample i (judge.cc's
// RecordEncodingErrors): in its band, for samples the reference judges.
void record_encoding(uint k, uint s, uint i) {
  uint r = s * pass.count + i;
  uint info = reference_info[r];
  if (db_reference_info_status(info) != DB_JUDGE_STATUS_JUDGED) {
    return;
  }
  uint slot_samples = pass.depth_slots * pass.count;
  uint band = band_slot(info, db_coverage_kind(coverage[i]));
  record(k, band, 0u, reference[3u * slot_samples + r], i);
  record(k, band, 1u, reference[4u * slot_samples + r], i);
}

// What sample i of cell accumulator k reads.
struct Loaded {
  uvec3 p;
  uvec4 frame;
  dvec3 ray;
  double true_depth;
  double denoted_depth;
  double inverse_distance_sq;
  uint info;
  uint kind;
};

// The bits of cell k's position of sample i: defined by the program that
// includes this file (judge.comp reads them where the reconstruction pass
// left them, fused.comp reconstructs them).
uvec3 cell_position_bits(uint k, uint i);

Loaded load_sample(uint k, uint i) {
  Loaded l;
  uint depth_slot = run_layout[k];
  l.p = cell_position_bits(k, i);
  l.frame = frames[frame_of(i)];
  l.ray = dvec3(rays[i], rays[pass.count + i], rays[2u * pass.count + i]);
  uint r = depth_slot * pass.count + i;
  uint slots_count = pass.depth_slots * pass.count;
  l.true_depth = reference[r];
  l.denoted_depth = reference[slots_count + r];
  l.inverse_distance_sq = reference[2u * slots_count + r];
  l.info = reference_info[r];
  l.kind = db_coverage_kind(coverage[i]);
  return l;
}

// Sample i of cell accumulator k, from what it read.
void judge_loaded(uint k, uint i, Loaded l) {
  uvec3 p = l.p;
  if (p.x == kUnwrittenBits || p.y == kUnwrittenBits || p.z == kUnwrittenBits) {
    if (pass.phase == 0u) {
      atomicAdd(unwritten[k], 1u);
    }
    return;
  }
  dvec3 camera = dvec3(float_value(l.frame.x), float_value(l.frame.y), float_value(l.frame.z));
  dvec3 ray = l.ray;
  uint info = l.info;

  // judge.cc's Errors, operation for operation.
  precise dvec3 q = dvec3(float_value(p.x), float_value(p.y), float_value(p.z)) - camera;
  precise dvec3 t = q - l.true_depth * ray;
  precise dvec3 a = q - l.denoted_depth * ray;
  precise double absolute_sq = t.x * t.x + t.y * t.y + t.z * t.z;
  precise double total_sq = absolute_sq * l.inverse_distance_sq;
  precise double arith_sq = (a.x * a.x + a.y * a.y + a.z * a.z) * l.inverse_distance_sq;

  uint kind = l.kind;
  bool natural = kind == 0u;
  uint band = band_slot(info, kind);
  uint distance = natural && pass.record_distances != 0u ? l.frame.w : kNoSlot;
  uint status = db_reference_info_status(info);
  bool holdable = db_reference_info_stored_holdable(info);
  bool finite = absolute_sq < 1.0lf / 0.0lf;  // false for NaN
  if (status == DB_JUDGE_STATUS_JUDGED && finite) {
    record(k, band, 0u, total_sq, i);
    record(k, band, 2u, absolute_sq, i);
    if (distance != kNoSlot) {
      record(k, distance, 0u, total_sq, i);
    }
    if (holdable) {
      record(k, band, 1u, arith_sq, i);
      if (distance != kNoSlot) {
        record(k, distance, 1u, arith_sq, i);
      }
    }
  } else {
    uint64_t index = sample_index(i);
    bool is_nan = absolute_sq != absolute_sq;
    count(k, band, status, holdable, is_nan, index);
    if (distance != kNoSlot) {
      count(k, distance, status, holdable, is_nan, index);
    }
  }
}

void main() {
  uint k = run_layout[pass.row_order + gl_WorkGroupID.y];
  uint lane = gl_LocalInvocationID.x;
  if (pass.phase == 1u && search_candidates(k)) {
    return;
  }
  bool tabling = kUseTable && pass.phase == 0u;  // phase 0 through the table
  if (pass.phase == 0u) {
    if (tabling) {
      for (uint entry = lane; entry < kTableEntries; entry += gl_WorkGroupSize.x) {
        table[entry] = 0u;
      }
    }
    for (uint entry = lane; entry < DB_JUDGE_SLOTS * DB_JUDGE_METRICS; entry += gl_WorkGroupSize.x) {
      group_high[entry] = 0u;
    }
    barrier();
  }
  uint first = gl_WorkGroupID.x * kGroupSamples;
  uint end = min(first + kGroupSamples, pass.count);
  // A depth slot's own row, or a cell's: each sample's reads first, then
  // what the judge makes of them (3% faster on an H200 than one function
  // reading as it went).
  uint stride = gl_WorkGroupSize.x;
  if (k >= pass.cells) {
    for (uint i = first + lane; i < end; i += stride) {
      record_encoding(k, k - pass.cells, i);
    }
  } else {
    for (uint i = first + lane; i < end; i += stride) {
      judge_loaded(k, i, load_sample(k, i));
    }
  }
  if (tabling) {
    barrier();
    for (uint entry = lane; entry < kTableEntries; entry += gl_WorkGroupSize.x) {
      uint held = table[entry];
      if (held != 0u) {
        uint key = (held >> kCountBits) - 1u;
        atomicAdd(counts[k * DB_JUDGE_SLOTS * DB_JUDGE_SLOT_UINTS + key], held & ((1u << kCountBits) - 1u));
      }
    }
  }
}
