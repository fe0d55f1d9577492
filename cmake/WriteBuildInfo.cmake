# Writes the build's identity into a C++ source (OUTPUT): the version and
# the commit of the source tree (SOURCE_DIR) at build time, with
# "-modified" when tracked files differ from it, or "unknown" outside a
# git checkout. Runs at every build (depthbench_build_info in
# bench/CMakeLists.txt) and rewrites OUTPUT only when it changes, so that
# results name the commit the binary was built from, and nothing is
# recompiled when it did not move.
#
#   cmake -DSOURCE_DIR=... -DOUTPUT=... -DVERSION=... -P cmake/WriteBuildInfo.cmake

find_package(Git QUIET)
set(commit unknown)
if(GIT_EXECUTABLE)
  execute_process(COMMAND ${GIT_EXECUTABLE} -C ${SOURCE_DIR} rev-parse --short=12 HEAD
                  OUTPUT_VARIABLE head RESULT_VARIABLE failed OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(NOT failed AND NOT head STREQUAL "")
    set(commit ${head})
    execute_process(COMMAND ${GIT_EXECUTABLE} -C ${SOURCE_DIR} status --porcelain --untracked-files=no
                    OUTPUT_VARIABLE changes OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    if(NOT changes STREQUAL "")
      set(commit "${commit}-modified")
    endif()
  endif()
endif()

set(content "// Written by cmake/WriteBuildInfo.cmake at build time; not in the source tree.
#include \"bench/base/build_info.h\"

namespace depthbench {

const char* BuildVersion() { return \"${VERSION}\"; }
const char* BuildCommit() { return \"${commit}\"; }

}  // namespace depthbench
")
if(EXISTS ${OUTPUT})
  file(READ ${OUTPUT} previous)
endif()
if(NOT previous STREQUAL content)
  file(WRITE ${OUTPUT} "${content}")
endif()
