#include "bench/capture/depth_capture.h"

#include <array>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <exception>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <fmt/format.h>
#include <png.h>

#include "bench/base/suggest.h"
#include "bench/fuzz/case_check.h"
#include "bench/numerics/formulas.h"
#include "bench/pipeline/stats.h"

namespace depthbench {
namespace {

const char* TypeName(Imf::PixelType type) {
  switch (type) {
    case Imf::HALF: return "half";
    case Imf::FLOAT: return "float";
    case Imf::UINT: return "uint";
    default: return "unknown";
  }
}

// The largest capture read: a 16K square frame's pixels (the eye depths
// take 8 bytes each, 2 GiB at this size).
constexpr std::uint64_t kMostCapturePixels = std::uint64_t{16384} * 16384;

}  // namespace

Expected<CaptureImage> ReadDepthExr(const std::filesystem::path& path, const std::string& channel) {
  const std::string name = path.string();
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    return InvalidArgument(fmt::format("{}: no such file", name));
  }
  try {
    Imf::InputFile file(name.c_str());
    const Imf::Header& header = file.header();
    const Imath::Box2i window = header.dataWindow();
    const std::int64_t width = std::int64_t{window.max.x} - window.min.x + 1;
    const std::int64_t height = std::int64_t{window.max.y} - window.min.y + 1;
    if (width <= 0 || height <= 0) return InvalidArgument(fmt::format("{}: the image has no pixels", name));
    if (static_cast<std::uint64_t>(width * height) > kMostCapturePixels) {
      return InvalidArgument(fmt::format("{}: {}x{} pixels; a capture holds at most 16384x16384", name, width, height));
    }
    std::vector<std::string> names;
    std::vector<Imf::PixelType> types;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
      names.emplace_back(it.name());
      types.push_back(it.channel().type);
    }
    std::size_t pick = names.size();
    if (!channel.empty()) {
      for (std::size_t k = 0; k < names.size(); ++k) {
        if (names[k] == channel) pick = k;
      }
      if (pick == names.size()) {
        return InvalidArgument(fmt::format("{}: no channel '{}'; it has {}{}", name, channel, fmt::join(names, ", "),
                                           DidYouMean(channel, names)));
      }
    } else if (names.size() == 1) {
      pick = 0;
    } else {
      return InvalidArgument(
          fmt::format("{}: {} channels ({}); name the depth channel (capture.channel in a scene file)", name,
                      names.size(), fmt::join(names, ", ")));
    }
    CaptureImage image;
    image.width = static_cast<std::uint32_t>(width);
    image.height = static_cast<std::uint32_t>(height);
    image.channel = names[pick];
    image.channel_type = TypeName(types[pick]);
    image.values.assign(static_cast<std::size_t>(width * height), 0.0f);
    Imf::FrameBuffer buffer;
    buffer.insert(image.channel, Imf::Slice::Make(Imf::FLOAT, image.values.data(), window, sizeof(float),
                                                  sizeof(float) * static_cast<std::size_t>(width)));
    file.setFrameBuffer(buffer);
    file.readPixels(window.min.y, window.max.y);
    return image;
  } catch (const std::exception& e) {
    return InvalidArgument(fmt::format("{}: not an OpenEXR image depthbench can read ({})", name, e.what()));
  }
}

Status WriteDepthExr(const std::filesystem::path& path, const CaptureImage& image) {
  const std::string name = path.string();
  try {
    Imf::Header header(static_cast<int>(image.width), static_cast<int>(image.height));
    header.compression() = Imf::ZIP_COMPRESSION;
    header.channels().insert(image.channel, Imf::Channel(Imf::FLOAT));
    Imf::OutputFile file(name.c_str(), header);
    Imf::FrameBuffer buffer;
    // OpenEXR's slices take a writable pointer; writing only reads it.
    buffer.insert(image.channel,
                  Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(image.values.data())),
                             sizeof(float), sizeof(float) * image.width));
    file.setFrameBuffer(buffer);
    file.writePixels(static_cast<int>(image.height));
  } catch (const std::exception& e) {
    return InvalidArgument(fmt::format("{}: cannot write the image ({})", name, e.what()));
  }
  return Status::Ok();
}

const char* CaptureStoresName(CaptureStores stores) {
  return stores == CaptureStores::kWindowDepth ? "window-depth" : "eye-depth";
}

Expected<CaptureStores> ParseCaptureStores(std::string_view text) {
  for (CaptureStores s : {CaptureStores::kWindowDepth, CaptureStores::kEyeDepth}) {
    if (text == CaptureStoresName(s)) return s;
  }
  return InvalidArgument(
      fmt::format("'{}' is not what a capture stores: window-depth (the depth buffer's values) "
                  "or eye-depth (linear depth in world units)",
                  text));
}

Expected<CapturedPixels> DecodeCapture(const CaptureImage& image, const std::string& source, CaptureStores stores,
                                       Convention convention, double near, double far) {
  const std::uint32_t bits = Info(convention).bits;
  const bool reversed = (bits & f32::DB_CONVENTION_REVERSED) != 0u;
  CapturedPixels out;
  out.source = source;
  out.width = image.width;
  out.height = image.height;
  out.eye_depth.resize(image.values.size());
  const auto bad = [&](std::size_t p, const char* allowed) {
    return InvalidArgument(fmt::format("{}: pixel ({}, {}) holds {}; {}", source, p % image.width, p / image.width,
                                       image.values[p], allowed));
  };
  for (std::size_t p = 0; p < image.values.size(); ++p) {
    const double v = image.values[p];
    double z = NAN;
    if (stores == CaptureStores::kWindowDepth) {
      if (!(v >= 0.0 && v <= 1.0)) return bad(p, "a depth buffer holds window depth in [0, 1]");
      const bool clear = reversed ? v == 0.0 : v == 1.0;
      if (!clear) {
        // Exact where it matters: 1 - v is exact for a float32 v in
        // [0.5, 1], and the double-double formula divides once.
        const DoubleDouble dd_far = std::isfinite(far) ? DoubleDouble(far) : DoubleDouble(0.0);
        z = hp::eye_depth_from_window_depth(DoubleDouble(near), dd_far, bits, DoubleDouble(v),
                                            DoubleDouble(1.0) - DoubleDouble(v))
                .ToDouble();
      }
    } else {
      if (std::isnan(v) || v < 0.0) return bad(p, "linear depth is an eye depth, at least 0 (0 or inf: nothing drawn)");
      if (v > 0.0 && std::isfinite(v)) z = v;
    }
    out.eye_depth[p] = z;
    if (std::isnan(z)) ++out.background;
  }
  return out;
}

