#include "bench/base/progress.h"

#include <cstdio>
#include <cstdlib>

#include <fmt/format.h>

namespace depthbench {

Progress::Progress(std::string stage, bool terminal, bool quiet)
    : stage_(std::move(stage)), terminal_(terminal), quiet_(quiet), start_(std::chrono::steady_clock::now()), last_(start_) {}

Progress::~Progress() {
  if (open_) std::fputs("\n", stderr);
}

namespace {

// How often a log (stderr not a terminal: CI) gets a progress line: often
// enough that a job log never looks hung, rarely enough to stay short.
// DEPTHBENCH_PROGRESS_SECONDS overrides it (tests use a fraction of a second).
std::chrono::duration<double> LogInterval() {
  static const double seconds = [] {
    const char* text = std::getenv("DEPTHBENCH_PROGRESS_SECONDS");
    char* end = nullptr;
    const double value = text != nullptr ? std::strtod(text, &end) : 0.0;
    return text != nullptr && end != text && *end == '\0' && value > 0.0 ? value : 10.0;
  }();
  return std::chrono::duration<double>(seconds);
}

}  // namespace

void Progress::Update(double fraction, const std::string& detail) {
  if (quiet_) return;
  auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const std::string left =
      fraction > 0.0 && fraction < 1.0 ? fmt::format(", {:.0f} s left", elapsed * (1.0 - fraction) / fraction) : "";
  if (!terminal_) {
    // A plain line now and then; none for work that ends within the interval.
    if (now - last_ < LogInterval() || fraction >= 1.0) return;
    last_ = now;
    std::fputs(fmt::format("[{}] {:3.0f}% {}{}\n", stage_, 100.0 * fraction, detail, left).c_str(), stderr);
    std::fflush(stderr);
    return;
  }
  if (open_ && now - last_ < std::chrono::milliseconds(100) && fraction < 1.0) return;
  last_ = now;
  std::fputs(fmt::format("\r\x1b[K[{}] {:3.0f}% {}{}", stage_, 100.0 * fraction, detail, left).c_str(), stderr);
  std::fflush(stderr);
  open_ = true;
}

void Progress::Finish(const std::string& summary) {
  if (quiet_) return;
  double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::string line = fmt::format("[{}] {} ({:.1f} s)\n", stage_, summary, elapsed);
  std::fputs(terminal_ && open_ ? ("\r\x1b[K" + line).c_str() : line.c_str(), stderr);
  open_ = false;
}

}  // namespace depthbench
