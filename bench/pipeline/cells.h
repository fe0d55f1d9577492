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

#include "bench/base/status.h"

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
// The built-in variants; variants from the user's shader files follow
// them (user_variant.h), so that a Variant is an index into AllVariants().
inline constexpr int kVariantCount = 8;

struct UserShader;  // bench/pipeline/user_variant.h

struct VariantInfo {
  Variant id;
  std::string_view name;
  std::string_view source;  // the article it restates, by its short name in docs/sources.md
  DepthInput input;
  std::string_view idea;
  // A variant from the user's shader file (--variant-file); null for the
  // built-in ones. It runs on Vulkan only.
  const UserShader* user = nullptr;
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

namespace catalog {
inline constexpr std::array<VariantInfo, kVariantCount> kVariants = {{
    {Variant::kFrustumRay, "frustum_ray", "Pettineo 2009", DepthInput::kLinear,
     "full-screen pass: world-space far-plane frustum ray, interpolated; camera + depth * ray"},
    {Variant::kVolumeRay, "volume_ray", "Pettineo 2009", DepthInput::kLinear,
     "light-volume geometry: ray = view position * (far / -view.z); view = depth * ray"},
    {Variant::kTanAspect, "tan_aspect", "Coluna 2011", DepthInput::kLinear,
     "similar triangles: view.xy = (tan*aspect, tan) * ndc.xy * z, no matrix"},
    {Variant::kEyeRay, "eye_ray", "eye-ray post 2011", DepthInput::kViewZ,
     "eye ray divided by its z in the pixel stage, times stored view z; world-space ray alongside"},
    {Variant::kInverseVp, "inverse_vp", "Unity URP", DepthInput::kHardware,
     "inverse view-projection times (ndc, depth, 1), divide by w"},
    {Variant::kDivide, "divide", "engine shader notes", DepthInput::kHardware,
     "view = (ndc.x/H, ndc.y/V, -1) / (depth/B - A/B)"},
    {Variant::kReciprocal, "reciprocal", "engine shader notes", DepthInput::kHardware,
     "invW = B / (depth - A); view = (ndc.x/H, ndc.y/V, -1) * invW"},
    {Variant::kPq, "pq", "engine shader notes", DepthInput::kHardware,
     "invW = 1 / (depth*P + Q), P = 1/B, Q = -A/B precomputed"},
}};

// The DB_CONVENTION_* bits of shared/params.h (cells.cc checks they agree).
inline constexpr std::uint32_t kRev = 1, kInf = 2, kGl = 4;

inline constexpr std::array<ConventionInfo, kConventionCount> kConventions = {{
    {Convention::kStandard, "standard", 0, true, "near -> 0, far -> 1, clip depth [0,1]"},
    {Convention::kReversed, "reversed", kRev, true, "near -> 1, far -> 0, clip depth [0,1]"},
    {Convention::kStandardInf, "standard-inf", kInf, true, "near -> 0, infinite far -> 1, clip depth [0,1]"},
    {Convention::kReversedInf, "reversed-inf", kRev | kInf, true, "near -> 1, infinite far -> 0, clip depth [0,1]"},
    {Convention::kStandardGl, "standard-gl", kGl, true, "near -> -1, far -> 1, clip depth [-1,1]"},
    {Convention::kReversedGl, "reversed-gl", kRev | kGl, true, "near -> 1, far -> -1, clip depth [-1,1]"},
    {Convention::kStandardInfGl, "standard-inf-gl", kInf | kGl, true,
     "near -> -1, infinite far -> 1, clip depth [-1,1]"},
    {Convention::kReversedInfGl, "reversed-inf-gl", kRev | kInf | kGl, true,
     "near -> 1, infinite far -> -1, clip depth [-1,1]"},
    {Convention::kLinear, "linear", 0, false, "no projective mapping: the stored value is linear in eye depth"},
}};

inline constexpr std::array<FormatInfo, kFormatCount> kFormats = {{
    {Format::kD16Unorm, "d16_unorm", "d16", "VK_FORMAT_D16_UNORM", DepthInput::kHardware, TexelKind::kUnorm, 16},
    {Format::kX8D24Unorm, "x8_d24_unorm", "d24", "VK_FORMAT_X8_D24_UNORM_PACK32", DepthInput::kHardware,
     TexelKind::kUnorm, 24},
    {Format::kD32Sfloat, "d32_sfloat", "d32f", "VK_FORMAT_D32_SFLOAT", DepthInput::kHardware, TexelKind::kFloat32, 32},
    {Format::kR32Sfloat, "r32_sfloat", "r32f", "VK_FORMAT_R32_SFLOAT", DepthInput::kLinear, TexelKind::kFloat32, 32},
    {Format::kR16Sfloat, "r16_sfloat", "r16f", "VK_FORMAT_R16_SFLOAT", DepthInput::kLinear, TexelKind::kFloat16, 16},
    {Format::kR16Unorm, "r16_unorm", "r16", "VK_FORMAT_R16_UNORM", DepthInput::kLinear, TexelKind::kUnorm, 16},
    {Format::kR32SfloatViewZ, "r32_sfloat_viewz", "viewz", "VK_FORMAT_R32_SFLOAT", DepthInput::kViewZ,
     TexelKind::kFloat32, 32},
}};
}  // namespace catalog

// Built-in variants, then those registered from the user's files.
const VariantInfo& Info(Variant v);
inline const ConventionInfo& Info(Convention c) { return catalog::kConventions[static_cast<int>(c)]; }
inline const FormatInfo& Info(Format f) { return catalog::kFormats[static_cast<int>(f)]; }
std::span<const VariantInfo> AllVariants();
// Appends a variant after the built-in ones and returns its id (how
// user_variant.cc registers the user's shader files); RemoveAddedVariants
// drops every appended one.
Variant AddVariant(const VariantInfo& info);
void RemoveAddedVariants();
inline std::span<const ConventionInfo> AllConventions() { return catalog::kConventions; }
inline std::span<const FormatInfo> AllFormats() { return catalog::kFormats; }

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
Expected<Cell> ParseCell(std::string_view name);      // "variant/convention/format"

// Which cells a filter keeps: empty lists keep everything.
struct CellFilter {
  std::vector<Variant> variants;
  std::vector<Convention> conventions;
  std::vector<Format> formats;
  bool Keeps(const Cell& cell) const;
};

}  // namespace depthbench
