// The sanitized stage of .ci/run (ASan and UBSan, tests/CMakeLists.txt)
// looks for memory and undefined-behaviour errors on the program's code
// paths; the release stage checks the figures. A test whose paths another
// test of the same binary already runs, and which adds only figures over
// larger runs (or the layout of text), is skipped under the sanitizers:
// there it would cost a minute and find nothing the other does not.
#ifndef DEPTHBENCH_TESTS_SANITIZED_STAGE_H_
#define DEPTHBENCH_TESTS_SANITIZED_STAGE_H_

#include <gtest/gtest.h>

namespace depthbench::testing {

// ASan and UBSan always go together there (CMakeLists.txt).
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif
#elif defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif

}  // namespace depthbench::testing

// First statement of such a test; WHERE names the test that runs its paths.
#define DEPTHBENCH_FIGURES_ONLY(WHERE)                                                        \
  if (::depthbench::testing::kSanitized) {                                                    \
    GTEST_SKIP() << "figures only: checked in the release stage; " WHERE " runs these paths"; \
  }

#endif  // DEPTHBENCH_TESTS_SANITIZED_STAGE_H_
