// Progress of long work on stderr: a self-updating line when stderr is a
// terminal; otherwise (a CI log) a plain line every ten seconds or so, and
// one when a stage ends; nothing at all when the user asked for quiet.
#pragma once

#include <chrono>
#include <string>

namespace depthbench {

class Progress {
 public:
  Progress(std::string stage, bool terminal, bool quiet = false);
  ~Progress();

  // fraction in [0, 1]; `detail` like "4.2M/10M samples, 98M/s".
  void Update(double fraction, const std::string& detail);
  // Ends the stage with a summary line (both modes).
  void Finish(const std::string& summary);

 private:
  std::string stage_;
  bool terminal_;
  bool quiet_;
  bool open_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_;
};

}  // namespace depthbench
