#include "bench/fuzz/known_findings.h"

#include <algorithm>

#include <fmt/format.h>

namespace depthbench {
namespace {

Expected<FindingKind> KindFrom(const JsonReader& r) {
  DB_ASSIGN_OR_RETURN(const std::string name, r.String());
  for (FindingKind kind :
       {FindingKind::kNaN, FindingKind::kInf, FindingKind::kBeyondBound, FindingKind::kBeyondProven}) {
    if (name == FindingKindName(kind)) return kind;
  }
  return r.Error(fmt::format("'{}' is not one of nan, inf, beyond_bound, beyond_proven_bound", name));
}

// A backend's name as --backend takes it: "cpu", "vulkan", or "vulkan:"
// and its probes.
Expected<std::string> ParseBackendName(const std::string& name) {
  if (name == "cpu" || name == "vulkan" || name.starts_with("vulkan:")) return name;
  return InvalidArgument(fmt::format("'{}' is not a backend (cpu, vulkan, or vulkan:PROBES)", name));
}

// Reads the optional list `key` of names through `parse`.
template <class T, class Parse>
Status NamesInto(const JsonReader& entry, const char* key, Parse parse, std::vector<T>& out) {
  if (!entry.Has(key)) return Status::Ok();
  return entry.ForEach(key, [&](const JsonReader& e) -> Status {
    DB_ASSIGN_OR_RETURN(const std::string name, e.String());
    const Expected<T> value = parse(name);
    if (!value.ok()) return e.Error(value.status().message());
    out.push_back(*value);
    return Status::Ok();
  });
}

}  // namespace

bool KnownFinding::Matches(const Cell& cell, FindingKind found, std::string_view backend) const {
  const auto listed = [](const auto& list, auto value) {
    return list.empty() || std::find(list.begin(), list.end(), value) != list.end();
  };
  // A backend's name before its probes: "vulkan" of "vulkan:worst-division".
  const std::string_view base = backend.substr(0, backend.find(':'));
  const bool on_backend = backends.empty() || std::any_of(backends.begin(), backends.end(), [&](const std::string& b) {
                            return b == backend || b == base;
                          });
  return cell.variant == variant && found == kind && listed(conventions, cell.convention) &&
         listed(formats, cell.format) && on_backend;
}

Expected<std::vector<KnownFinding>> KnownFindingsFromJson(const nlohmann::json& json, const std::string& source) {
  const JsonReader top(json, source);
  DB_RETURN_IF_ERROR(top.CheckSchema(kKnownFindingsSchema));
  std::vector<KnownFinding> known;
  DB_RETURN_IF_ERROR(top.ForEach("findings", [&](const JsonReader& entry) -> Status {
    KnownFinding k;
    DB_ASSIGN_OR_RETURN(const std::string variant, entry.String("variant"));
    const Expected<Variant> parsed = ParseVariant(variant);
    if (!parsed.ok()) return entry.Error(parsed.status().message());
    k.variant = *parsed;
    DB_RETURN_IF_ERROR(NamesInto(entry, "conventions", ParseConvention, k.conventions));
    DB_RETURN_IF_ERROR(NamesInto(entry, "formats", ParseFormat, k.formats));
    DB_RETURN_IF_ERROR(NamesInto(entry, "backends", ParseBackendName, k.backends));
    DB_ASSIGN_OR_RETURN(const JsonReader kind, entry.Field("kind"));
    DB_ASSIGN_OR_RETURN(k.kind, KindFrom(kind));
    DB_ASSIGN_OR_RETURN(k.reason, entry.String("reason"));
    if (k.reason.empty()) return entry.Error("reason: say why this finding is accepted");
    known.push_back(std::move(k));
    return Status::Ok();
  }));
  return known;
}

Expected<std::vector<KnownFinding>> ReadKnownFindings(const std::filesystem::path& path) {
  DB_ASSIGN_OR_RETURN(const nlohmann::json json, ReadJsonFile(path));
  return KnownFindingsFromJson(json, path.string());
}

const KnownFinding* FindKnown(const std::vector<KnownFinding>& known, const Cell& cell, FindingKind kind,
                              std::string_view backend) {
  for (const KnownFinding& k : known) {
    if (k.Matches(cell, kind, backend)) return &k;
  }
  return nullptr;
}

}  // namespace depthbench
