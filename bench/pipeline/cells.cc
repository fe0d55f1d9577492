#include "bench/pipeline/cells.h"

#include <algorithm>
#include <cctype>

#include "bench/base/suggest.h"
#include "bench/numerics/formulas.h"
#include "bench/pipeline/user_variant.h"

namespace depthbench {

static_assert(catalog::kRev == f32::DB_CONVENTION_REVERSED && catalog::kInf == f32::DB_CONVENTION_INFINITE &&
                  catalog::kGl == f32::DB_CONVENTION_CLIP_MINUS_ONE &&
                  catalog::kOrtho == f32::DB_CONVENTION_ORTHOGRAPHIC && f32::DB_CONVENTION_SLOTS == 7u,
              "convention bits must match shared/params.h");

namespace {
using catalog::kConventions;
using catalog::kFormats;

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

// "; did you mean ..." among the names of a catalogue.
template <class Catalogue>
std::string Suggest(std::string_view word, const Catalogue& catalogue) {
  std::vector<std::string> names;
  for (const auto& entry : catalogue) names.emplace_back(entry.name);
  return DidYouMean(word, names);
}

}  // namespace

const VariantInfo& Info(Variant v) { return catalog::kVariants.at(static_cast<std::size_t>(v)); }

bool Reads(const VariantInfo& v, Convention c, Format f) {
  const Projections needed = Info(c).orthographic() ? Projections::kOrthographic : Projections::kPerspective;
  return Info(f).stores == v.input && Info(c).hardware == (v.input == DepthInput::kHardware) &&
         (v.projections == Projections::kBoth || v.projections == needed);
}

bool Reads(Variant v, Convention c, Format f) { return Reads(Info(v), c, f); }

const VariantInfo& Cell::variant_info() const {
  return catalogue != nullptr ? catalogue->Info(variant) : depthbench::Info(variant);
}

std::string Cell::Name() const {
  return std::string(variant_info().name) + "/" + std::string(Info(convention).name) + "/" +
         std::string(Info(format).name);
}

Catalogue::Catalogue() : variants_(catalog::kVariants.begin(), catalog::kVariants.end()) {}

Catalogue::Catalogue(std::vector<UserVariant> user_variants)
    : user_variants_(std::move(user_variants)), variants_(catalog::kVariants.begin(), catalog::kVariants.end()) {
  // The vector holding the user's variants never changes again: the views
  // into its strings stay valid for the catalogue's life.
  for (const UserVariant& user : user_variants_) {
    variants_.push_back({static_cast<Variant>(variants_.size()), user.name, user.source, user.input, user.idea, false,
                         Projections::kPerspective, &user.shader});
  }
}

Catalogue::~Catalogue() = default;

const Catalogue& Catalogue::BuiltIn() {
  static const Catalogue built_in;
  return built_in;
}

const VariantInfo& Catalogue::Info(Variant v) const { return variants_.at(static_cast<std::size_t>(v)); }

bool Catalogue::Reads(Variant v, Convention c, Format f) const { return depthbench::Reads(Info(v), c, f); }

std::vector<Cell> Catalogue::Cells() const {
  std::vector<Cell> cells;
  for (const auto& v : variants_)
    for (const auto& c : kConventions)
      for (const auto& f : kFormats)
        if (Reads(v.id, c.id, f.id)) cells.push_back(MakeCell(v.id, c.id, f.id));
  return cells;
}

std::vector<Cell> AllCells() { return Catalogue::BuiltIn().Cells(); }

std::vector<Encoding> AllEncodings() {
  std::vector<Encoding> encodings;
  for (const auto& c : kConventions)
    for (const auto& f : kFormats) {
      bool read = std::any_of(catalog::kVariants.begin(), catalog::kVariants.end(),
                              [&](const VariantInfo& v) { return Reads(v.id, c.id, f.id); });
      if (read) encodings.push_back({c.id, f.id});
    }
  return encodings;
}

Expected<Variant> Catalogue::ParseVariant(std::string_view name) const {
  std::string key = Lower(name);
  for (const auto& v : variants_)
    if (v.name == key) return v.id;
  return InvalidArgument("unknown variant '" + std::string(name) +
                         "'; allowed: " + JoinNames(variants_, [](const VariantInfo& v) { return v.name; }) +
                         Suggest(name, variants_) + " (a variant from a shader file needs its --variant-file)");
}

Expected<Variant> ParseVariant(std::string_view name) { return Catalogue::BuiltIn().ParseVariant(name); }

Expected<Convention> ParseConvention(std::string_view name) {
  std::string key = Lower(name);
  for (const auto& c : kConventions)
    if (c.name == key) return c.id;
  return InvalidArgument("unknown convention '" + std::string(name) +
                         "'; allowed: " + JoinNames(kConventions, [](const ConventionInfo& c) { return c.name; }) +
                         Suggest(name, kConventions));
}

Expected<Format> ParseFormat(std::string_view name) {
  std::string key = Lower(name);
  for (const auto& f : kFormats)
    if (f.name == key || f.short_name == key) return f.id;
  // VK_FORMAT_R32_SFLOAT names two of our formats; it means the linear one.
  for (const auto& f : kFormats)
    if (Lower(f.vulkan_name) == key) return f.id;
  return InvalidArgument(
      "unknown format '" + std::string(name) + "'; allowed: " +
      JoinNames(kFormats,
                [](const FormatInfo& f) { return std::string(f.name) + " (" + std::string(f.short_name) + ")"; }) +
      Suggest(name, kFormats));
}

Expected<Cell> Catalogue::ParseCell(std::string_view name) const {
  auto first = name.find('/');
  auto second = first == std::string_view::npos ? first : name.find('/', first + 1);
  if (second == std::string_view::npos) {
    return InvalidArgument("cell '" + std::string(name) + "' is not of the form variant/convention/format");
  }
  DB_ASSIGN_OR_RETURN(Variant v, ParseVariant(name.substr(0, first)));
  DB_ASSIGN_OR_RETURN(Convention c, ParseConvention(name.substr(first + 1, second - first - 1)));
  DB_ASSIGN_OR_RETURN(Format f, ParseFormat(name.substr(second + 1)));
  if (!Reads(v, c, f)) {
    return InvalidArgument("cell '" + std::string(name) + "' does not exist: " + std::string(Info(v).name) +
                           " does not read " + std::string(depthbench::Info(f).name) + " under the " +
                           std::string(depthbench::Info(c).name) + " convention");
  }
  return MakeCell(v, c, f);
}

Expected<Cell> ParseCell(std::string_view name) { return Catalogue::BuiltIn().ParseCell(name); }

bool CellFilter::Keeps(const Cell& cell) const {
  auto keeps = [](const auto& list, auto value) {
    return list.empty() || std::find(list.begin(), list.end(), value) != list.end();
  };
  return keeps(variants, cell.variant) && keeps(conventions, cell.convention) && keeps(formats, cell.format);
}

std::vector<Cell> CellFilter::CellsOf(const Catalogue& catalogue) const {
  std::vector<Cell> cells;
  for (const Cell& cell : catalogue.Cells())
    if (Keeps(cell)) cells.push_back(cell);
  return cells;
}

}  // namespace depthbench
