#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
// The reference on the device (bench/device_judge/device_judge.h): for
// each depth slot and sample of a batch, the eye depth its stored value
// denotes and the one its pipeline's float denotes, each decoded in
// double-double, and from them the figures the judge reads: the true and
// the denoted depth, the inverse squared distance, the squared storage and
// production errors, the band and the status. It is the host's reference,
// operation for operation: encode.cc's DecodeValue and reference.cc's
// ReferenceOf, in the same order, unfused (`precise`), so that it equals
// the host's bit for bit (tests/device_judge_test.cc). Workgroup row y
// computes pipeline y's depth slots: the sample, the pipeline's float and
// what the frame's constants give are worked out once for them all.
#include "../../shared/compat.h"
#include "../../shared/params.h"
#include "../../shared/judge.h"

layout(local_size_x = 64) in;

#include "bindings.glsl"
#include "double_double.glsl"

// reference.cc's kPlaneSlack (2^-20) and kLargestFloatSquared.
const double kPlaneSlack = 9.5367431640625e-7lf;
const double kLargestFloatSquared = 3.4028234663852886e+38lf * 3.4028234663852886e+38lf;

// shared/depth_mapping.h's eye_depth_from_window_depth in double-double.
dvec2 eye_depth_from_window_depth(dvec2 near, dvec2 far, uint convention, dvec2 d, dvec2 one_minus_d) {
  bool reversed = (convention & DB_CONVENTION_REVERSED) != 0u;
  if ((convention & DB_CONVENTION_INFINITE) != 0u) {
    return reversed ? dd_div(near, d) : dd_div(near, one_minus_d);
  }
  if (reversed) {
    return dd_div(dd_mul(near, far), dd_add(dd_mul(near, one_minus_d), dd_mul(far, d)));
  }
  return dd_div(dd_mul(near, far), dd_add(dd_mul(far, one_minus_d), dd_mul(near, d)));
}

// The eye depth a float value denotes (encode.cc's DecodeValue), rounded
// to double: under the exact mapping, or under the float32 constants A, B
// (window depth) or far plane `a` (eye depth / far).
double decode(uint stores, uint convention, double near, double far, double a, double b, uint value_bits) {
  double value = float_value(value_bits);
  dvec2 v = dd(value);
  if (stores == DB_JUDGE_STORES_WINDOW_DEPTH) {
    if (pass.production == DB_JUDGE_PRODUCTION_EXACT) {
      return eye_depth_from_window_depth(dd(near), dd(far), convention, v, dd_sub(dd(1.0lf), v)).x;
    }
    dvec2 ndc = (convention & DB_CONVENTION_CLIP_MINUS_ONE) == 0u ? v : dd_sub(dd_mul(v, dd(2.0lf)), dd(1.0lf));
    return dd_div(dd(b), dd_sub(ndc, dd(a))).x;
  }
  if (stores == DB_JUDGE_STORES_LINEAR) {
    return dd_mul(v, dd(pass.production == DB_JUDGE_PRODUCTION_EXACT ? far : a)).x;
  }
  return -value;
}

// bands.h's DecadeBand: the powers of ten up to x, at most count - 1.
uint decade_band(double x, uint count) {
  uint band = 0u;
  double power = 10.0lf;
  for (uint k = 0u; k + 1u < count; ++k) {
    band += x >= power ? 1u : 0u;
    power *= 10.0lf;  // exact up to 1e22
  }
  return band;
}

