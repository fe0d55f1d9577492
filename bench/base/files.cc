#include "bench/base/files.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include <fmt/format.h>

#include "bench/base/interrupt.h"

namespace depthbench {
namespace {

namespace fs = std::filesystem;

// Linux follows at most 40 symbolic links in one path (MAXSYMLINKS); more
// is a loop.
constexpr int kMostLinks = 40;

// What a file that is not a regular one is, for messages.
const char* KindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a named pipe (FIFO)";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISREG(mode)) return "a file";
  return "a special file";
}

std::string ByteSize(std::uintmax_t bytes) {
  if (bytes < 1024) return fmt::format("{} bytes", bytes);
  const double b = static_cast<double>(bytes);
  if (bytes < (std::uintmax_t{1} << 20)) return fmt::format("{:.1f} KiB", b / 1024.0);
  if (bytes < (std::uintmax_t{1} << 30)) return fmt::format("{:.1f} MiB", b / (1024.0 * 1024.0));
  return fmt::format("{:.1f} GiB", b / (1024.0 * 1024.0 * 1024.0));
}

// stat() with links followed; a failure says why, naming the path as `name`
// ("file 'x'", "directory 'x'").
Status StatFollowingLinks(const fs::path& path, const std::string& name, struct stat& st) {
  if (::stat(path.c_str(), &st) == 0) return Status::Ok();
  const int error = errno;
  if (error == ELOOP) return InvalidArgument(fmt::format("'{}' is a loop of symbolic links", path.string()));
  if (error == ENOENT) {
    struct stat link {};
    std::error_code ec;
    if (::lstat(path.c_str(), &link) == 0 && S_ISLNK(link.st_mode)) {
      return NotFound(fmt::format("'{}' is a symbolic link to '{}', which does not exist", path.string(),
                                  fs::read_symlink(path, ec).string()));
    }
    return NotFound(fmt::format("{} does not exist", name));
  }
  if (error == ENOTDIR) return NotFound(fmt::format("{} does not exist (a part of its path is a file)", name));
  return IoError(fmt::format("cannot read '{}': {}", path.string(), std::strerror(error)));
}

Status CheckRegular(const fs::path& path, const struct stat& st, std::uintmax_t max_bytes) {
  if (S_ISDIR(st.st_mode)) return InvalidArgument(fmt::format("'{}' is a directory, not a file", path.string()));
  if (!S_ISREG(st.st_mode)) {
    return InvalidArgument(fmt::format("'{}' is {}, not a regular file", path.string(), KindOf(st.st_mode)));
  }
  const auto size = static_cast<std::uintmax_t>(st.st_size);
  if (size > max_bytes) {
    return InvalidArgument(fmt::format("'{}' is {}; files of this kind are read up to {}", path.string(),
                                       ByteSize(size), ByteSize(max_bytes)));
  }
  return Status::Ok();
}

bool WriteAll(int fd, std::string_view content) {
  while (!content.empty()) {
    const ssize_t written = ::write(fd, content.data(), content.size());
    if (written < 0 && errno == EINTR) continue;
    if (written <= 0) return false;
    content.remove_prefix(static_cast<std::size_t>(written));
  }
  return true;
}

Status WriteToStandardOutput(std::string_view content) {
  const bool ok = std::fwrite(content.data(), 1, content.size(), stdout) == content.size();
  if (std::fflush(stdout) != 0 || !ok) {
    return IoError(fmt::format("cannot write to standard output ('-'): {}", std::strerror(errno)));
  }
  return Status::Ok();
}

}  // namespace

Status CheckReadableFile(const fs::path& path, std::uintmax_t max_bytes, const std::string& what) {
  struct stat st {};
  DB_RETURN_IF_ERROR(StatFollowingLinks(path, fmt::format("{} '{}'", what, path.string()), st));
  return CheckRegular(path, st, max_bytes);
}

Status CheckDirectory(const fs::path& path, const std::string& what) {
  struct stat st {};
  DB_RETURN_IF_ERROR(StatFollowingLinks(path, fmt::format("{} '{}'", what, path.string()), st));
  if (S_ISDIR(st.st_mode)) return Status::Ok();
  return InvalidArgument(fmt::format("{} '{}' is {}, not a directory", what, path.string(), KindOf(st.st_mode)));
}

