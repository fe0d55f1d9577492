// Runs the depthbench program the build made, the way a user does, and
// captures its exit code and output.
#pragma once

#include <string>
#include <vector>

namespace depthbench::testing {

struct CommandResult {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

// Runs `depthbench args...` (no shell: arguments are passed as they are).
CommandResult RunDepthbench(const std::vector<std::string>& args);

// A fresh empty directory under the system's temporary directory.
std::string MakeTempDir(const std::string& name);

}  // namespace depthbench::testing
