# "Every public header compiles on its own": one generated translation unit per header, which includes
# only that header (twice, so a missing include guard fails too), compiled with FSS's warning flags into
# an object library. Nothing links it: the build fails when a header misses an include of its own.
#
# fss_add_header_check(<target> BASE_DIR <dir> HEADERS <h>... LIBS <lib>...)
#   checks the headers of one layer (core, render, widgets). Headers that include <fss/mesh.h>, directly or
#   through other FSS headers, are not compiled here but collected for fss_finish_header_checks().
# fss_finish_header_checks(<target> INCLUDE_ROOTS <dir>...)
#   compiles the collected headers in one object library whose precompiled header holds exactly the
#   third-party includes of fss/mesh.h (CGAL's kernel and Surface_mesh, Eigen). Parsing those is ~80 % of
#   such a header's cost (measured: fss/stitch.h 16.8 s alone, 3.5 s with the precompiled header, which
#   costs ~40 s once). The check keeps its strength: each of these headers includes fss/mesh.h and so those
#   same third-party headers anyway; the precompiled header only has them parsed first. A header that misses
#   an include of its own (an FSS header, a standard header mesh.h does not bring, Qt, VTK) still fails.

# The FSS headers a header includes ("fss/..." or <fss/...>), resolved against the include roots.
function(_fss_direct_fss_includes header roots out)
  file(STRINGS "${header}" lines REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"]fss/")
  set(found)
  foreach(line IN LISTS lines)
    if(line MATCHES "[<\"](fss/[^>\"]+)[>\"]")
      foreach(root IN LISTS roots)
        if(EXISTS "${root}/${CMAKE_MATCH_1}")
          list(APPEND found "${root}/${CMAKE_MATCH_1}")
          break()
        endif()
      endforeach()
    endif()
  endforeach()
  set(${out} "${found}" PARENT_SCOPE)
endfunction()

# TRUE when <header> is fss/mesh.h or includes it, directly or through other FSS headers.
function(_fss_includes_mesh header roots out)
  set(todo "${header}")
  set(seen)
  while(todo)
    list(POP_FRONT todo current)
    if(current IN_LIST seen)
      continue()
    endif()
    list(APPEND seen "${current}")
    if(current MATCHES "/fss/mesh\\.h$")
      set(${out} TRUE PARENT_SCOPE)
      return()
    endif()
    _fss_direct_fss_includes("${current}" "${roots}" next)
    list(APPEND todo ${next})
  endwhile()
  set(${out} FALSE PARENT_SCOPE)
endfunction()

function(_fss_header_check_tu target base_dir header out)
  file(RELATIVE_PATH rel "${base_dir}" "${header}")
  string(MAKE_C_IDENTIFIER "${rel}" id)
  set(tu "${CMAKE_CURRENT_BINARY_DIR}/${target}/${id}.cpp")
  file(CONFIGURE OUTPUT "${tu}" CONTENT "// Generated: ${rel} must compile on its own.\n#include <${rel}>\n#include <${rel}>\n" @ONLY)
  set(${out} "${tu}" PARENT_SCOPE)
endfunction()

function(_fss_header_check_target target)
  fss_target_warnings(${target})
  # Only whether it compiles matters: no optimisation or debug information (parsing dominates anyway).
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE -O0 -g0)
  endif()
endfunction()

function(fss_add_header_check target)
  cmake_parse_arguments(ARG "" "BASE_DIR" "HEADERS;LIBS;INCLUDE_ROOTS" ${ARGN})
  set(roots ${ARG_INCLUDE_ROOTS} "${ARG_BASE_DIR}")
  set(sources)
  foreach(header ${ARG_HEADERS})
    _fss_includes_mesh("${header}" "${roots}" heavy)
    if(heavy)
      _fss_header_check_tu(headers_mesh "${ARG_BASE_DIR}" "${header}" tu)
      set_property(GLOBAL APPEND PROPERTY FSS_HEADER_CHECK_MESH_SOURCES "${tu}")
    else()
      _fss_header_check_tu(${target} "${ARG_BASE_DIR}" "${header}" tu)
      list(APPEND sources "${tu}")
    endif()
  endforeach()
  set_property(GLOBAL APPEND PROPERTY FSS_HEADER_CHECK_MESH_LIBS ${ARG_LIBS})
  if(sources)
    add_library(${target} OBJECT ${sources})
    target_link_libraries(${target} PRIVATE ${ARG_LIBS})
    _fss_header_check_target(${target})
  endif()
endfunction()

function(fss_finish_header_checks target)
  cmake_parse_arguments(ARG "" "MESH_HEADER" "" ${ARGN})
  get_property(sources GLOBAL PROPERTY FSS_HEADER_CHECK_MESH_SOURCES)
  get_property(libs GLOBAL PROPERTY FSS_HEADER_CHECK_MESH_LIBS)
  if(NOT sources)
    return()
  endif()
  list(REMOVE_DUPLICATES libs)
  # The precompiled header: fss/mesh.h's own includes other than FSS's.
  file(STRINGS "${ARG_MESH_HEADER}" lines REGEX "^[ \t]*#[ \t]*include[ \t]*<")
  set(pch)
  foreach(line IN LISTS lines)
    if(line MATCHES "<([^>]+)>")
      set(name "${CMAKE_MATCH_1}")
      if(NOT name MATCHES "^fss/")
        list(APPEND pch "<${name}>")
      endif()
    endif()
  endforeach()
  add_library(${target} OBJECT ${sources})
  target_link_libraries(${target} PRIVATE ${libs})
  _fss_header_check_target(${target})
  target_precompile_headers(${target} PRIVATE ${pch})
endfunction()
