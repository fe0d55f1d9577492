// Known findings: shader findings (a NaN, an Inf or an error beyond the
// bound where exact arithmetic on the shader's inputs is fine) that are
// understood and accepted, each with its reason, committed in
// fuzz/known_findings.json. The fuzz campaign reports them apart and fails
// only on findings that none of them matches, so a fuzz job stays green on
// unchanged code and turns red on anything new.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "bench/base/json_reader.h"
#include "bench/base/status.h"
#include "bench/fuzz/case_check.h"
#include "bench/pipeline/cells.h"

namespace depthbench {

inline constexpr JsonSchema kKnownFindingsSchema{"depthbench.known_findings", 1,
                                                 "a known-findings file (fuzz/known_findings.json)"};

struct KnownFinding {
  Variant variant;
  std::vector<Convention> conventions;  // empty: any
  std::vector<Format> formats;          // empty: any
  // Backends it is accepted on (empty: any); "vulkan" also covers its
  // probes ("vulkan:worst-division"), as the device's own behaviour does.
  std::vector<std::string> backends;
  FindingKind kind = FindingKind::kNaN;
  std::string reason;

  bool Matches(const Cell& cell, FindingKind found, std::string_view backend) const;
};

Expected<std::vector<KnownFinding>> KnownFindingsFromJson(const nlohmann::json& json, const std::string& source);
Expected<std::vector<KnownFinding>> ReadKnownFindings(const std::filesystem::path& path);

// The first entry that matches, or nullptr.
const KnownFinding* FindKnown(const std::vector<KnownFinding>& known, const Cell& cell, FindingKind kind,
                              std::string_view backend);

}  // namespace depthbench
