#include "bench/base/environment.h"

#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>

namespace depthbench {

namespace {

// What a shell command prints on stdout, without trailing newlines.
std::string OutputOf(const std::string& command) {
  std::FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return "";
  std::array<char, 64> buffer{};
  std::string out;
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) out += buffer.data();
  ::pclose(pipe);
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out;
}

}  // namespace

std::string CurrentCommit() {
  if (const char* env = std::getenv("DEPTHBENCH_COMMIT")) return env;
  const std::string git = std::string("git -C '") + DEPTHBENCH_SOURCE_DIR + "' ";
  const std::string commit = OutputOf(git + "rev-parse --short=12 HEAD 2>/dev/null");
  if (commit.empty()) return "unknown";
  // Uncommitted changes to tracked files: the results are not the
  // commit's (the same rule as bench/tools/package_for_device.sh).
  const bool modified = !OutputOf(git + "status --porcelain --untracked-files=no 2>/dev/null").empty();
  return modified ? commit + "-modified" : commit;
}

std::string CurrentTimeUtc() {
  std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  ::gmtime_r(&now, &utc);
  std::array<char, 32> text{};
  std::strftime(text.data(), text.size(), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text.data();
}

std::string HostName() {
  std::array<char, 256> name{};
  if (::gethostname(name.data(), name.size() - 1) != 0) return "unknown";
  return name.data();
}

}  // namespace depthbench
