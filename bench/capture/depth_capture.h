// A depth buffer saved from a real frame, as a domain: an OpenEXR file of
// one channel (what RenderDoc and engines' debug dumps save a depth
// texture as), read with Debian's OpenEXR library, its values decoded to
// eye depth through the frame's projection (projection_matrix.h); and the
// picture of a reconstruction's error over it, bits lost per pixel as a
// PNG with a colour scale (libpng).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bench/backends/backend.h"
#include "bench/base/status.h"
#include "bench/pipeline/captured.h"
#include "bench/pipeline/cells.h"
#include "bench/pipeline/domain.h"

namespace depthbench {

// One channel of an EXR image, converted to float32 (half and uint
// channels convert exactly), row by row from the top.
struct CaptureImage {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::string channel;
  std::string channel_type;  // "float", "half" or "uint", as the file stores it
  std::vector<float> values;
};

// `channel` empty: the file's only channel; a file with several must name
// one. Errors name the file and, where the file is readable, its channels.
Expected<CaptureImage> ReadDepthExr(const std::filesystem::path& path, const std::string& channel = "");
// One float channel named `image.channel`, ZIP-compressed.
Status WriteDepthExr(const std::filesystem::path& path, const CaptureImage& image);

// What a capture's values are.
enum class CaptureStores : std::uint8_t {
  kWindowDepth,  // the depth buffer's own values: window depth in [0, 1], decoded through the projection
  kEyeDepth,     // linear depth written by the engine: eye depth (-view z) in world units
};
const char* CaptureStoresName(CaptureStores stores);  // "window-depth", "eye-depth"
Expected<CaptureStores> ParseCaptureStores(std::string_view text);

// The image's pixels as eye depths. Window depth is decoded with the
// projection's convention (bits of `convention`) and planes; the clear
// value (the far plane's window depth: 1, or 0 reversed) and, for eye
// depth, 0 and infinity are background. A value no frame of the
// projection can store (below 0 or above 1, NaN, a negative eye depth) is
// an error naming the pixel.
Expected<CapturedPixels> DecodeCapture(const CaptureImage& image, const std::string& source, CaptureStores stores,
                                       Convention convention, double near, double far);

// Bits lost (BitsLost of the total error, as the judge measures it) at each
// pixel of the capture by one cell on one backend; NaN where the pixel is
// background or outside the domain. `domain` holds the capture.
Expected<std::vector<float>> BitsLostPerPixel(const Domain& domain, const Cell& cell, Backend& backend);

// The picture: each pixel coloured by its bits lost on a scale from 0 to
// kAllBitsLost (dark blue through green to yellow, then red for the last
// four bits), background grey; under it a colour bar with a tick every 4
// bits. Errors name the file.
Status WriteBitsLostPng(const std::filesystem::path& path, std::uint32_t width, std::uint32_t height,
                        const std::vector<float>& bits);
// The colour of `bits` on that scale (RGB).
std::array<std::uint8_t, 3> BitsColour(float bits);

}  // namespace depthbench
