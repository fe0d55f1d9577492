// Counter-based random numbers: each value is a pure function of
// (seed, sample index, stream), with no state carried from one sample to the
// next. The sampler uses it on the host; because it needs only 32-bit
// integer arithmetic it compiles unchanged as GLSL, so an on-device mode can
// draw the very same numbers on the GPU.
// No include guard: see compat.h.

// A bijective 32-bit mixer: two xor-shift/multiply rounds and a final
// xor-shift, with the multipliers of MurmurHash3's finalizer. Every input
// bit reaches every output bit.
DB_FN uint random_mix(uint x) {
  x = x ^ (x >> 16u);
  x = x * 0x85ebca6bu;
  x = x ^ (x >> 13u);
  x = x * 0xc2b2ae35u;
  x = x ^ (x >> 16u);
  return x;
}

// 32 random bits for (seed, index, stream). The seed and the index are
// 64-bit values split into low and high words; each word is absorbed by
// xor and a full mixing round, so inputs that differ in one word differ
// everywhere. The constant keeps an all-zero input from mapping to zero.
// The stream comes last, so the state before it (random_state) serves
// every stream of one sample: the host computes it once per sample.
DB_FN uint random_state(uint seed_lo, uint seed_hi, uint index_lo, uint index_hi) {
  uint h = random_mix(seed_lo ^ 0x9e3779b9u);
  h = random_mix(h ^ seed_hi);
  h = random_mix(h ^ index_hi);
  return random_mix(h ^ index_lo);
}
DB_FN uint random_bits_from_state(uint state, uint stream) { return random_mix(state ^ stream); }
DB_FN uint random_bits(uint seed_lo, uint seed_hi, uint index_lo, uint index_hi, uint stream) {
  return random_bits_from_state(random_state(seed_lo, seed_hi, index_lo, index_hi), stream);
}

// Uniform float in [0, 1) with 24 random bits: every value is exact.
DB_FN real random_unit(uint bits) { return real(bits >> 8u) * (1.0f / 16777216.0f); }