void main() {
  uint i = gl_GlobalInvocationID.x;
  uint pipeline = gl_WorkGroupID.y;
  if (i >= pass.count) {
    return;
  }
  // What a pipeline's slots share (batch.cc's PipelineOfSlots groups them
  // by convention and by what the format stores): its first slot's
  // encoding serves them all.
  uint first_slot = pipeline_first_slot(pipeline);
  uint encoding = run_layout[pass.cells + first_slot];
  uint stores = db_encoding_stores(encoding);
  uint convention = db_encoding_convention(encoding);
  uint hardware = db_encoding_hardware(encoding);
  bool infinite_far = db_encoding_infinite_far(encoding);

  uint frame = frame_of(i);
  uint fd = frame * DB_JUDGE_FRAME_DEPTHS;
  double near = frame_depths[fd];
  double far = frame_depths[fd + 1u];
  double depth_limit = frame_depths[fd + 2u];
  double interest_min = frame_depths[fd + 3u];
  double interest_max = frame_depths[fd + 4u];
  uint fc = frame * DB_JUDGE_FRAME_WORDS;
  uint ratio_band = frame_constants[fc];
  double a = 0.0lf;
  double b = 0.0lf;
  if (stores == DB_JUDGE_STORES_WINDOW_DEPTH) {
    a = float_value(frame_constants[fc + 2u + 2u * hardware]);
    b = float_value(frame_constants[fc + 3u + 2u * hardware]);
  } else if (stores == DB_JUDGE_STORES_LINEAR) {
    a = float_value(frame_constants[fc + 1u]);
  }

  // The sample (reference.cc's SampleArrays::Set).
  bool eye = db_coverage_pick(coverage[i]) == 0u;
  double eye_depth = eye_depths[i];
  dvec3 ray = dvec3(rays[i], rays[pass.count + i], rays[2u * pass.count + i]);
  precise double ray_length_sq = ray.x * ray.x + ray.y * ray.y + ray.z * ray.z;
  precise double eye_inverse_distance_sq = 1.0lf / (eye_depth * eye_depth * ray_length_sq);
  // The pipeline's float denotes the same depth in each of its slots; a
  // stored-value pick reads its own stored value instead.
  double produced_hi =
      eye ? decode(stores, convention, near, far, a, b, pipeline_float_bits[pipeline * pass.count + i]) : 0.0lf;
  double limit = infinite_far ? 1.0lf / 0.0lf : depth_limit;
  double far_end = interest_max < limit ? interest_max : limit;
  double nearest = near < interest_min ? interest_min : near;
  precise double low = nearest * (1.0lf - kPlaneSlack);
  precise double high = far_end * (1.0lf + kPlaneSlack);
  uint slot_samples = pass.depth_slots * pass.count;

  for (uint slot = first_slot; slot != kNoDepthSlot; slot = pipeline_next_slot(slot)) {
    double denoted_hi = decode(stores, convention, near, far, a, b, texel_bits[slot * pass.slice_length + pass.lead + i]);

    // reference.cc's ReferenceOf.
    double t = eye ? eye_depth : denoted_hi;
    double produced = eye ? produced_hi : denoted_hi;
    double denoted_out = dd_finite(denoted_hi) ? denoted_hi : 1.7976931348623157e+308lf;
    precise double t_extent = t * t * ray_length_sq;
    bool holdable = t > 0.0lf && t_extent < kLargestFloatSquared;
    bool outside = t < low || t > high;
    uint status = holdable ? (outside ? DB_JUDGE_STATUS_OUTSIDE : DB_JUDGE_STATUS_JUDGED) : DB_JUDGE_STATUS_DEGENERATE;
    precise double s_extent = denoted_hi * denoted_hi * ray_length_sq;
    bool stored_holdable = denoted_hi > 0.0lf && s_extent < kLargestFloatSquared;
    precise double inverse = eye ? eye_inverse_distance_sq : 1.0lf / t_extent;
    double inverse_out = status == DB_JUDGE_STATUS_JUDGED ? inverse : 0.0lf;
    precise double scale = inverse_out * ray_length_sq;
    precise double storage = denoted_hi - produced;
    precise double production = produced - t;
    precise double storage_square = storage * storage * scale;
    precise double production_square = production * production * scale;
    // The raster form (batch.cc's ReferenceChunk and AdoptStoredDepths):
    // a sample the host had no geometry for has no point to judge; a texel
    // the rasterizer left as cleared holds no depth of the sample's.
    if (pass.production == DB_JUDGE_PRODUCTION_RASTER) {
      uint drawn = texel_status[slot * pass.slice_length + pass.lead + i];
      if (drawn == DB_RASTER_TEXEL_NO_GEOMETRY) {
        status = DB_JUDGE_STATUS_DEGENERATE;
        inverse_out = 0.0lf;
      } else if (drawn == DB_RASTER_TEXEL_UNDRAWN) {
        status = DB_JUDGE_STATUS_UNDRAWN;
      }
    }

    // Bands: a stored-value pick takes the decade of the depth it denotes.
    precise double depth_over_near = (eye ? eye_depth : t) / near;
    uint depth_band = decade_band(depth_over_near, DB_JUDGE_DEPTH_BANDS);
    uint joint = (infinite_far ? DB_JUDGE_INFINITE_RATIO_BAND : ratio_band) * DB_JUDGE_DEPTH_BANDS + depth_band;

    uint r = slot * pass.count + i;
    reference[r] = t;
    reference[slot_samples + r] = denoted_out;
    reference[2u * slot_samples + r] = inverse_out;
    reference[3u * slot_samples + r] = storage_square;
    reference[4u * slot_samples + r] = production_square;
    reference_info[r] = db_reference_info_word(joint, status, stored_holdable);
  }
}
