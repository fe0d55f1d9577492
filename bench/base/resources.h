// Where depthbench finds the files it ships with, so that a built, packed
// or installed binary runs from anywhere: the shaders it compiles at run
// time (shaders/, with the shared/ headers they include beside them), the
// report page's template and plotting library (reports/), the committed
// speed files (reports/speed/), the example scenes (scenes/) and the fuzz
// seed corpus (fuzz/corpus/).
//
// The data folder is the first of these that holds shaders/compute_pass.glsl:
//   1. $DEPTHBENCH_DATA_DIR, when set (then it must hold them);
//   2. PREFIX/share/depthbench, for a binary at PREFIX/bin/depthbench
//      (what `cmake --install` and bench/tools/package_for_device.sh lay out);
//   3. the source tree the binary was built from, for a binary that runs
//      from its own build tree (so that an edited shader needs no rebuild).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "bench/base/status.h"

namespace depthbench {

struct DataFolder {
  std::filesystem::path root;
  std::string found_by;  // "DEPTHBENCH_DATA_DIR", "install prefix", "build tree"
};

// The data folder, or NotFound naming the places looked in.
Expected<DataFolder> FindDataFolder();

// `relative` (e.g. "shaders", "reports/report_template.html") inside the
// data folder.
Expected<std::filesystem::path> DataPath(std::string_view relative);

// Where depthbench keeps what it writes for a user across runs (the report
// history): $XDG_DATA_HOME/depthbench, else ~/.local/share/depthbench.
std::filesystem::path UserDataFolder();

// The running program's own path (/proc/self/exe).
std::filesystem::path ExecutablePath();

}  // namespace depthbench
