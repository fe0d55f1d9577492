#include "bench/base/interrupt.h"

#include <signal.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <csignal>
#include <cstring>

namespace depthbench {
namespace {

std::atomic<int> g_signal{0};

// Paths of the temporary files being written, fixed-size so that the
// handler touches no allocator. A slot is claimed by storing 1 in `state`,
// filled, then published by storing 2.
constexpr int kSlots = 8;
constexpr std::size_t kPathMax = 4096;
struct Slot {
  std::atomic<int> state{0};
  std::array<char, kPathMax> path{};
};
std::array<Slot, kSlots> g_slots;

void OnSignal(int signal) {
  int expected = 0;
  if (g_signal.compare_exchange_strong(expected, signal)) return;  // the first: raise the flag only
  // The second: remove what is half written and end with the signal's status.
  for (Slot& slot : g_slots) {
    if (slot.state.load() == 2) ::unlink(slot.path.data());
  }
  ::signal(signal, SIG_DFL);
  ::raise(signal);
}

}  // namespace

void InstallInterruptHandlers() {
  struct sigaction action {};
  action.sa_handler = OnSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  ::sigaction(SIGINT, &action, nullptr);
  ::sigaction(SIGTERM, &action, nullptr);
}

bool Interrupted() { return g_signal.load(std::memory_order_relaxed) != 0; }

int InterruptSignal() { return g_signal.load(); }

Status InterruptedError(const std::string& what_was_kept) {
  const int signal = InterruptSignal();
  std::string message = std::string("interrupted by ") + (signal == SIGTERM ? "SIGTERM" : "SIGINT");
  if (!what_was_kept.empty()) message += "; " + what_was_kept;
  return Status(StatusCode::kInterrupted, message);
}

namespace {
std::atomic<bool> g_abandoned{false};
}  // namespace

void NoteAbandonedThread() { g_abandoned.store(true); }

bool AbandonedThreads() { return g_abandoned.load(); }

TemporaryFileGuard::TemporaryFileGuard(const std::filesystem::path& path) {
  const std::string& text = path.native();
  if (text.size() >= kPathMax) return;
  for (int i = 0; i < kSlots; ++i) {
    int expected = 0;
    if (!g_slots[i].state.compare_exchange_strong(expected, 1)) continue;
    std::memcpy(g_slots[i].path.data(), text.c_str(), text.size() + 1);
    g_slots[i].state.store(2);
    slot_ = i;
    return;
  }
}

TemporaryFileGuard::~TemporaryFileGuard() {
  if (slot_ >= 0) g_slots[slot_].state.store(0);
}

}  // namespace depthbench
