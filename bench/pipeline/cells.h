// The catalog: reconstruction variants, depth conventions, storage formats,
// and the one rule that says which variant reads which format under which
// convention. A Cell is one (variant, convention, format) recipe; results
// are kept per cell and per backend. The built-in variants are a constant
// table; a command that runs the user's shader files as well builds a
// Catalogue of its own (user_variant.h MakeCatalogue) and passes it down.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <tuple>
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
  kOrthoLerp,
};
// The built-in variants; a Catalogue's variants from the user's shader
// files follow them, so that a Variant is an index into its catalogue.
inline constexpr int kVariantCount = 9;
// Variant ids are a byte; far more user variants than anyone passes on a
// command line.
inline constexpr int kMostUserVariants = 64;
// Every id a variant of any catalogue can have is below this.
inline constexpr int kMostVariants = kVariantCount + kMostUserVariants;

struct UserShader;   // bench/pipeline/user_variant.h
struct UserVariant;  // bench/pipeline/user_variant.h

// The projections a variant's formula is written for: a ray through a
// perspective frustum, the linear map of an orthographic view volume, or
// any (a matrix inverse that covers both).
enum class Projections : std::uint8_t { kPerspective, kOrthographic, kBoth };

struct VariantInfo {
  Variant id;
  std::string_view name;
  std::string_view source;  // the article it restates, by its short name in docs/sources.md
  DepthInput input;
  std::string_view idea;
  // The formula puts NDC (0, 0) on the view axis (it reads the lens's
  // half extents only, as its source writes it): wrong for an off-centre
  // frustum, a VR eye's or a jittered one (Domain::OffCentre).
  bool assumes_symmetric_frustum = false;
  Projections projections = Projections::kPerspective;
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
  // An orthographic projection's depth buffer: linear in eye depth too,
  // but written by the hardware (no infinite far plane).
  kOrthoStandard,
  kOrthoReversed,
  kOrthoStandardGl,
  kOrthoReversedGl,
};
inline constexpr int kConventionCount = 13;
// A frame's DepthParams slots: one per perspective convention, numbered by
// its DB_CONVENTION_* bits; an orthographic frame's conventions take the
// slots of their perspective namesakes (DepthSlot).
inline constexpr int kHardwareConventionCount = 8;

struct ConventionInfo {
  Convention id;
  std::string_view name;
  std::uint32_t bits;  // DB_CONVENTION_* of shared/params.h
  bool hardware;  // a depth buffer's: the frame has DepthParams for it
  std::string_view description;
  bool orthographic() const { return (bits & 8u) != 0u; }  // DB_CONVENTION_ORTHOGRAPHIC
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
     "full-screen pass: world-space far-plane frustum ray, interpolated; camera + depth * ray", false},
    {Variant::kVolumeRay, "volume_ray", "Pettineo 2009", DepthInput::kLinear,
     "light-volume geometry: ray = view position * (far / -view.z); view = depth * ray", false},
    {Variant::kTanAspect, "tan_aspect", "Coluna 2011", DepthInput::kLinear,
     "similar triangles: view.xy = (tan*aspect, tan) * ndc.xy * z, no matrix", true},
    {Variant::kEyeRay, "eye_ray", "eye-ray post 2011", DepthInput::kViewZ,
     "eye ray divided by its z in the pixel stage, times stored view z; world-space ray alongside", false},
    {Variant::kInverseVp, "inverse_vp", "Unity URP", DepthInput::kHardware,
     "inverse view-projection times (ndc, depth, 1), divide by w", false, Projections::kBoth},
    {Variant::kDivide, "divide", "engine shader notes", DepthInput::kHardware,
     "view = (ndc.x/H, ndc.y/V, -1) / (depth/B - A/B)", true},
    {Variant::kReciprocal, "reciprocal", "engine shader notes", DepthInput::kHardware,
     "invW = B / (depth - A); view = (ndc.x/H, ndc.y/V, -1) * invW", true},
    {Variant::kPq, "pq", "engine shader notes", DepthInput::kHardware,
     "invW = 1 / (depth*P + Q), P = 1/B, Q = -A/B precomputed", true},
    {Variant::kOrthoLerp, "ortho_lerp", "Unity orthographic", DepthInput::kHardware,
     "orthographic: z = lerp(near, far, depth) (1 - depth if reversed); view.xy = half extents * ndc.xy + centre",
     false, Projections::kOrthographic},
}};

// The DB_CONVENTION_* bits of shared/params.h (cells.cc checks they agree).
inline constexpr std::uint32_t kRev = 1, kInf = 2, kGl = 4, kOrtho = 8;

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
    {Convention::kOrthoStandard, "ortho-standard", kOrtho, true,
     "orthographic: near -> 0, far -> 1, linear in eye depth, clip depth [0,1]"},
    {Convention::kOrthoReversed, "ortho-reversed", kOrtho | kRev, true,
     "orthographic: near -> 1, far -> 0, linear in eye depth, clip depth [0,1]"},
    {Convention::kOrthoStandardGl, "ortho-standard-gl", kOrtho | kGl, true,
     "orthographic: near -> -1, far -> 1, linear in eye depth, clip depth [-1,1]"},
    {Convention::kOrthoReversedGl, "ortho-reversed-gl", kOrtho | kRev | kGl, true,
     "orthographic: near -> 1, far -> -1, linear in eye depth, clip depth [-1,1]"},
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

