#include "tests/command_runner.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

namespace depthbench::testing {

pid_t StartDepthbench(const std::vector<std::string>& args, const std::string& out_path, const std::string& err_path) {
  const std::string program = std::string(DEPTHBENCH_BINARY_DIR) + "/bench/depthbench";
  pid_t pid = ::fork();
  if (pid == 0) {
    std::freopen(out_path.c_str(), "w", stdout);
    std::freopen(err_path.c_str(), "w", stderr);
    std::vector<char*> argv{const_cast<char*>(program.c_str())};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(program.c_str(), argv.data());
    std::_Exit(127);
  }
  return pid;
}

int WaitForExit(pid_t pid, double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  int status = 0;
  while (true) {
    const pid_t done = ::waitpid(pid, &status, seconds > 0 ? WNOHANG : 0);
    if (done == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    if (done < 0) return -1;
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

StartedCommand StartDepthbench(const std::vector<std::string>& args) {
  namespace fs = std::filesystem;
  // One folder per command, so that commands running at once keep their
  // outputs apart.
  static int started = 0;
  const fs::path dir =
      fs::temp_directory_path() / ("depthbench_cmd_" + std::to_string(::getpid()) + "_" + std::to_string(started++));
  fs::create_directories(dir);
  return {StartDepthbench(args, (dir / "out").string(), (dir / "err").string()), dir.string()};
}

CommandResult FinishDepthbench(const StartedCommand& started) {
  namespace fs = std::filesystem;
  CommandResult result;
  result.exit_code = WaitForExit(started.pid, 0);
  const fs::path dir = started.dir;
  result.out = ReadText((dir / "out").string());
  result.err = ReadText((dir / "err").string());
  fs::remove_all(dir);
  return result;
}

CommandResult RunDepthbench(const std::vector<std::string>& args) { return FinishDepthbench(StartDepthbench(args)); }

namespace {

// The directories MakeTempDir made, removed when the test program ends
// (by the process that made them: a forked child leaves them alone), or
// kept for a look at a failure with DEPTHBENCH_KEEP_TEST_DIRS=1.
class TempDirs {
 public:
  ~TempDirs() {
    if (::getpid() != owner_ || std::getenv("DEPTHBENCH_KEEP_TEST_DIRS") != nullptr) return;
    std::error_code ignored;
    for (const std::string& dir : dirs_) std::filesystem::remove_all(dir, ignored);
  }
  void Add(std::string dir) {
    const std::lock_guard<std::mutex> lock(mutex_);
    dirs_.push_back(std::move(dir));
  }

 private:
  pid_t owner_ = ::getpid();
  std::mutex mutex_;
  std::vector<std::string> dirs_;
};
TempDirs temp_dirs;

}  // namespace

std::string MakeTempDir(const std::string& name) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("depthbench_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  temp_dirs.Add(dir.string());
  return dir.string();
}

void CopyShaderSources(const std::string& dir) {
  namespace fs = std::filesystem;
  fs::copy(std::string(DEPTHBENCH_SOURCE_DIR) + "/shaders", dir + "/shaders", fs::copy_options::recursive);
  fs::copy(std::string(DEPTHBENCH_SOURCE_DIR) + "/shared", dir + "/shared", fs::copy_options::recursive);
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

bool ReplaceInFile(const std::string& path, const std::string& from, const std::string& to) {
  std::string s = ReadText(path);
  const auto at = s.find(from);
  if (at == std::string::npos) return false;
  s.replace(at, from.size(), to);
  std::ofstream(path) << s;
  return true;
}

}  // namespace depthbench::testing
