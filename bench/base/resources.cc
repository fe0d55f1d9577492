#include "bench/base/resources.h"

#include <algorithm>
#include <cstdlib>
#include <system_error>
#include <vector>

#include <fmt/format.h>

namespace depthbench {
namespace {

namespace fs = std::filesystem;

// A folder is a data folder when it holds the shaders and their headers.
bool HoldsData(const fs::path& root) {
  std::error_code error;
  return fs::is_regular_file(root / "shaders" / "compute_pass.glsl", error) && fs::is_directory(root / "shared", error);
}

// Whether `path` lies inside `folder` (both made absolute and normal).
bool Inside(const fs::path& path, const fs::path& folder) {
  std::error_code error;
  const fs::path p = fs::weakly_canonical(path, error), f = fs::weakly_canonical(folder, error);
  const auto [end, unused] = std::mismatch(f.begin(), f.end(), p.begin(), p.end());
  return end == f.end();
}

}  // namespace

fs::path ExecutablePath() {
  std::error_code error;
  return fs::read_symlink("/proc/self/exe", error);
}

Expected<DataFolder> FindDataFolder() {
  if (const char* env = std::getenv("DEPTHBENCH_DATA_DIR"); env != nullptr && *env != '\0') {
    if (HoldsData(env)) return DataFolder{env, "DEPTHBENCH_DATA_DIR"};
    return NotFound(fmt::format(
        "DEPTHBENCH_DATA_DIR is '{}', which does not hold depthbench's data (shaders/compute_pass.glsl and shared/)",
        env));
  }
  const fs::path executable = ExecutablePath();
  std::vector<std::string> looked;
  if (!executable.empty()) {
    const fs::path installed = (executable.parent_path() / DEPTHBENCH_INSTALL_DATA_RELATIVE).lexically_normal();
    if (HoldsData(installed)) return DataFolder{installed, "install prefix"};
    looked.push_back(installed.string());
    if (Inside(executable, DEPTHBENCH_BUILD_TREE) && HoldsData(DEPTHBENCH_SOURCE_TREE)) {
      return DataFolder{DEPTHBENCH_SOURCE_TREE, "build tree"};
    }
  }
  return NotFound(fmt::format(
      "depthbench's data folder (its shaders, shared/ headers and report template) is not in {}: install "
      "depthbench with cmake --install, or set DEPTHBENCH_DATA_DIR to a folder that holds shaders/ and shared/",
      looked.empty() ? std::string("any known place") : fmt::format("{}", fmt::join(looked, ", "))));
}

Expected<fs::path> DataPath(std::string_view relative) {
  DB_ASSIGN_OR_RETURN(const DataFolder folder, FindDataFolder());
  return folder.root / relative;
}

fs::path UserDataFolder() {
  if (const char* xdg = std::getenv("XDG_DATA_HOME"); xdg != nullptr && *xdg == '/') {
    return fs::path(xdg) / "depthbench";
  }
  const char* home = std::getenv("HOME");
  return fs::path(home != nullptr && *home != '\0' ? home : ".") / ".local" / "share" / "depthbench";
}

}  // namespace depthbench
