#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
// The judge on the device (bench/device_judge/device_judge.h): compares the
// positions a reconstruction pass left in device memory with the reference
// (reference.comp, run just before) and counts the errors into histograms
// that stay on the device. It records exactly what the host judge
// (bench/pipeline/judge.cc) records for the total, shader (arith) and
// absolute errors, sample by sample: the same float64 operations in the
// same order, none fused (`precise`), and the same bins read from the bits
// of each square. A dispatch's workgroup row y judges the y-th cell of the
// run, one sample per invocation; rows past the cells record the storage
// and production errors of each depth slot (shared/judge.h).
//
// A workgroup judges kGroupSamples consecutive samples of one
// accumulator. In phase 0 it adds their bins into a table in shared memory
// first (open addressing on the bin's place in the accumulator), and only
// the table's totals into the device's counters at its end: neighbouring
// samples fall into few bins, and global atomic additions on one address
// wait for each other. A bin the table has no room for goes to the
// device's counter at once. Integer additions in any order give the same
// counts.
//
// Two phases over the same batch: phase 0 adds bins and counts and raises
// each slot's largest square (a 64-bit atomic maximum on its bits: squares
// are never negative, so their bits order as they do); phase 1 finds, for
// each slot whose largest square this batch reached, the smallest index
// that reached it, as the host keeps the first sample on a tie. A sample
// whose square equals the final maximum found the running maximum no
// larger when it raised it, so phase 0 lists every sample that raised or
// met it (a few dozen per slot) as a candidate, and phase 1 reads the
// candidates instead of judging every sample again; an accumulator with
// more candidates than its list holds is judged again whole.
#include "../../shared/compat.h"
#include "../../shared/judge.h"

#include "judge.glsl"

uvec3 cell_position_bits(uint k, uint i) {
  uint base = k * 3u * pass.slice_length + pass.lead + i;
  return uvec3(position_bits[base], position_bits[base + pass.slice_length],
               position_bits[base + 2u * pass.slice_length]);
}
