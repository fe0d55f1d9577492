// Reading and writing whole files. Writes are atomic: the content goes to a
// temporary file beside the target, which is then renamed over it, so an
// interrupted run never leaves a half-written file.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "bench/base/status.h"

namespace depthbench {

Expected<std::string> ReadFile(const std::filesystem::path& path);
Status WriteFileAtomically(const std::filesystem::path& path, std::string_view content);

}  // namespace depthbench
