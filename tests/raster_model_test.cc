// The host's side of the raster pipeline (bench/pipeline/raster_model.h):
// the geometry drawn for a sample puts the sampled point under its pixel,
// and the host's model of a rasterizer produces the depth and the rays the
// compute form produces, up to the few float32 roundings by which the two
// pipelines' arithmetic differs. One pixel off is about 1e-3 of a ray, so
// every bound below (a few ulps) tells a right pixel, face and matrix from
// a wrong one.
#include <bit>
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "bench/pipeline/batch.h"
#include "bench/pipeline/encode.h"
#include "bench/pipeline/raster_model.h"
#include "bench/pipeline/shader_constants.h"

namespace depthbench {
namespace {

// |a - b| in units of the ulp of the larger magnitude (2^-23 relative).
double Ulps(const glm::vec3& a, const glm::vec3& b) {
  const double scale = std::max(glm::length(glm::dvec3(a)), glm::length(glm::dvec3(b)));
  return glm::length(glm::dvec3(a) - glm::dvec3(b)) / (scale * 0x1p-23);
}

struct Drawn {
  Frame frame;
  PixelSample sample;
  RasterGeometry geometry;
  f32::FrameParams frame_params;
  std::array<f32::DepthParams, kHardwareConventionCount> depth_params;
};

// Samples of a domain at far/near 1e4 with the camera `distance` from the
// origin, with their geometry and the exact constants.
std::vector<Drawn> DrawSamples(double distance, int count) {
  Domain domain;
  domain.ratio = {1e4, 1e4};
  domain.infinite_far = true;
  domain.camera_distance = {distance, distance};
  const Sampler sampler(11, domain);
  std::vector<Drawn> out;
  for (int i = 0; i < count; ++i) {
    Drawn d;
    d.frame = sampler.FrameAt(static_cast<std::uint64_t>(i) / kSamplesPerFrame);
    d.sample = sampler.SampleAt(static_cast<std::uint64_t>(i), d.frame);
    d.geometry = MakeRasterGeometry(d.frame, d.sample);
    BuildShaderConstants(d.frame, ConstantsModel::kExact, d.frame_params, d.depth_params);
    out.push_back(d);
  }
  return out;
}

TEST(RasterModelTest, TheTrianglePutsTheSampledPointUnderItsPixel) {
  int drawn = 0;
  for (const Drawn& d : DrawSamples(0.0, 4000)) {
    if (d.sample.pick != DepthPick::kEyeDepth) {
      EXPECT_FALSE(d.geometry.rendered_depth) << "a stored-value pick has no point to draw";
      continue;
    }
    ASSERT_TRUE(d.geometry.rendered_depth) << "sample " << d.sample.index;
    ++drawn;
    // The corners' float32 rounding moves the plane by a few 2^-24 of
    // their distance from the origin, here about the eye depth.
    EXPECT_LT(std::fabs(*d.geometry.rendered_depth / d.sample.eye_depth - 1.0), 1e-6) << "sample " << d.sample.index;
    EXPECT_NE(*d.geometry.rendered_depth, d.sample.eye_depth) << "the truth is the float plane's, not the sample's";
    EXPECT_FLOAT_EQ(d.geometry.sample.volume.w, static_cast<float>(d.sample.eye_depth / 4.0));
  }
  EXPECT_GT(drawn, 3000);
}

TEST(RasterModelTest, TheTriangleTurnsByTheGoldenRatioFromSampleToSample) {
  // Sample i's first corner lies at angle frac(i * 0.618...) of a turn
  // around the pixel centre (x right, y down, in pixels), the others a
  // third of a turn on. The corners' float32 rounding, 2^-24 of their
  // distance from the origin (here the eye depth, a few thousand times
  // the triangle's size on a frame thousands of pixels wide), and the
  // float32 view matrix move them by up to a few 1e-4 rad; 2e-3 rad is
  // allowed. A corner in the wrong octant or mirrored in its quarter is
  // off by far more for all but a few angles.
  int checked = 0;
  for (const Drawn& d : DrawSamples(0.0, 2000)) {
    if (!d.geometry.rendered_depth) continue;
    const f32::RasterSample& g = d.geometry.sample;
    std::array<glm::dvec3, 3> view;
    for (int k = 0; k < 3; ++k) {
      view[k] = glm::dvec3(glm::vec3(d.frame_params.world_view * std::array{g.triangle0, g.triangle1, g.triangle2}[k]));
    }
    const glm::dvec3 centre = (view[0] + view[1] + view[2]) / 3.0;
    const double turn = std::fmod(static_cast<double>(d.sample.index) * 0.6180339887498948482, 1.0);
    // The view units of a pixel at the triangle's depth (a frame's pixels
    // need not be square).
    const double tan_y = d.frame.tan_half_fov_y, depth = -centre.z;
    const double pixel_x = 2.0 * d.frame.aspect * tan_y * depth / d.frame.width;
    const double pixel_y = 2.0 * tan_y * depth / d.frame.height;
    for (int k = 0; k < 3; ++k) {
      // In pixels, with the screen's y down (view y is up).
      const double angle =
          std::atan2((centre.y - view[k].y) / pixel_y, (view[k].x - centre.x) / pixel_x) / (2.0 * std::numbers::pi);
      double off = std::fmod(angle - turn - k / 3.0, 1.0);
      off -= std::round(off);
      EXPECT_LT(std::fabs(off), 2e-3 / (2.0 * std::numbers::pi)) << "sample " << d.sample.index << " corner " << k;
    }
    ++checked;
  }
  EXPECT_GT(checked, 1500);
}

TEST(RasterModelTest, NothingIsDrawnWhereFloatCornersCannotHoldTheTriangle) {
  // At 1e6 from the origin float32 coordinates are 0.0625 apart: a
  // triangle a pixel wide at eye depth below about 10 cannot be held.
  int near_drawn = 0, near_total = 0, far_drawn = 0, far_total = 0;
  for (const Drawn& d : DrawSamples(1e6, 4000)) {
    if (d.sample.pick != DepthPick::kEyeDepth) continue;
    if (d.sample.eye_depth < 0.5) {
      ++near_total;
      near_drawn += d.geometry.rendered_depth ? 1 : 0;
    } else if (d.sample.eye_depth > 1e3) {
      ++far_total;
      far_drawn += d.geometry.rendered_depth ? 1 : 0;
    }
  }
  ASSERT_GT(near_total, 50);
  ASSERT_GT(far_total, 50);
  EXPECT_EQ(near_drawn, 0);
  EXPECT_EQ(far_drawn, far_total);
}

TEST(RasterModelTest, RasterizedDepthIsTheComputeFormsWithinUlps) {
  // Both are float32 pipelines from the same exact constants: the compute
  // form from A and B and the eye depth, the raster form through the view-
  // projection matrix and the divide of clip z by clip w. A handful of
  // roundings separate them; a y flip, a wrong matrix or a wrong pixel
  // would be thousands of ulps off.
  const std::array<Encoding, 4> encodings = {{{Convention::kStandard, Format::kD32Sfloat},
                                              {Convention::kReversed, Format::kD32Sfloat},
                                              {Convention::kReversedGl, Format::kD32Sfloat},
                                              {Convention::kLinear, Format::kR32Sfloat}}};
  for (const Encoding encoding : encodings) {
    double worst = 0.0;
    for (const Drawn& d : DrawSamples(0.0, 2000)) {
      if (!d.geometry.rendered_depth) continue;
      const bool hardware = Info(encoding.format).stores == DepthInput::kHardware;
      const auto slot = hardware ? static_cast<std::size_t>(encoding.convention) : 0;
      const float raster = RasterPipelineFloat(encoding, d.frame_params, d.depth_params[slot], d.sample.x, d.sample.y,
                                               d.geometry.sample);
      const float compute = PipelineFloat(encoding, ProductionModel::kFloat32, d.frame, *d.geometry.rendered_depth);
      // Where window depth crowds near a value (1 for standard Z, 0.5 for
      // GL-style clip depth) both pipelines have that value's absolute
      // resolution, so they are compared there in units of 2^-24;
      // elsewhere (reversed Z with clip depth [0, 1], where the value goes
      // to 0 at the far plane, and linear depth) by the eye depths the two
      // values denote, relatively, in units of 2^-24.
      const std::uint32_t bits = Info(encoding.convention).bits;
      const bool absolute =
          hardware && ((bits & f32::DB_CONVENTION_REVERSED) == 0u || (bits & f32::DB_CONVENTION_CLIP_MINUS_ONE) != 0u);
      double difference = 0.0;
      if (absolute) {
        difference = std::fabs(static_cast<double>(raster) - compute) / 0x1p-24;
      } else {
        const double r = DecodeEyeDepth(encoding, ProductionModel::kFloat32, d.frame, raster).hi();
        const double c = DecodeEyeDepth(encoding, ProductionModel::kFloat32, d.frame, compute).hi();
        difference = std::fabs(r / c - 1.0) / 0x1p-24;
      }
      worst = std::max(worst, difference);
    }
    EXPECT_LT(worst, 16.0) << Info(encoding.convention).name << " " << Info(encoding.format).name;
    EXPECT_GT(worst, 0.0) << "the two pipelines round differently somewhere";
  }
}

TEST(RasterModelTest, OneModelPerSampleGivesEveryEncodingsValue) {
  // A batch keeps one RasterTexelModel per sample for all its pipelines,
  // which reuses the screen corners across matrices whose x, y and w rows
  // agree. Asked in any order, among them a matrix whose x row differs
  // (the screen must then be made again), it must give what a model made
  // for each value alone gives, bit for bit.
  std::vector<Encoding> encodings = MakeRunLayout(AllCells()).encodings;
  std::vector<Encoding> twice(encodings.rbegin(), encodings.rend());
  encodings.insert(encodings.end(), twice.begin(), twice.end());
  int compared = 0, moved = 0;
  for (const Drawn& d : DrawSamples(0.0, 500)) {
    if (!d.geometry.rendered_depth) continue;
    f32::DepthParams shifted = d.depth_params[0];
    // x_ndc + 0.25: an eighth of the screen to the right.
    for (int column = 0; column < 4; ++column) {
      shifted.view_projection[column][0] += 0.25f * shifted.view_projection[column][3];
    }
    RasterTexelModel model(d.frame_params, d.sample.x, d.sample.y, d.geometry.sample);
    for (std::size_t e = 0; e < encodings.size(); ++e) {
      const Encoding encoding = encodings[e];
      const bool hardware = Info(encoding.format).stores == DepthInput::kHardware;
      const f32::DepthParams& depth =
          e % 5 == 4 ? shifted : d.depth_params[hardware ? DepthSlot(encoding.convention) : 0];
      const float alone =
          RasterPipelineFloat(encoding, d.frame_params, depth, d.sample.x, d.sample.y, d.geometry.sample);
      const float shared = model.Value(encoding, depth);
      EXPECT_EQ(std::bit_cast<std::uint32_t>(shared), std::bit_cast<std::uint32_t>(alone))
          << "sample " << d.sample.index << ", " << Info(encoding.convention).name << " " << Info(encoding.format).name
          << (e % 5 == 4 ? ", shifted matrix" : "");
      ++compared;
      moved += &depth == &shifted && std::isnan(alone) ? 1 : 0;
    }
  }
  EXPECT_GT(compared, 10000);
  EXPECT_GT(moved, 1000) << "the shifted matrix moves the triangle off its pixel";
}

TEST(RasterModelTest, InterpolatedRaysAreTheComputeFormsWithinUlps) {
  double frustum_worst = 0.0, volume_worst = 0.0;
  for (const Drawn& d : DrawSamples(0.0, 2000)) {
    if (!d.geometry.rendered_depth) continue;
    const f32::FrameParams& f = d.frame_params;
    const f32::FrameParams raster =
        RasterFrameParams(f, d.depth_params[0], d.sample.x, d.sample.y, d.geometry.sample);
    EXPECT_EQ(raster.frustum_ray_du, glm::vec4(0.0f));
    const glm::vec2 uv = f32::uv_from_pixel(static_cast<float>(d.sample.x), static_cast<float>(d.sample.y), f.resolution);
    // The frustum ray: the compute form's plane of the same corner values.
    const glm::vec3 compute = f32::interpolate_screen_attribute(f.frustum_ray_origin, f.frustum_ray_du,
                                                                f.frustum_ray_dv, uv);
    frustum_worst = std::max(frustum_worst, Ulps(glm::vec3(raster.frustum_ray_origin), compute));
    // The light volume's surface, scaled to the far plane, is the same
    // pixel's far-plane ray in view space as the compute form's plane.
    const auto to_far = [&](const glm::vec3& surface) { return surface * (f.camera_position.w / -surface.z); };
    const glm::vec3 plane = f32::interpolate_screen_attribute(f.volume_position_origin, f.volume_position_du,
                                                              f.volume_position_dv, uv);
    volume_worst = std::max(volume_worst, Ulps(to_far(glm::vec3(raster.volume_position_origin)), to_far(plane)));
  }
  // The interpolation itself is exact in the model: what is left are the
  // vertex values' roundings (a couple of ulps of the ray).
  EXPECT_LT(frustum_worst, 4.0);
  // The cube's corners and their view transform round at the scale of
  // the eye depth, the scaling to far adds a division: a few ulps more.
  EXPECT_LT(volume_worst, 32.0);
  EXPECT_GT(frustum_worst, 0.0);
}

}  // namespace
}  // namespace depthbench
