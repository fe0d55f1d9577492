// Reading and writing whole files.
//
// Reads are bounded: a file is read only when it is a regular file (after
// symbolic links) no larger than the limit its caller states, so that a
// device (/dev/zero), a FIFO or a runaway file is refused with a message
// instead of being read until memory runs out.
//
// Writes are atomic: the content goes to a temporary file beside the target,
// which is then renamed over it, so an interrupted run never leaves a
// half-written file. A symbolic link is written through (the temporary file
// goes beside the file it points to, and the link stays), an existing file
// keeps its permission bits, and a target that is not a regular file (a
// device, a FIFO, a socket) is refused rather than replaced. "-" writes to
// standard output.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "bench/base/status.h"

namespace depthbench {

// Read limits, by kind of input. Results JSON of a long sweep with the
// worst samples of every cell stays far below 1 GiB; scene TOML, shader
// sources, HTML templates, script bundles and fuzz corpus entries are
// hand-written or small generated text (the largest, vega's bundle, is
// under 1 MiB).
inline constexpr std::uintmax_t kMaxJsonFileBytes = std::uintmax_t{1} << 30;     // 1 GiB
inline constexpr std::uintmax_t kMaxSourceFileBytes = std::uintmax_t{16} << 20;  // 16 MiB

// The output name that means standard output.
inline constexpr std::string_view kStandardOutputName = "-";

// Ok when `path` names a regular file of at most `max_bytes` (symbolic links
// followed); otherwise an error that names the file and says what it is
// ("does not exist", "is a directory", "is a character device", "is a loop
// of symbolic links", "is 2.0 GiB; the limit is 1.0 GiB").
// `what` names the file where it does not exist ("shader source 'x' does
// not exist").
Status CheckReadableFile(const std::filesystem::path& path, std::uintmax_t max_bytes, const std::string& what = "file");

// Ok when `path` is a directory (links followed); otherwise an error that
// calls it `what` and says what it is ("folder 'x' does not exist", "folder
// 'x' is a file, not a directory").
Status CheckDirectory(const std::filesystem::path& path, const std::string& what);

// The whole content of a file that CheckReadableFile accepts.
Expected<std::string> ReadFile(const std::filesystem::path& path, std::uintmax_t max_bytes,
                               const std::string& what = "file");

// The file that writing to `path` replaces: `path` with its symbolic links
// followed (a dangling link names the file it would create). An error when
// that is a directory, a device, a FIFO or a socket, or a loop of links.
Expected<std::filesystem::path> OutputTarget(const std::filesystem::path& path);

// Writes `content` to `path` atomically (see above), or to standard output
// when `path` is "-"; a write that fails (a full disk) is an error.
Status WriteFileAtomically(const std::filesystem::path& path, std::string_view content);

// Adds `content` at the end of `path`, creating it if needed (a file that
// several writers add to in turn, such as a CI job's summary).
Status AppendToFile(const std::filesystem::path& path, std::string_view content);

}  // namespace depthbench
