// Facts about where and when a run happens, recorded in its results.
#pragma once

#include <string>

namespace depthbench {

std::string
CurrentCommit();  // git commit of the source tree ("-modified" appended when tracked files differ), or "unknown"
std::string CurrentTimeUtc();  // ISO 8601, e.g. "2026-11-22T10:03:00Z"
std::string HostName();

}  // namespace depthbench
