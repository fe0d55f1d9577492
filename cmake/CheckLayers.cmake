# Checks that every #include in the bench goes down the layers, never up.
#
#   cmake -DLAYER_MAP=build/layers.txt -DROOT=. -P cmake/CheckLayers.cmake
#
# LAYER_MAP (written by the build, cmake/DepthbenchLayers.cmake) has one
# "layer:dependency,dependency" line per layer. A file under bench/NAME/ is
# in layer NAME, a file under shared/ in layer shared. A file may include
# from its own layer and from every layer its layer depends on, directly or
# through others; anything else is reported with the file and the include, and the
# script fails. A source file in no layer's folder fails it too.

cmake_minimum_required(VERSION 3.25)
foreach(required LAYER_MAP ROOT)
  if(NOT DEFINED ${required})
    message(FATAL_ERROR "CheckLayers: pass -D${required}=...")
  endif()
endforeach()

get_filename_component(ROOT ${ROOT} ABSOLUTE)
file(STRINGS ${LAYER_MAP} lines)
set(layers "")
foreach(line IN LISTS lines)
  string(REPLACE ":" ";" parts "${line}")
  list(GET parts 0 layer)
  list(LENGTH parts n)
  set(direct_${layer} "")
  if(n GREATER 1)
    list(GET parts 1 deps)
    string(REPLACE "," ";" direct_${layer} "${deps}")
  endif()
  list(APPEND layers ${layer})
endforeach()

# Every layer a layer may use: itself and the closure of its dependencies.
# The map lists a layer after those it depends on, so one pass suffices.
foreach(layer IN LISTS layers)
  set(allowed_${layer} ${layer})
  foreach(dep IN LISTS direct_${layer})
    if(NOT DEFINED allowed_${dep})
      message(FATAL_ERROR "CheckLayers: layer '${layer}' depends on '${dep}', which is not listed before it")
    endif()
    list(APPEND allowed_${layer} ${allowed_${dep}})
  endforeach()
  list(REMOVE_DUPLICATES allowed_${layer})
endforeach()

# The layer of a path relative to ROOT, or "" when it is in none.
function(layer_of path out)
  set(result "")
  if(path MATCHES "^shared/")
    set(result shared)
  elseif(path MATCHES "^bench/([^/]+)/")
    set(result ${CMAKE_MATCH_1})
  endif()
  set(${out} ${result} PARENT_SCOPE)
endfunction()

file(GLOB_RECURSE sources RELATIVE ${ROOT} ${ROOT}/bench/*.h ${ROOT}/bench/*.cc ${ROOT}/bench/*.inc
     ${ROOT}/shared/*.h)
list(SORT sources)
set(violations "")
set(files 0)
set(includes 0)
foreach(source IN LISTS sources)
  math(EXPR files "${files} + 1")
  layer_of(${source} layer)
  if(layer STREQUAL "" OR NOT layer IN_LIST layers)
    string(APPEND violations "  ${source}: in no layer (the layers: ${layers})\n")
    continue()
  endif()
  get_filename_component(folder ${source} DIRECTORY)
  file(STRINGS ${ROOT}/${source} include_lines REGEX "^[ \t]*#[ \t]*include[ \t]*\"")
  foreach(include_line IN LISTS include_lines)
    string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*\"([^\"]+)\".*" "\\1" included "${include_line}")
    math(EXPR includes "${includes} + 1")
    # Project paths start at the root; others are relative to the file.
    if(included MATCHES "^(bench|shared)/")
      set(target ${included})
    elseif(EXISTS ${ROOT}/${folder}/${included})
      cmake_path(SET target NORMALIZE "${folder}/${included}")
    else()
      continue()
    endif()
    layer_of(${target} target_layer)
    if(NOT target_layer IN_LIST allowed_${layer})
      string(APPEND violations
             "  ${source} includes ${included}: layer '${layer}' may use ${allowed_${layer}}, not '${target_layer}'\n")
    endif()
  endforeach()
endforeach()

if(NOT violations STREQUAL "")
  message(FATAL_ERROR "layering: includes that go up or sideways\n${violations}")
endif()
message(STATUS "layering: ${files} files, ${includes} includes, all within their layers (${layers})")
