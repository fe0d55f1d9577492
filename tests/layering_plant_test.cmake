# Proves that the layering check can fail: on a copy of the bench's sources
# it must pass as they are, then fail, naming the file and the include, once
# a low layer includes a header from the top (base/status.h including the
# command line's app.h).
#
#   cmake -DLAYER_MAP=... -DROOT=... -DWORK=... -DCHECK=cmake/CheckLayers.cmake -P tests/layering_plant_test.cmake

foreach(required LAYER_MAP ROOT WORK CHECK)
  if(NOT DEFINED ${required})
    message(FATAL_ERROR "pass -D${required}=...")
  endif()
endforeach()

file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
file(COPY ${ROOT}/bench ${ROOT}/shared DESTINATION ${WORK})

function(run_check out_code out_text)
  execute_process(COMMAND ${CMAKE_COMMAND} -DLAYER_MAP=${LAYER_MAP} -DROOT=${WORK} -P ${CHECK}
                  RESULT_VARIABLE code OUTPUT_VARIABLE text ERROR_VARIABLE text)
  set(${out_code} ${code} PARENT_SCOPE)
  set(${out_text} "${text}" PARENT_SCOPE)
endfunction()

run_check(code text)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "the unplanted copy should pass the check:\n${text}")
endif()

file(APPEND ${WORK}/bench/base/status.h "\n#include \"bench/cli/app.h\"\n")
run_check(code text)
if(code EQUAL 0)
  message(FATAL_ERROR "the check passed a copy where bench/base/status.h includes bench/cli/app.h:\n${text}")
endif()
if(NOT text MATCHES "bench/base/status.h includes bench/cli/app.h: layer 'base' may use base, not 'cli'")
  message(FATAL_ERROR "the check failed without naming the planted include:\n${text}")
endif()
message(STATUS "the planted upward include fails the check, as it must")
file(REMOVE_RECURSE ${WORK})
