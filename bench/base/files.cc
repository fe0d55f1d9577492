#include "bench/base/files.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

namespace depthbench {

Expected<std::string> ReadFile(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return NotFound("file '" + path.string() + "' does not exist");
  if (std::filesystem::is_directory(path, ec)) {
    return InvalidArgument("'" + path.string() + "' is a directory, not a file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return IoError("cannot open '" + path.string() + "': " + std::strerror(errno));
  std::ostringstream content;
  content << in.rdbuf();
  if (in.bad()) return IoError("cannot read '" + path.string() + "'");
  return content.str();
}

Status WriteFileAtomically(const std::filesystem::path& path, std::string_view content) {
  const std::filesystem::path target = path.empty() ? path : std::filesystem::absolute(path);
  if (target.empty() || !target.has_filename()) return InvalidArgument("no output file name given");
  std::error_code ec;
  const std::filesystem::path dir = target.parent_path();
  if (!std::filesystem::is_directory(dir, ec)) {
    return IoError("cannot write '" + path.string() + "': directory '" + dir.string() + "' does not exist");
  }
  if (std::filesystem::is_directory(target, ec)) {
    return IoError("cannot write '" + path.string() + "': it is a directory");
  }
  const std::filesystem::path temp = dir / ("." + target.filename().string() + ".tmp." + std::to_string(::getpid()));
  std::FILE* f = std::fopen(temp.c_str(), "wb");
  if (f == nullptr) return IoError("cannot write '" + path.string() + "': " + std::strerror(errno));
  bool ok = std::fwrite(content.data(), 1, content.size(), f) == content.size();
  ok = (std::fflush(f) == 0) && ok;
  ok = (::fsync(::fileno(f)) == 0) && ok;
  ok = (std::fclose(f) == 0) && ok;
  if (!ok) {
    std::filesystem::remove(temp, ec);
    return IoError("cannot write '" + path.string() + "': " + std::strerror(errno));
  }
  std::filesystem::rename(temp, target, ec);
  if (ec) {
    std::filesystem::remove(temp, ec);
    return IoError("cannot write '" + path.string() + "': " + ec.message());
  }
  return Status::Ok();
}

}  // namespace depthbench
