// What the fuzz targets share.
#pragma once

#include <cstdlib>

#include "bench/base/status.h"

namespace depthbench::fuzzing {

// Whether a reader accepted its input; aborts (a finding for libFuzzer)
// when it refused without a message, which a user could not act on.
template <class T>
bool Accepted(const Expected<T>& read) {
  if (read.ok()) return true;
  if (read.status().message().empty()) std::abort();
  return false;
}

}  // namespace depthbench::fuzzing
