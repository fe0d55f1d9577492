# The bench's layers: one folder under bench/ and one static library each,
# linking only the layers below it. depthbench_layer() records every layer
# with the layers it may use, so that the link graph and the include check
# (tests: layering, cmake/CheckLayers.cmake) read one and the same map.

# Warnings belong to the project's own targets, not to the whole build
# (dependencies' headers are included as system headers anyway).
option(DEPTHBENCH_WERROR "Treat the project's compiler warnings as errors (CI turns it on)" OFF)
add_library(depthbench_warnings INTERFACE)
target_compile_options(depthbench_warnings INTERFACE -Wall -Wextra)
# GCC 12 reports impossible overlaps in std::string concatenation at -O2
# (GCC bug 105329); the warning is noise there.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
  target_compile_options(depthbench_warnings INTERFACE -Wno-restrict)
endif()
if(DEPTHBENCH_WERROR)
  target_compile_options(depthbench_warnings INTERFACE -Werror)
endif()

# depthbench_layer(NAME [INTERFACE] [SOURCES file...] [DEPENDS layer...]
#                  [PUBLIC lib...] [PRIVATE lib...])
# The library depthbench_NAME from SOURCES (relative to bench/NAME/, or an
# interface library of headers alone), linking the layers in DEPENDS and
# the libraries in PUBLIC and PRIVATE. A layer may include from itself and
# from every layer it depends on, directly or through others.
function(depthbench_layer name)
  cmake_parse_arguments(ARG "INTERFACE" "" "SOURCES;DEPENDS;PUBLIC;PRIVATE" ${ARGN})
  if(ARG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "depthbench_layer(${name}): unexpected arguments ${ARG_UNPARSED_ARGUMENTS}")
  endif()
  set(target depthbench_${name})
  if(ARG_INTERFACE)
    add_library(${target} INTERFACE)
    target_include_directories(${target} INTERFACE ${PROJECT_SOURCE_DIR})
    target_link_libraries(${target} INTERFACE ${ARG_PUBLIC})
  else()
    list(TRANSFORM ARG_SOURCES PREPEND ${CMAKE_CURRENT_SOURCE_DIR}/${name}/)
    add_library(${target} STATIC ${ARG_SOURCES})
    target_include_directories(${target} PUBLIC ${PROJECT_SOURCE_DIR})
    target_link_libraries(${target} PUBLIC ${ARG_PUBLIC} PRIVATE depthbench_warnings ${ARG_PRIVATE})
  endif()
  foreach(dependency IN LISTS ARG_DEPENDS)
    get_property(known GLOBAL PROPERTY DEPTHBENCH_LAYER_NAMES)
    if(NOT dependency IN_LIST known)
      message(FATAL_ERROR "depthbench_layer(${name}): '${dependency}' is not a layer defined before it")
    endif()
    if(ARG_INTERFACE)
      target_link_libraries(${target} INTERFACE depthbench_${dependency})
    else()
      target_link_libraries(${target} PUBLIC depthbench_${dependency})
    endif()
  endforeach()
  set_property(GLOBAL APPEND PROPERTY DEPTHBENCH_LAYER_NAMES ${name})
  list(JOIN ARG_DEPENDS "," dependencies)
  set_property(GLOBAL APPEND PROPERTY DEPTHBENCH_LAYER_MAP "${name}:${dependencies}")
endfunction()

# Writes the layer map, one "layer:dependency,dependency" line each, for
# cmake/CheckLayers.cmake.
function(depthbench_write_layer_map path)
  get_property(map GLOBAL PROPERTY DEPTHBENCH_LAYER_MAP)
  list(JOIN map "\n" text)
  file(WRITE ${path} "${text}\n")
endfunction()
