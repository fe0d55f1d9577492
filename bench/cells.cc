#include "bench/cells.h"

#include <algorithm>
#include <cctype>

#include "bench/formulas.h"

namespace depthbench {
namespace {

constexpr std::array<VariantInfo, kVariantCount> kVariants = {{
    {Variant::kFrustumRay, "frustum_ray", "000", DepthInput::kLinear,
     "full-screen pass: world-space far-plane frustum ray, interpolated; camera + depth * ray"},
    {Variant::kVolumeRay, "volume_ray", "000", DepthInput::kLinear,
     "light-volume geometry: ray = view position * (far / -view.z); view = depth * ray"},
    {Variant::kTanAspect, "tan_aspect", "001", DepthInput::kLinear,
     "similar triangles: view.xy = (tan*aspect, tan) * ndc.xy * z, no matrix"},
    {Variant::kEyeRay, "eye_ray", "003", DepthInput::kViewZ,
     "eye ray divided by its z in the pixel stage, times stored view z; world-space ray alongside"},
    {Variant::kInverseVp, "inverse_vp", "002", DepthInput::kHardware,
     "inverse view-projection times (ndc, depth, 1), divide by w"},
    {Variant::kDivide, "divide", "004", DepthInput::kHardware,
     "view = (ndc.x/H, ndc.y/V, -1) / (depth/B - A/B)"},
    {Variant::kReciprocal, "reciprocal", "004", DepthInput::kHardware,
     "invW = B / (depth - A); view = (ndc.x/H, ndc.y/V, -1) * invW"},
    {Variant::kPq, "pq", "004", DepthInput::kHardware,
     "invW = 1 / (depth*P + Q), P = 1/B, Q = -A/B precomputed"},
}};

constexpr std::uint32_t kRev = f32::DB_CONVENTION_REVERSED;
constexpr std::uint32_t kInf = f32::DB_CONVENTION_INFINITE;
constexpr std::uint32_t kGl = f32::DB_CONVENTION_CLIP_MINUS_ONE;

constexpr std::array<ConventionInfo, kConventionCount> kConventions = {{
    {Convention::kStandard, "standard", 0, true, "near -> 0, far -> 1, clip depth [0,1]"},
    {Convention::kReversed, "reversed", kRev, true, "near -> 1, far -> 0, clip depth [0,1]"},
    {Convention::kStandardInf, "standard-inf", kInf, true,
     "near -> 0, infinite far -> 1, clip depth [0,1]"},
    {Convention::kReversedInf, "reversed-inf", kRev | kInf, true,
     "near -> 1, infinite far -> 0, clip depth [0,1]"},
    {Convention::kStandardGl, "standard-gl", kGl, true, "near -> -1, far -> 1, clip depth [-1,1]"},
    {Convention::kReversedGl, "reversed-gl", kRev | kGl, true,
     "near -> 1, far -> -1, clip depth [-1,1]"},
    {Convention::kStandardInfGl, "standard-inf-gl", kInf | kGl, true,
     "near -> -1, infinite far -> 1, clip depth [-1,1]"},
    {Convention::kReversedInfGl, "reversed-inf-gl", kRev | kInf | kGl, true,
     "near -> 1, infinite far -> -1, clip depth [-1,1]"},
    {Convention::kLinear, "linear", 0, false,
     "no projective mapping: the stored value is linear in eye depth"},
}};

constexpr std::array<FormatInfo, kFormatCount> kFormats = {{
    {Format::kD16Unorm, "d16_unorm", "d16", "VK_FORMAT_D16_UNORM", DepthInput::kHardware,
     TexelKind::kUnorm, 16},
    {Format::kX8D24Unorm, "x8_d24_unorm", "d24", "VK_FORMAT_X8_D24_UNORM_PACK32",
     DepthInput::kHardware, TexelKind::kUnorm, 24},
    {Format::kD32Sfloat, "d32_sfloat", "d32f", "VK_FORMAT_D32_SFLOAT", DepthInput::kHardware,
     TexelKind::kFloat32, 32},
    {Format::kR32Sfloat, "r32_sfloat", "r32f", "VK_FORMAT_R32_SFLOAT", DepthInput::kLinear,
     TexelKind::kFloat32, 32},
    {Format::kR16Sfloat, "r16_sfloat", "r16f", "VK_FORMAT_R16_SFLOAT", DepthInput::kLinear,
     TexelKind::kFloat16, 16},
    {Format::kR16Unorm, "r16_unorm", "r16", "VK_FORMAT_R16_UNORM", DepthInput::kLinear,
     TexelKind::kUnorm, 16},
    {Format::kR32SfloatViewZ, "r32_sfloat_viewz", "viewz", "VK_FORMAT_R32_SFLOAT",
     DepthInput::kViewZ, TexelKind::kFloat32, 32},
}};

std::string Lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

template <class Table, class NameOf>
std::string JoinNames(const Table& table, NameOf name_of) {
  std::string out;
  for (const auto& entry : table) {
    if (!out.empty()) out += ", ";
    out += name_of(entry);
  }
  return out;
}

}  // namespace

const VariantInfo& Info(Variant v) { return kVariants[static_cast<int>(v)]; }
const ConventionInfo& Info(Convention c) { return kConventions[static_cast<int>(c)]; }
const FormatInfo& Info(Format f) { return kFormats[static_cast<int>(f)]; }
std::span<const VariantInfo> AllVariants() { return kVariants; }
std::span<const ConventionInfo> AllConventions() { return kConventions; }
std::span<const FormatInfo> AllFormats() { return kFormats; }

bool Reads(Variant v, Convention c, Format f) {
  DepthInput input = Info(v).input;
  return Info(f).stores == input && Info(c).hardware == (input == DepthInput::kHardware);
}

std::string Cell::Name() const {
  return std::string(Info(variant).name) + "/" + std::string(Info(convention).name) + "/" +
         std::string(Info(format).name);
}

std::vector<Cell> AllCells() {
  std::vector<Cell> cells;
  for (const auto& v : kVariants)
    for (const auto& c : kConventions)
      for (const auto& f : kFormats)
        if (Reads(v.id, c.id, f.id)) cells.push_back({v.id, c.id, f.id});
  return cells;
}

std::vector<Encoding> AllEncodings() {
  std::vector<Encoding> encodings;
  for (const auto& c : kConventions)
    for (const auto& f : kFormats) {
      bool read = std::any_of(kVariants.begin(), kVariants.end(),
                              [&](const VariantInfo& v) { return Reads(v.id, c.id, f.id); });
      if (read) encodings.push_back({c.id, f.id});
    }
  return encodings;
}

Expected<Variant> ParseVariant(std::string_view name) {
  std::string key = Lower(name);
  for (const auto& v : kVariants)
    if (v.name == key) return v.id;
  return InvalidArgument("unknown variant '" + std::string(name) + "'; allowed: " +
                         JoinNames(kVariants, [](const VariantInfo& v) { return v.name; }));
}

Expected<Convention> ParseConvention(std::string_view name) {
  std::string key = Lower(name);
  for (const auto& c : kConventions)
    if (c.name == key) return c.id;
  return InvalidArgument("unknown convention '" + std::string(name) + "'; allowed: " +
                         JoinNames(kConventions, [](const ConventionInfo& c) { return c.name; }));
}

Expected<Format> ParseFormat(std::string_view name) {
  std::string key = Lower(name);
  for (const auto& f : kFormats)
    if (f.name == key || f.short_name == key) return f.id;
  // VK_FORMAT_R32_SFLOAT names two of our formats; it means the linear one.
  for (const auto& f : kFormats)
    if (Lower(f.vulkan_name) == key) return f.id;
  return InvalidArgument("unknown format '" + std::string(name) + "'; allowed: " +
                         JoinNames(kFormats, [](const FormatInfo& f) {
                           return std::string(f.name) + " (" + std::string(f.short_name) + ")";
                         }));
}

Expected<Cell> ParseCell(std::string_view name) {
  auto first = name.find('/');
  auto second = first == std::string_view::npos ? first : name.find('/', first + 1);
  if (second == std::string_view::npos) {
    return InvalidArgument("cell '" + std::string(name) +
                           "' is not of the form variant/convention/format");
  }
  DB_ASSIGN_OR_RETURN(Variant v, ParseVariant(name.substr(0, first)));
  DB_ASSIGN_OR_RETURN(Convention c, ParseConvention(name.substr(first + 1, second - first - 1)));
  DB_ASSIGN_OR_RETURN(Format f, ParseFormat(name.substr(second + 1)));
  if (!Reads(v, c, f)) {
    return InvalidArgument("cell '" + std::string(name) + "' does not exist: " +
                           std::string(Info(v).name) + " does not read " +
                           std::string(Info(f).name) + " under the " +
                           std::string(Info(c).name) + " convention");
  }
  return Cell{v, c, f};
}

bool CellFilter::Keeps(const Cell& cell) const {
  auto keeps = [](const auto& list, auto value) {
    return list.empty() || std::find(list.begin(), list.end(), value) != list.end();
  };
  return keeps(variants, cell.variant) && keeps(conventions, cell.convention) &&
         keeps(formats, cell.format);
}

}  // namespace depthbench
