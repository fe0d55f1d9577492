// What this binary is: recorded when it was built (cmake/WriteBuildInfo.cmake),
// not read from wherever it runs, so results name the commit the binary
// was built from.
#pragma once

namespace depthbench {

const char* BuildVersion();  // "0.1.0"
// The source tree's commit at build time ("3748e2751ceb"), with
// "-modified" when tracked files had uncommitted changes; "unknown" when
// built outside a git checkout.
const char* BuildCommit();

}  // namespace depthbench
