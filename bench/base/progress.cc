#include "bench/base/progress.h"

#include <cstdio>

#include <fmt/format.h>

namespace depthbench {

Progress::Progress(std::string stage, bool terminal)
    : stage_(std::move(stage)), terminal_(terminal), start_(std::chrono::steady_clock::now()), last_(start_) {}

Progress::~Progress() {
  if (open_) std::fputs("\n", stderr);
}

void Progress::Update(double fraction, const std::string& detail) {
  if (!terminal_) return;
  auto now = std::chrono::steady_clock::now();
  if (open_ && now - last_ < std::chrono::milliseconds(100) && fraction < 1.0) return;
  last_ = now;
  double elapsed = std::chrono::duration<double>(now - start_).count();
  std::string left =
      fraction > 0.0 && fraction < 1.0 ? fmt::format(", {:.0f} s left", elapsed * (1.0 - fraction) / fraction) : "";
  std::fputs(fmt::format("\r\x1b[K[{}] {:3.0f}% {}{}", stage_, 100.0 * fraction, detail, left).c_str(), stderr);
  std::fflush(stderr);
  open_ = true;
}

void Progress::Finish(const std::string& summary) {
  double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::string line = fmt::format("[{}] {} ({:.1f} s)\n", stage_, summary, elapsed);
  std::fputs(terminal_ && open_ ? ("\r\x1b[K" + line).c_str() : line.c_str(), stderr);
  open_ = false;
}

}  // namespace depthbench
