// Facts about where and when a run happens, recorded in its results (what
// the binary is comes from build_info.h).
#pragma once

#include <string>

namespace depthbench {

std::string CurrentTimeUtc();  // ISO 8601, e.g. "2026-11-22T10:03:00Z"
std::string HostName();

// Whether this runs in a CI job: CI set to anything but "" or "false", as
// GitHub Actions, GitLab CI and most other services set it.
bool InCi();
// The Markdown file a GitHub Actions job shows as its summary
// ($GITHUB_STEP_SUMMARY), empty outside such a job. Steps append to it.
std::string StepSummaryFile();

}  // namespace depthbench