// A built-in variant (below kVariantCount); any other is looked up in its
// Catalogue (Cell::variant_info, Catalogue::Info).
const VariantInfo& Info(Variant v);
inline const ConventionInfo& Info(Convention c) { return catalog::kConventions[static_cast<int>(c)]; }
inline const FormatInfo& Info(Format f) { return catalog::kFormats[static_cast<int>(f)]; }
// Bytes a texel of the format takes as Vulkan stores it, and as a copy to a
// buffer packs it: X8_D24 takes four.
inline std::uint32_t TexelBytes(Format f) { return Info(f).bits <= 16 ? 2u : 4u; }
// The built-in variants.
inline std::span<const VariantInfo> AllVariants() { return catalog::kVariants; }
inline std::span<const ConventionInfo> AllConventions() { return catalog::kConventions; }
inline std::span<const FormatInfo> AllFormats() { return catalog::kFormats; }

// The pairing rule, the one place that decides it: a variant reads a format
// when the format stores the kind of depth the variant consumes, the
// convention is a projective one exactly when that depth is hardware depth,
// and the variant's formula is written for the convention's projection
// (perspective or orthographic).
bool Reads(const VariantInfo& v, Convention c, Format f);
// The rule for a built-in variant.
bool Reads(Variant v, Convention c, Format f);
// The DepthParams slot of a frame that holds a projective convention's
// constants (its DB_CONVENTION_* bits less the orthographic one).
inline std::uint32_t DepthSlot(Convention c) { return Info(c).bits & 7u; }

// A depth buffer's content: what a convention and format make of a scene.
struct Encoding {
  Convention convention;
  Format format;
  friend bool operator==(const Encoding&, const Encoding&) = default;
};

class Catalogue;

struct Cell {
  Variant variant;
  Convention convention;
  Format format;
  // The catalogue that defines `variant`; it outlives the cell. Null stands
  // for the built-in variants, which need none; a cell of a variant from
  // the user's file always names its catalogue (Catalogue makes such cells).
  const Catalogue* catalogue = nullptr;

  Encoding encoding() const { return {convention, format}; }
  // The variant's name, input and, for a user's variant, shader file.
  const VariantInfo& variant_info() const;
  std::string Name() const;  // "divide/standard/x8_d24_unorm"
  // A cell is its recipe: cells of the same variant, convention and format
  // are equal whichever pointer to their catalogue they hold (a command
  // has one catalogue).
  std::tuple<Variant, Convention, Format> recipe() const { return {variant, convention, format}; }
  friend bool operator==(const Cell& a, const Cell& b) { return a.recipe() == b.recipe(); }
  friend auto operator<=>(const Cell& a, const Cell& b) { return a.recipe() <=> b.recipe(); }
};

// The variants a command runs: the built-in ones, then those of the user's
// shader files (user_variant.h MakeCatalogue), in Variant order, with the
// cells and names they make. A command builds its own and passes it down;
// nothing of it outlives the command. It does not change once built, and
// the cells it makes point to it, so it is neither copied nor moved.
class Catalogue {
 public:
  // The built-in variants alone.
  Catalogue();
  // The built-in variants, then `user_variants` in order: their names
  // differ from each other and from the built-in ones, and there are at
  // most kMostUserVariants (MakeCatalogue checks both).
  explicit Catalogue(std::vector<UserVariant> user_variants);
  ~Catalogue();
  Catalogue(const Catalogue&) = delete;
  Catalogue& operator=(const Catalogue&) = delete;

  // One shared catalogue of the built-in variants, for callers that run no
  // user's file (it never changes).
  static const Catalogue& BuiltIn();

  std::span<const VariantInfo> variants() const { return variants_; }
  const VariantInfo& Info(Variant v) const;
  bool has_user_variants() const { return variants_.size() > static_cast<std::size_t>(kVariantCount); }
  bool Reads(Variant v, Convention c, Format f) const;
  // The cell of this catalogue's variant `v` under `c` and `f`.
  Cell MakeCell(Variant v, Convention c, Format f) const { return {v, c, f, this}; }
  // Every valid cell, in catalog order.
  std::vector<Cell> Cells() const;

  // Lookup by name, with a message that lists the allowed names.
  Expected<Variant> ParseVariant(std::string_view name) const;
  Expected<Cell> ParseCell(std::string_view name) const;  // "variant/convention/format"

 private:
  std::vector<UserVariant> user_variants_;  // what the user's VariantInfo point into
  std::vector<VariantInfo> variants_;
};

// The cells, names and lookups of the built-in catalogue (Catalogue::BuiltIn()).
// Every valid cell, in catalog order.
std::vector<Cell> AllCells();
// Every encoding some variant reads, in catalog order (the user's variants
// read the same kinds of depth, and so the same encodings).
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
  // The catalogue's cells it keeps, in the catalogue's order.
  std::vector<Cell> CellsOf(const Catalogue& catalogue) const;
};

}  // namespace depthbench