Expected<std::string> ReadFile(const fs::path& path, std::uintmax_t max_bytes, const std::string& what) {
  DB_RETURN_IF_ERROR(CheckReadableFile(path, max_bytes, what));
  // O_NONBLOCK: a FIFO put in the file's place since the check does not
  // block the open (fstat below then refuses it).
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return IoError(fmt::format("cannot open '{}': {}", path.string(), std::strerror(errno)));
  struct stat st {};
  Status regular = ::fstat(fd, &st) == 0
                       ? CheckRegular(path, st, max_bytes)
                       : IoError(fmt::format("cannot read '{}': {}", path.string(), std::strerror(errno)));
  std::string content;
  if (regular.ok()) content.reserve(static_cast<std::size_t>(st.st_size));
  char buffer[1 << 16];
  while (regular.ok()) {
    const ssize_t got = ::read(fd, buffer, sizeof buffer);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) regular = IoError(fmt::format("cannot read '{}': {}", path.string(), std::strerror(errno)));
    if (got <= 0) break;
    content.append(buffer, static_cast<std::size_t>(got));
    // A file that grows while it is read is held to the same limit.
    if (content.size() > max_bytes) {
      regular = InvalidArgument(fmt::format("'{}' grew past {} while it was read", path.string(), ByteSize(max_bytes)));
    }
  }
  ::close(fd);
  if (!regular.ok()) return regular;
  return content;
}

Expected<fs::path> OutputTarget(const fs::path& path) {
  std::error_code ec;
  const fs::path given = fs::absolute(path, ec);
  if (ec || path.empty() || !path.has_filename()) {
    return InvalidArgument(fmt::format("'{}' is not a usable file name", path.string()));
  }
  fs::path target = given;
  for (int links = 0;; ++links) {
    struct stat st {};
    if (::lstat(target.c_str(), &st) != 0) {
      // A file to create, or a folder that is missing (the caller says so).
      if (errno == ENOENT || errno == ENOTDIR) return target;
      if (errno == ELOOP) return InvalidArgument(fmt::format("'{}' is a loop of symbolic links", path.string()));
      return IoError(fmt::format("cannot write '{}': {}", path.string(), std::strerror(errno)));
    }
    if (S_ISREG(st.st_mode)) return target;
    if (!S_ISLNK(st.st_mode)) {
      const std::string name = target == given
                                   ? fmt::format("'{}'", path.string())
                                   : fmt::format("'{}' (where '{}' points)", target.string(), path.string());
      return InvalidArgument(fmt::format("{} is {}, not a regular file", name, KindOf(st.st_mode)));
    }
    if (links == kMostLinks) return InvalidArgument(fmt::format("'{}' is a loop of symbolic links", path.string()));
    const fs::path next = fs::read_symlink(target, ec);
    if (ec) return IoError(fmt::format("cannot write '{}': {}", path.string(), ec.message()));
    target = next.is_absolute() ? next : target.parent_path() / next;
  }
}

Status WriteFileAtomically(const fs::path& path, std::string_view content) {
  if (path == kStandardOutputName) return WriteToStandardOutput(content);
  DB_ASSIGN_OR_RETURN(const fs::path target, OutputTarget(path));
  const fs::path dir = target.parent_path();
  DB_RETURN_IF_ERROR(CheckDirectory(dir, "directory").WithContext(fmt::format("cannot write '{}'", path.string())));
  // An existing file keeps its permission bits.
  struct stat existing {};
  const bool exists = ::stat(target.c_str(), &existing) == 0;
  const fs::path temp = dir / ("." + target.filename().string() + ".tmp." + std::to_string(::getpid()));
  // A first SIGINT or SIGTERM lets this write finish; a second removes the
  // temporary file before the process ends.
  const TemporaryFileGuard guard(temp);
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, exists ? 0600 : 0666);
  if (fd < 0) return IoError(fmt::format("cannot write '{}': {}", path.string(), std::strerror(errno)));
  int error = 0;
  if (!WriteAll(fd, content) || (exists && ::fchmod(fd, existing.st_mode & 07777) != 0) || ::fsync(fd) != 0) {
    error = errno;
  }
  if (::close(fd) != 0 && error == 0) error = errno;
  std::error_code ec;
  if (error != 0) {
    fs::remove(temp, ec);
    return IoError(fmt::format("cannot write '{}': {}", path.string(), std::strerror(error)));
  }
  fs::rename(temp, target, ec);
  if (ec) {
    const std::string why = ec.message();
    fs::remove(temp, ec);
    return IoError(fmt::format("cannot write '{}': {}", path.string(), why));
  }
  return Status::Ok();
}

Status AppendToFile(const fs::path& path, std::string_view content) {
  DB_ASSIGN_OR_RETURN(const fs::path target, OutputTarget(path));
  const int fd = ::open(target.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC | O_NOFOLLOW, 0666);
  if (fd < 0) return IoError(fmt::format("cannot add to '{}': {}", path.string(), std::strerror(errno)));
  const int error = WriteAll(fd, content) ? 0 : errno;
  if (::close(fd) != 0 || error != 0) {
    return IoError(fmt::format("cannot add to '{}': {}", path.string(), std::strerror(error != 0 ? error : errno)));
  }
  return Status::Ok();
}

}  // namespace depthbench
