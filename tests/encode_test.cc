// The encoder rounds exactly as the formats and an ideal pipeline do.
#include <bit>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "bench/numerics/formulas_mpfr.h"
#include "bench/pipeline/encode.h"

namespace depthbench {
namespace {

// The float nearest to code / (2^bits - 1), by exact comparison of
// neighbours (|g * scale - code| is exact in double): the slow definition.
float ExactUnormFetch(std::uint32_t code, int bits) {
  const double scale = std::ldexp(1.0, bits) - 1.0;
  float best = static_cast<float>(code / scale);
  auto error = [&](float g) { return std::fabs(static_cast<double>(g) * scale - code); };
  for (float g : {std::nextafter(best, -INFINITY), std::nextafter(best, INFINITY)}) {
    if (error(g) < error(best) || (error(g) == error(best) && (std::bit_cast<std::uint32_t>(g) & 1u) == 0)) best = g;
  }
  return best;
}

TEST(EncodeTest, UnormFetchIsCorrectlyRoundedForEveryCode) {
  for (std::uint32_t c = 0; c <= 0xffffu; ++c) ASSERT_EQ(FetchTexel(Format::kD16Unorm, c), ExactUnormFetch(c, 16)) << c;
  for (std::uint32_t c = 0; c <= 0xffffffu; ++c) {
    ASSERT_EQ(FetchTexel(Format::kX8D24Unorm, c), ExactUnormFetch(c, 24)) << c;
  }
}

TEST(EncodeTest, UnormConversionRoundsToNearestEven) {
  EXPECT_EQ(FloatToUnorm(0.0f, 16), 0u);
  EXPECT_EQ(FloatToUnorm(1.0f, 16), 65535u);
  EXPECT_EQ(FloatToUnorm(1.5f, 16), 65535u);  // clamped
  EXPECT_EQ(FloatToUnorm(-0.5f, 24), 0u);
  // 0.5 * 65535 = 32767.5: a tie, to the even code 32768.
  EXPECT_EQ(FloatToUnorm(0.5f, 16), 32768u);
  // 0.5 * (2^24 - 1) = 8388607.5: a tie, to the even code 8388608.
  EXPECT_EQ(FloatToUnorm(0.5f, 24), 8388608u);
}

// StoreFloats runs four values at a time where it can, one at a time in
// the tail; both must round (ties to even), clamp (NaN to 0) and fetch
// alike. Each value is stored once in a block of four (the wide path) and
// once alone (the one-value path).
TEST(EncodeTest, UnormStoresAgreeFourAtATimeAndOneByOne) {
  std::vector<float> values = {0.0f,
                               -0.0f,
                               1.0f,
                               0.5f,
                               -0.5f,
                               1.5f,
                               NAN,
                               INFINITY,
                               -INFINITY,
                               std::nextafter(1.0f, 0.0f),
                               std::nextafter(0.0f, 1.0f),
                               1e-30f};
  for (int bits : {16, 24}) {
    const double scale = std::ldexp(1.0, bits) - 1.0;
    // Codes plus one half (ties, where the float holds them), and neighbours.
    for (std::uint32_t c = 0; c < (1u << bits); c += 4099) {
      const auto tie = static_cast<float>((c + 0.5) / scale);
      values.insert(values.end(), {tie, std::nextafter(tie, 0.0f), std::nextafter(tie, 2.0f)});
    }
  }
  while (values.size() % 4 != 0) values.push_back(0.25f);
  for (Format format : {Format::kD16Unorm, Format::kX8D24Unorm}) {
    std::vector<std::uint32_t> codes(values.size());
    std::vector<float> fetched(values.size());
    StoreFloats(format, values.data(), values.size(), codes.data(), fetched.data());
    for (std::size_t i = 0; i < values.size(); ++i) {
      const StoredDepth one = StoreFloat(format, values[i]);
      ASSERT_EQ(codes[i], one.code) << values[i];
      ASSERT_EQ(std::bit_cast<std::uint32_t>(fetched[i]), std::bit_cast<std::uint32_t>(one.fetched)) << values[i];
      ASSERT_EQ(one.fetched, FetchTexel(format, one.code)) << values[i];
    }
  }
  EXPECT_EQ(StoreFloat(Format::kD16Unorm, NAN).code, 0u);
}

TEST(EncodeTest, HalfConversionRoundTripsAndTiesToEven) {
  for (std::uint32_t h = 0; h < 0x10000u; ++h) {
    const auto half = static_cast<std::uint16_t>(h);
    const float f = HalfToFloat(half);
    if (std::isnan(f)) continue;
    ASSERT_EQ(FloatToHalf(f), half) << h;
  }
  // 1 + 2^-11 lies halfway between 1 and 1 + 2^-10: to even (1.0).
  EXPECT_EQ(FloatToHalf(1.0f + std::ldexp(1.0f, -11)), 0x3c00);
  // 1 + 3 * 2^-11 lies halfway between 1 + 2^-10 and 1 + 2^-9: to even.
  EXPECT_EQ(FloatToHalf(1.0f + 3.0f * std::ldexp(1.0f, -11)), 0x3c02);
  EXPECT_EQ(FloatToHalf(std::ldexp(1.0f, -25)), 0x0000);  // half the smallest subnormal: to even (0)
  EXPECT_EQ(FloatToHalf(std::ldexp(1.5f, -25)), 0x0001);  // above the tie
  EXPECT_EQ(FloatToHalf(65520.0f), 0x7c00);               // rounds to infinity
  EXPECT_EQ(FloatToHalf(65519.0f), 0x7bff);
}

Frame TestFrame(double near, double far) {
  Frame f;
  f.near = near;
  f.far = far;
  f.depth_limit = std::isinf(far) ? near * Domain::kInfiniteDepthSpan : far;
  return f;
}

// The float the pipeline must produce for eye depth z, from MPFR.
float ExactPipelineFloat(Encoding e, const Frame& frame, double z) {
  const std::uint32_t bits = Info(e.convention).bits;
  const double far = frame.finite() ? frame.far : 0.0;
  mp::real window = mp::window_depth_from_eye_depth(frame.near, far, bits, z);
  if ((bits & 4u) == 0u) return window.ToFloat();
  float ndc = (window * mp::real(2.0) - mp::real(1.0)).ToFloat();
  return static_cast<float>(0.5 * static_cast<double>(ndc) + 0.5);
}

// The distance between two texels that the raster form reports: unorm
// codes apart, or floats stepped over, whichever binade or sign the two
// lie in (a raw difference of float bits reads billions across zero).
TEST(EncodeTest, CodeDistanceCountsValuesBetweenTexels) {
  EXPECT_EQ(CodeDistance(Format::kX8D24Unorm, 5, 2), 3u);
  EXPECT_EQ(CodeDistance(Format::kD16Unorm, 0, 65535), 65535u);
  const auto bits = [](float f) { return std::bit_cast<std::uint32_t>(f); };
  EXPECT_EQ(CodeDistance(Format::kD32Sfloat, bits(1.0f), bits(std::nextafter(1.0f, 2.0f))), 1u);
  EXPECT_EQ(CodeDistance(Format::kD32Sfloat, bits(2.0f), bits(std::nextafter(2.0f, 0.0f))), 1u);  // a binade's edge
  const float tiny = std::numeric_limits<float>::denorm_min();
  EXPECT_EQ(CodeDistance(Format::kR32Sfloat, bits(tiny), bits(-tiny)), 2u);  // through zero
  EXPECT_EQ(CodeDistance(Format::kR32Sfloat, bits(0.0f), bits(-0.0f)), 0u);
  EXPECT_EQ(CodeDistance(Format::kR32Sfloat, bits(-1.0f), bits(1.0f)), 2u * bits(1.0f));
  EXPECT_EQ(CodeDistance(Format::kR16Sfloat, 0x3C00u, 0xBC00u), 2u * 0x3C00u);  // half 1.0 and -1.0
  EXPECT_EQ(CodeDistance(Format::kD32Sfloat, bits(-std::numeric_limits<float>::max()),
                         bits(std::numeric_limits<float>::max())),
            2u * bits(std::numeric_limits<float>::max()));
}

TEST(EncodeTest, PipelineFloatIsCorrectlyRoundedEverywhere) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (Convention c :
       {Convention::kStandard, Convention::kReversed, Convention::kStandardInf, Convention::kReversedInf,
        Convention::kStandardGl, Convention::kReversedGl, Convention::kStandardInfGl, Convention::kReversedInfGl}) {
    const Encoding e{c, Format::kD32Sfloat};
    for (int k = 0; k < 3000; ++k) {
      const double near = std::exp(std::log(1e-6) + unit(rng) * std::log(1e7));
      const double ratio = std::exp(std::log(10.0) + unit(rng) * std::log(1e11));  // up to 1e12
      const bool infinite = (Info(c).bits & 2u) != 0u;
      const Frame frame = TestFrame(near, infinite ? INFINITY : near * ratio);
      // Depths spread log-uniformly, and bunched against the far plane.
      double z =
          k % 3 == 0 ? near * ratio * (1.0 - std::ldexp(unit(rng), -20)) : near * std::exp(unit(rng) * std::log(ratio));
      ASSERT_EQ(PipelineFloat(e, ProductionModel::kExact, frame, z), ExactPipelineFloat(e, frame, z))
          << Info(c).name << " near " << near << " ratio " << ratio << " z " << z;
    }
  }
}

TEST(EncodeTest, ExactTiesAreSettledByMpfr) {
  // Standard Z with an infinite far plane: d = 1 - n/z. With z = 1 and
  // n = 1/2 - 2^-25, d = 1/2 + 2^-25 exactly: the midpoint between the
  // floats 1/2 and 1/2 + 2^-24. Ties go to even: 1/2.
  const Frame frame = TestFrame(0.5 - std::ldexp(1.0, -25), INFINITY);
  const EncodeFallbacks before = EncodeFallbackCounts();
  EXPECT_EQ(PipelineFloat({Convention::kStandardInf, Format::kD32Sfloat}, ProductionModel::kExact, frame, 1.0), 0.5f);
  const EncodeFallbacks after = EncodeFallbackCounts();
  EXPECT_EQ(after.ties, before.ties + 1);
  EXPECT_EQ(after.mpfr, before.mpfr + 1);
  // Just beyond the tie the answer moves up.
  const Frame nearer = TestFrame(std::nextafter(0.5 - std::ldexp(1.0, -25), 0.0), INFINITY);
  EXPECT_EQ(PipelineFloat({Convention::kStandardInf, Format::kD32Sfloat}, ProductionModel::kExact, nearer, 1.0),
            0.5f + std::ldexp(1.0f, -24));
}

TEST(EncodeTest, EdgeValuesAreTheFormatsExtremeCodes) {
  const Frame frame = TestFrame(0.1, 1000.0);
  const Encoding d24{Convention::kStandard, Format::kX8D24Unorm};
  EXPECT_EQ(EncodeEdge(d24, frame, DepthPick::kStoredZero).code, 0u);
  EXPECT_EQ(EncodeEdge(d24, frame, DepthPick::kStoredOne).code, 0xffffffu);
  EXPECT_EQ(EncodeEdge(d24, frame, DepthPick::kStoredBeforeOne).code, 0xfffffeu);
  EXPECT_EQ(EncodeEdge(d24, frame, DepthPick::kStoredAfterZero).code, 1u);
  const Encoding d32{Convention::kReversed, Format::kD32Sfloat};
  EXPECT_EQ(EncodeEdge(d32, frame, DepthPick::kStoredBeforeOne).fetched, std::nextafter(1.0f, 0.0f));
  EXPECT_EQ(EncodeEdge(d32, frame, DepthPick::kStoredAfterZero).fetched, std::numeric_limits<float>::denorm_min());
  const Encoding half{Convention::kLinear, Format::kR16Sfloat};
  EXPECT_EQ(EncodeEdge(half, frame, DepthPick::kStoredBeforeOne).fetched, 1.0f - std::ldexp(1.0f, -11));
}

TEST(EncodeTest, StoredPlanesDecodeToThePlanes) {
  const Frame finite = TestFrame(0.25, 4000.0);
  const Frame infinite = TestFrame(0.25, INFINITY);
  for (Format f : {Format::kD16Unorm, Format::kX8D24Unorm, Format::kD32Sfloat}) {
    EXPECT_EQ(DecodeEyeDepth({Convention::kStandard, f}, ProductionModel::kExact, finite,
                             EncodeEdge({Convention::kStandard, f}, finite, DepthPick::kStoredZero).fetched)
                  .hi(),
              0.25);
    EXPECT_EQ(DecodeEyeDepth({Convention::kStandard, f}, ProductionModel::kExact, finite,
                             EncodeEdge({Convention::kStandard, f}, finite, DepthPick::kStoredOne).fetched)
                  .hi(),
              4000.0);
    EXPECT_EQ(DecodeEyeDepth({Convention::kReversed, f}, ProductionModel::kExact, finite,
                             EncodeEdge({Convention::kReversed, f}, finite, DepthPick::kStoredOne).fetched)
                  .hi(),
              0.25);
    EXPECT_EQ(DecodeEyeDepth({Convention::kReversed, f}, ProductionModel::kExact, finite,
                             EncodeEdge({Convention::kReversed, f}, finite, DepthPick::kStoredZero).fetched)
                  .hi(),
              4000.0);
    EXPECT_TRUE(
        std::isinf(DecodeEyeDepth({Convention::kStandardInf, f}, ProductionModel::kExact, infinite,
                                  EncodeEdge({Convention::kStandardInf, f}, infinite, DepthPick::kStoredOne).fetched)
                       .hi()));
    EXPECT_TRUE(
        std::isinf(DecodeEyeDepth({Convention::kReversedInf, f}, ProductionModel::kExact, infinite,
                                  EncodeEdge({Convention::kReversedInf, f}, infinite, DepthPick::kStoredZero).fetched)
                       .hi()));
  }
}

TEST(EncodeTest, LinearDepthUnderflowsInHalfFloatAtLargeRatios) {
  // z/far = 1e-8 is below half float's smallest subnormal (2^-24 = 6e-8):
  // the stored value is 0 and denotes the camera.
  const Frame frame = TestFrame(1.0, 1e8);
  const StoredDepth s = EncodeEyeDepth({Convention::kLinear, Format::kR16Sfloat}, ProductionModel::kExact, frame, 1.0);
  EXPECT_EQ(s.fetched, 0.0f);
  EXPECT_EQ(DecodeEyeDepth({Convention::kLinear, Format::kR16Sfloat}, ProductionModel::kExact, frame, s.fetched).hi(),
            0.0);
}

}  // namespace
}  // namespace depthbench
