// Facts about where and when a run happens, recorded in its results (what
// the binary is comes from build_info.h).
#pragma once

#include <string>

namespace depthbench {

std::string CurrentTimeUtc();  // ISO 8601, e.g. "2026-11-22T10:03:00Z"
std::string HostName();

}  // namespace depthbench
