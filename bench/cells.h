// The catalog: reconstruction variants, depth conventions, storage formats,
// and the one rule that says which variant reads which format under which
// convention. A Cell is one (variant, convention, format) recipe; results
// are kept per cell and per backend.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "bench/status.h"

namespace depthbench {

// What a stored depth value means.
enum class DepthInput : std::uint8_t {
  kHardware,  // window-space depth of a projection (depth buffer)
  kLinear,    // eye depth / far, in [0, 1] (a G-buffer channel)
  kViewZ,     // view-space z itself (negative in our right-handed view space)
};

enum class Variant : std::uint8_t {
  kFrustumRay,
  kVolumeRay,
  kTanAspect,
  kEyeRay,
  kInverseVp,
  kDivide,
  kReciprocal,
  kPq,
};
inline constexpr int kVariantCount = 8;

struct VariantInfo {
  Variant id;
  std::string_view name;
  std::string_view seed;  // the article in ../shared/seeds it restates
  DepthInput input;
  std::string_view idea;
};

enum class Convention : std::uint8_t {
  kStandard,
  kReversed,
  kStandardInf,
  kReversedInf,
  kStandardGl,
  kReversedGl,
  kStandardInfGl,
  kReversedInfGl,
  kLinear,  // not a projective mapping: the value stored is linear in depth
};
inline constexpr int kConventionCount = 9;
// The projective conventions are the first eight; DepthParams exist for them.
inline constexpr int kHardwareConventionCount = 8;

struct ConventionInfo {
  Convention id;
  std::string_view name;
  std::uint32_t bits;  // DB_CONVENTION_* of shared/params.h
  bool hardware;
  std::string_view description;
};

enum class Format : std::uint8_t {
  kD16Unorm,
  kX8D24Unorm,
  kD32Sfloat,
  kR32Sfloat,
  kR16Sfloat,
  kR16Unorm,
  kR32SfloatViewZ,
};
inline constexpr int kFormatCount = 7;

// How a format's texels hold a value.
enum class TexelKind : std::uint8_t { kUnorm, kFloat32, kFloat16 };

struct FormatInfo {
  Format id;
  std::string_view name;
  std::string_view short_name;
  std::string_view vulkan_name;
  DepthInput stores;
  TexelKind texel;
  int bits;  // unorm bits, or the float's storage bits
};

const VariantInfo& Info(Variant v);
const ConventionInfo& Info(Convention c);
const FormatInfo& Info(Format f);
std::span<const VariantInfo> AllVariants();
std::span<const ConventionInfo> AllConventions();
std::span<const FormatInfo> AllFormats();

// The pairing rule, the one place that decides it: a variant reads a format
// when the format stores the kind of depth the variant consumes, and the
// convention is a projective one exactly when that depth is hardware depth.
bool Reads(Variant v, Convention c, Format f);

// A depth buffer's content: what a convention and format make of a scene.
struct Encoding {
  Convention convention;
  Format format;
  friend bool operator==(const Encoding&, const Encoding&) = default;
};

struct Cell {
  Variant variant;
  Convention convention;
  Format format;
  Encoding encoding() const { return {convention, format}; }
  std::string Name() const;  // "divide/standard/x8_d24_unorm"
  friend bool operator==(const Cell&, const Cell&) = default;
  friend auto operator<=>(const Cell&, const Cell&) = default;
};

// Every valid cell, in catalog order.
std::vector<Cell> AllCells();
// Every encoding some cell reads, in catalog order.
std::vector<Encoding> AllEncodings();

// Lookup by name, with a message that lists the allowed names.
Expected<Variant> ParseVariant(std::string_view name);
Expected<Convention> ParseConvention(std::string_view name);
Expected<Format> ParseFormat(std::string_view name);  // canonical, short or VK_FORMAT_ name
Expected<Cell> ParseCell(std::string_view name);       // "variant/convention/format"

// Which cells a filter keeps: empty lists keep everything.
struct CellFilter {
  std::vector<Variant> variants;
  std::vector<Convention> conventions;
  std::vector<Format> formats;
  bool Keeps(const Cell& cell) const;
};

}  // namespace depthbench