Expected<std::vector<float>> BitsLostPerPixel(const Domain& domain, const Cell& cell, Backend& backend) {
  const CapturedSource source(domain);
  std::vector<float> bits(source.pixels().eye_depth.size(), NAN);
  DB_ASSIGN_OR_RETURN(CaseChecker checker, CaseChecker::Make({cell}, {&backend}));
  constexpr std::uint64_t kChunk = 1u << 16;
  for (std::uint64_t first = 0; first < source.sample_count(); first += kChunk) {
    const auto count = static_cast<std::uint32_t>(std::min(kChunk, source.sample_count() - first));
    DB_RETURN_IF_ERROR(checker.Evaluate(source, first, count));
    for (std::uint32_t s = 0; s < count; ++s) {
      const Judgement& j = checker.At(0, 0, s);
      if (j.judged) bits[source.PixelOf(first + s)] = static_cast<float>(BitsLost(j.total));
    }
  }
  return bits;
}

std::array<std::uint8_t, 3> BitsColour(float bits) {
  // Dark blue through teal and green to yellow over the first 20 bits (what
  // a reader tells apart), red over the last four (nothing left).
  struct Stop {
    float bits;
    std::array<float, 3> rgb;
  };
  static constexpr std::array<Stop, 5> kStops = {{{0.0f, {20, 20, 110}},
                                                  {8.0f, {30, 140, 140}},
                                                  {16.0f, {150, 210, 60}},
                                                  {20.0f, {250, 230, 40}},
                                                  {24.0f, {215, 25, 30}}}};
  const float b = std::clamp(bits, 0.0f, kStops.back().bits);
  std::size_t k = 1;
  while (k + 1 < kStops.size() && b > kStops[k].bits) ++k;
  const float t = (b - kStops[k - 1].bits) / (kStops[k].bits - kStops[k - 1].bits);
  std::array<std::uint8_t, 3> out;
  for (int c = 0; c < 3; ++c) {
    out[c] =
        static_cast<std::uint8_t>(std::lround(kStops[k - 1].rgb[c] + t * (kStops[k].rgb[c] - kStops[k - 1].rgb[c])));
  }
  return out;
}

Status WriteBitsLostPng(const std::filesystem::path& path, std::uint32_t width, std::uint32_t height,
                        const std::vector<float>& bits) {
  // The picture, a white gap, then the colour bar with its ticks.
  constexpr std::uint32_t kGap = 4, kBar = 12, kTick = 4;
  const std::uint32_t rows = height + kGap + kBar;
  std::vector<std::uint8_t> pixels(static_cast<std::size_t>(width) * rows * 3, 255);
  const auto put = [&](std::uint32_t x, std::uint32_t y, std::array<std::uint8_t, 3> rgb) {
    std::copy(rgb.begin(), rgb.end(), pixels.begin() + (static_cast<std::size_t>(y) * width + x) * 3);
  };
  for (std::uint32_t y = 0; y < height; ++y) {
    for (std::uint32_t x = 0; x < width; ++x) {
      const float b = bits[static_cast<std::size_t>(y) * width + x];
      put(x, y, std::isnan(b) ? std::array<std::uint8_t, 3>{128, 128, 128} : BitsColour(b));
    }
  }
  for (std::uint32_t x = 0; x < width; ++x) {
    const float b = static_cast<float>(kAllBitsLost) * (static_cast<float>(x) + 0.5f) / static_cast<float>(width);
    for (std::uint32_t y = height + kGap; y < rows; ++y) put(x, y, BitsColour(b));
  }
  for (int tick = 0; tick <= 6; ++tick) {  // every 4 bits
    const auto x = std::min(width - 1, static_cast<std::uint32_t>(tick * (width - 1) / 6));
    for (std::uint32_t y = rows - kTick; y < rows; ++y) put(x, y, {0, 0, 0});
  }

  const std::string name = path.string();
  std::FILE* file = std::fopen(name.c_str(), "wb");
  if (file == nullptr) return InvalidArgument(fmt::format("{}: cannot write the image", name));
  std::vector<png_bytep> row_pointers(rows);
  for (std::uint32_t y = 0; y < rows; ++y) row_pointers[y] = pixels.data() + static_cast<std::size_t>(y) * width * 3;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  volatile bool written = false;
  // libpng reports errors by longjmp: nothing with a destructor is made
  // between here and the jump's target.
  if (png != nullptr && info != nullptr && setjmp(png_jmpbuf(png)) == 0) {
    png_init_io(png, file);
    png_set_IHDR(png, info, width, rows, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    png_write_image(png, row_pointers.data());
    png_write_end(png, nullptr);
    written = true;
  }
  png_destroy_write_struct(&png, &info);
  const bool closed = std::fclose(file) == 0;
  if (!written || !closed) return InvalidArgument(fmt::format("{}: cannot write the image", name));
  return Status::Ok();
}

}  // namespace depthbench
