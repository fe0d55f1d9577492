// Runs the depthbench program the build made, the way a user does, and
// captures its exit code and output.
#pragma once

#include <sys/types.h>

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

// Starts `depthbench args...` with stdout and stderr written to the files
// given (which may be devices: /dev/full), and returns its process id.
pid_t StartDepthbench(const std::vector<std::string>& args, const std::string& out_path, const std::string& err_path);

// Waits for a process StartDepthbench started: its exit code (128 + signal
// when a signal ended it), or -1 when it is still running after `seconds`
// (it is then killed). 0 seconds: no limit.
int WaitForExit(pid_t pid, double seconds);

// RunDepthbench in two steps, for tests that run several at once: Start
// returns as soon as the process is started, Finish waits for it and
// collects its output. Every started command must be finished once.
struct StartedCommand {
  pid_t pid = -1;
  std::string dir;  // where its stdout and stderr go until Finish reads them
};
StartedCommand StartDepthbench(const std::vector<std::string>& args);
CommandResult FinishDepthbench(const StartedCommand& started);

// A fresh empty directory under the system's temporary directory, removed
// when the test program ends (kept with DEPTHBENCH_KEEP_TEST_DIRS=1).
std::string MakeTempDir(const std::string& name);

// Copies the source tree's shaders/ and shared/ into `dir`, so that a test
// can edit them and run the edited shaders with --shaders DIR/shaders.
void CopyShaderSources(const std::string& dir);

// Replaces the first `from` by `to` in a file; false when `from` is not in it.
bool ReplaceInFile(const std::string& path, const std::string& from, const std::string& to);

// The whole text of a file ("" when it cannot be read).
std::string ReadText(const std::string& path);

}  // namespace depthbench::testing
