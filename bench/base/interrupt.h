// Stopping on SIGINT and SIGTERM without losing what was done.
//
// The first signal only raises a flag: long work polls Interrupted() between
// batches, finishes the file it is writing, writes what it measured (marked
// as partial) and returns InterruptedError(), which main turns into exit
// 128 + signal (130 for Ctrl-C). A second signal means "now": the temporary
// files being written are removed and the process ends at once.
#pragma once

#include <filesystem>

#include "bench/base/status.h"

namespace depthbench {

// Installs the handlers; safe to call more than once.
void InstallInterruptHandlers();

// True once SIGINT or SIGTERM has arrived.
bool Interrupted();

// The signal that arrived (0 when none).
int InterruptSignal();

// The status that long work returns when it stops early: "interrupted by
// SIGINT" and exit code 128 + signal.
Status InterruptedError(const std::string& what_was_kept);

// Work that cannot be stopped (a glslang compile past its time limit) is
// given up on while its thread runs: the program must then end without
// running static destructors under it (main does, when this was noted).
void NoteAbandonedThread();
bool AbandonedThreads();

// A temporary file in the course of being written: while the guard lives, a
// second signal removes the file before the process ends. At most a few are
// live at once (one per writer); more are written but not guarded.
class TemporaryFileGuard {
 public:
  explicit TemporaryFileGuard(const std::filesystem::path& path);
  ~TemporaryFileGuard();
  TemporaryFileGuard(const TemporaryFileGuard&) = delete;
  TemporaryFileGuard& operator=(const TemporaryFileGuard&) = delete;

 private:
  int slot_ = -1;
};

}  // namespace depthbench
