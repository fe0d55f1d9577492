// The raster pipeline on the host: the geometry drawn for each sample, the
// exact point that geometry puts under the pixel (the truth a raster run is
// judged against), and a model of what a rasterizer makes of it, so that a
// raster backend's depths and interpolated rays can be compared with the
// host's, and so that the CPU backend has a raster form.
//
// The geometry of a sample (shared/params.h RasterSample):
//   - a triangle facing the camera, in the plane of view depth d through
//     the sample's point, whose inscribed circle (radius kTriangleInradius
//     pixels) is centred on the pixel's centre; its corners are rounded to
//     float32, as a vertex buffer holds them. It produces the depth.
//   - a light volume: an axis-aligned cube of half edge d / 4 centred on the
//     point (float32), drawn back faces only by the bounding-volume ray
//     variant (Pettineo 2009).
// The rounding moves the triangle's plane off the sampled point by about
// 2^-24 of the distance from the world origin, so the truth is not the
// sampled point but the exact intersection of the pixel's ray with the
// plane of the float corners.
//
// The model of a rasterizer (what the Vulkan specification leaves exact):
// vertices transformed in float32 by the uploaded matrices, the divide by w
// and the viewport's depth transform in float32 (0.5 * z + 0.5 for GL-style
// clip depth), then the value at the pixel centre interpolated exactly
// from the vertices (depth linearly in screen space, other attributes
// perspective-correctly) and rounded once to float32. A device's
// interpolator is allowed to differ: the specification fixes neither the
// sub-pixel precision of vertex positions nor the arithmetic of the
// interpolation, only that it is close to the exact plane. How close
// lavapipe is, is measured (tests/raster_model_test.cc).
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include <glm/glm.hpp>

#include "bench/numerics/formulas.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/sampler.h"

namespace depthbench {

// The triangle's inscribed radius, in pixels: the pixel centre lies this far
// inside every edge, far more than the rasterizer's sub-pixel snapping
// (1/256 pixel on lavapipe) or float32 rounding of the corners can move an
// edge, so coverage never depends on them; and small enough that the
// triangle leaves the render target by at most 2 pixels (its corners lie
// at twice the radius), which every rasterizer's guard band takes without
// clipping.
inline constexpr double kTriangleInradius = 0.75;

// The geometry of one sample and the eye depth of the point it puts under
// the pixel centre. Nothing to draw (all zero, no depth) for samples that
// do not pick an eye depth, and where float32 world coordinates cannot
// hold the triangle (a camera far from the origin looking at a point close
// to it): the corners' rounding would then move an edge past the pixel
// centre, so what the device covers could not be predicted.
struct RasterGeometry {
  f32::RasterSample sample{};
  std::optional<double> rendered_depth;  // eye depth of the pixel's point on the triangle
};
RasterGeometry MakeRasterGeometry(const Frame& frame, const PixelSample& sample);

// How the depths a real rasterizer produced for one encoding compare with
// this model's (the texel codes the batch would hold), over the samples
// that have geometry. A raster backend counts them (Backend::raster_agreement)
// and the sweep keeps them in its results.
struct RasterAgreement {
  Encoding encoding{};
  std::uint64_t texels = 0;             // samples with geometry
  std::uint64_t differing = 0;          // drawn, and whose texel bits differ from the model's code
  std::uint64_t uncovered = 0;          // that the device left uncovered (nothing written): not judged
  std::uint32_t max_code_distance = 0;  // the largest |device code - model code| over drawn texels (ulps for floats)

  // Adds the counts of another part of the same sweep (a shard).
  void Merge(const RasterAgreement& other);
  friend bool operator==(const RasterAgreement&, const RasterAgreement&) = default;
};

// The value the raster pipeline's first pass stores for a sample, before
// the format's rounding: window depth for hardware formats, eye depth / far
// for linear ones, view z for view-z ones. `frame` and `depth` are the
// shaders' float32 constants (depth: the cell's convention; ignored for
// linear and view-z formats); NaN when the sample has nothing to draw.
// Like a backend, it sees only the float32 constants.
float RasterPipelineFloat(Encoding encoding, const f32::FrameParams& frame_params,
                          const f32::DepthParams& depth, std::uint32_t pixel_x, std::uint32_t pixel_y,
                          const f32::RasterSample& geometry);

// RasterPipelineFloat for one sample in many encodings. What they share is
// computed once: the triangle's screen corners and the pixel's barycentrics
// (the same for every view-projection matrix whose x, y and w rows are the
// same bits, as the conventions' are), and its interpolated view z. The
// values are RasterPipelineFloat's, bit for bit.
class RasterTexelModel {
 public:
  RasterTexelModel(const f32::FrameParams& frame_params, std::uint32_t pixel_x, std::uint32_t pixel_y,
                   const f32::RasterSample& geometry);
  float Value(Encoding encoding, const f32::DepthParams& depth);

  struct ScreenVertex {
    glm::dvec2 screen;  // on the frame's screen, in pixels (the float NDC taken exactly)
    double w;           // clip w
  };

 private:
  const f32::FrameParams& frame_params_;
  std::uint32_t pixel_x_, pixel_y_;
  std::array<glm::vec4, 3> corners_;
  bool has_geometry_;
  // The screen, for the matrix whose x, y and w rows it was made with.
  std::optional<glm::mat4> screen_of_;
  std::array<ScreenVertex, 3> vertices_{};
  std::optional<glm::dvec3> barycentrics_;
  std::optional<double> view_z_;  // interpolated at the pixel (perspective-correct), for that screen
};

// The FrameParams a raster pass's fragment hands the variant at pixel
// (x, y): its screen attributes replaced by the values the rasterizer
// interpolates there (origin = the value, du = dv = 0, so that the shared
// variant code reads exactly it):
//   - from a full-screen triangle (uv (0,0), (2,0), (0,2)) whose vertices
//     carry the attributes computed in float32 as a vertex shader would;
//   - the light volume's view-space surface position, from the back face
//     of the sample's cube that covers the pixel (the frame's own surface
//     values when the sample has no volume).
f32::FrameParams RasterFrameParams(const f32::FrameParams& frame_params,
                                   const f32::DepthParams& standard_depth, std::uint32_t pixel_x,
                                   std::uint32_t pixel_y, const f32::RasterSample& geometry);

}  // namespace depthbench
