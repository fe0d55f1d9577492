# The installed program runs without the source tree: cmake --install into a
# fresh prefix, then, from a folder outside both trees, `depthbench
# --version` must find its data folder under the prefix (not the build
# tree), and `run` and `report` must work on both backends.
#
#   cmake -DBUILD_DIR=... -DWORK=... -P tests/install_test.cmake

foreach(required BUILD_DIR WORK)
  if(NOT DEFINED ${required})
    message(FATAL_ERROR "pass -D${required}=...")
  endif()
endforeach()

file(REMOVE_RECURSE ${WORK})
set(prefix ${WORK}/prefix)
set(elsewhere ${WORK}/elsewhere)
file(MAKE_DIRECTORY ${elsewhere})

function(run_or_fail what)
  execute_process(COMMAND ${ARGN} WORKING_DIRECTORY ${elsewhere} RESULT_VARIABLE code OUTPUT_VARIABLE out
                  ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "${what} failed (exit ${code}):\n${out}\n${err}")
  endif()
  set(output "${out}${err}" PARENT_SCOPE)
endfunction()

run_or_fail("cmake --install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
set(depthbench ${prefix}/bin/depthbench)

run_or_fail("depthbench --version" ${depthbench} --version)
if(NOT output MATCHES "data folder: ${prefix}/share/depthbench \\(install prefix\\)")
  message(FATAL_ERROR "the installed program does not use its installed data folder:\n${output}")
endif()

# Its own history, so that nothing is written outside the work folder.
run_or_fail("depthbench run" ${depthbench} run --samples 2e4 --json ${elsewhere}/run.json)
if(NOT output MATCHES "divide/reversed/d32_sfloat" OR NOT EXISTS ${elsewhere}/run.json)
  message(FATAL_ERROR "depthbench run printed no results table or wrote no results:\n${output}")
endif()
run_or_fail("depthbench report" ${depthbench} report --quick --variant divide,pq --out ${elsewhere}/report
            --history ${elsewhere}/history.sqlite)
foreach(file report.html report.md results.json)
  if(NOT EXISTS ${elsewhere}/report/${file})
    message(FATAL_ERROR "depthbench report wrote no ${file}:\n${output}")
  endif()
endforeach()
message(STATUS "installed at ${prefix}: --version, run and report work from ${elsewhere}")
file(REMOVE_RECURSE ${WORK})
