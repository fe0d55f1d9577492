// What the fuzz targets share.
#pragma once

#include <cstdlib>
#include <string>

#include <nlohmann/json.hpp>

#include "bench/base/status.h"
#include "bench/pipeline/cells.h"

namespace depthbench::fuzzing {

// Whether a reader accepted its input; aborts (a finding for libFuzzer)
// when it refused without a message, which a user could not act on.
template <class T>
bool Accepted(const Expected<T>& read) {
  if (read.ok()) return true;
  if (read.status().message().empty()) std::abort();
  return false;
}

// What the bench reads, it writes back in full: `value` (as a reader
// accepted it) written, read back and written again gives the same text.
// A member that the writer leaves out or the reader forgets comes back
// with another value, or not at all; aborts then.
template <class T>
void CheckRoundTrip(const T& value, nlohmann::json (*write)(const T&),
                    Expected<T> (*read)(const nlohmann::json&, const std::string&, const Catalogue&)) {
  const nlohmann::json written = write(value);
  const Expected<T> again = read(written, "written", Catalogue::BuiltIn());
  if (!again.ok() || write(*again).dump() != written.dump()) std::abort();
}

}  // namespace depthbench::fuzzing
