#include "bench/speed/depth_image.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "bench/pipeline/encode.h"
#include "bench/pipeline/shader_constants.h"

namespace depthbench {
namespace {

constexpr std::uint64_t kSceneSeed = 4;
// Larger images than this are no full-screen pass an engine renders.
constexpr std::uint32_t kMaxSide = 16384;

// A 32-bit integer hash (xorshift-multiply), for the per-pixel variation.
std::uint32_t Hash(std::uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

// Eye depth of pixel (x, y): 0.2% of the way (log scale) from the near to
// the far plane at the bottom row, 90% at the top, as a ground plane
// recedes towards the horizon, plus up to 5% of per-pixel noise.
double EyeDepthAt(const Frame& frame, std::uint32_t x, std::uint32_t y) {
  const double row = (static_cast<double>(y) + 0.5) / static_cast<double>(frame.height);
  const double noise = static_cast<double>(Hash(y * 65536u + x) >> 8) * 0x1p-24;
  const double t = 0.002 + 0.898 * (1.0 - row) + 0.05 * noise * (1.0 - row);
  return frame.near * std::pow(frame.far / frame.near, std::min(t, 0.95));
}

}  // namespace

std::vector<std::uint32_t> EncodeDepthRows(Encoding encoding, const Frame& frame, std::uint32_t first_row,
                                           std::uint32_t rows) {
  const std::uint32_t width = frame.width;
  const std::size_t n = static_cast<std::size_t>(width) * rows;
  std::vector<double> near(n, frame.near), far(n, frame.far), eye(n), a(n), b(n);
  for (std::uint32_t r = 0; r < rows; ++r) {
    for (std::uint32_t x = 0; x < width; ++x) eye[std::size_t{r} * width + x] = EyeDepthAt(frame, x, first_row + r);
  }
  // The pipeline's float, then the format's code (encode.h). The image is
  // only timed, so its depth is the exactly rounded one.
  std::vector<float> floats(n), fetched(n);
  std::vector<std::uint32_t> codes(n);
  PipelineFloats(encoding, ProductionModel::kExact, {near.data(), far.data(), a.data(), b.data()}, eye.data(), n,
                 floats.data());
  StoreFloats(encoding.format, floats.data(), n, codes.data(), fetched.data());
  return codes;
}

Frame SpeedFrame(Resolution resolution) {
  Domain domain;
  domain.fov_degrees = {60.0, 60.0};
  domain.aspect = {static_cast<double>(resolution.width) / resolution.height,
                   static_cast<double>(resolution.width) / resolution.height};
  domain.near = {0.1, 0.1};
  domain.ratio = {1e4, 1e4};
  domain.infinite_far = false;
  domain.camera_distance = {100.0, 100.0};
  domain.resolutions = {resolution};
  return Sampler(kSceneSeed, domain).FrameAt(0);
}

std::uint32_t DepthImage::Code(std::uint32_t x, std::uint32_t y) const {
  const std::size_t at = (static_cast<std::size_t>(y) * resolution.width + x) * texel_bytes;
  if (texel_bytes == 2) {
    std::uint16_t code;
    std::memcpy(&code, texels.data() + at, 2);
    return code;
  }
  std::uint32_t code;
  std::memcpy(&code, texels.data() + at, 4);
  return code;
}

Expected<DepthImage> MakeDepthImage(Encoding encoding, Resolution resolution, ThreadPool& pool) {
  const bool read = std::any_of(AllVariants().begin(), AllVariants().end(), [&](const VariantInfo& v) {
    return Reads(v.id, encoding.convention, encoding.format);
  });
  if (!read) {
    return InvalidArgument(fmt::format("no variant reads {} under the {} convention, so there is no pass to time",
                                       Info(encoding.format).name, Info(encoding.convention).name));
  }
  if (resolution.width == 0 || resolution.height == 0 || resolution.width > kMaxSide || resolution.height > kMaxSide) {
    return InvalidArgument(fmt::format("resolution {}x{} is outside 1x1 to {}x{}", resolution.width, resolution.height,
                                       kMaxSide, kMaxSide));
  }
  DepthImage image;
  image.encoding = encoding;
  image.resolution = resolution;
  image.texel_bytes = TexelBytes(encoding.format);
  image.frame = SpeedFrame(resolution);
  const hp::FrameParams exact = BuildFrameParams(image.frame);
  image.frame_params = RoundToFloat(exact);
  if (Info(encoding.convention).hardware) {
    image.depth_params = RoundToFloat(BuildDepthParams(image.frame, exact, encoding.convention));
  }

  const std::uint32_t width = resolution.width;
  image.texels.resize(static_cast<std::size_t>(width) * resolution.height * image.texel_bytes);
  pool.ParallelFor(
      resolution.height,
      [&](std::size_t begin, std::size_t end, unsigned) {
        const std::vector<std::uint32_t> codes = EncodeDepthRows(
            encoding, image.frame, static_cast<std::uint32_t>(begin), static_cast<std::uint32_t>(end - begin));
        std::uint8_t* out = image.texels.data() + begin * width * image.texel_bytes;
        for (std::size_t k = 0; k < codes.size(); ++k) {
          if (image.texel_bytes == 2) {
            const auto code = static_cast<std::uint16_t>(codes[k]);
            std::memcpy(out + k * 2, &code, 2);
          } else {
            std::memcpy(out + k * 4, &codes[k], 4);
          }
        }
      },
      16);
  return image;
}

}  // namespace depthbench
