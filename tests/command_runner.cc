#include "tests/command_runner.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace depthbench::testing {

CommandResult RunDepthbench(const std::vector<std::string>& args) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("depthbench_cmd_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path out_path = dir / "out", err_path = dir / "err";
  const std::string program = std::string(DEPTHBENCH_BINARY_DIR) + "/bench/depthbench";
  CommandResult result;
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
  int status = 0;
  ::waitpid(pid, &status, 0);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  auto slurp = [](const fs::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  };
  result.out = slurp(out_path);
  result.err = slurp(err_path);
  fs::remove_all(dir);
  return result;
}

std::string MakeTempDir(const std::string& name) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("depthbench_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
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
