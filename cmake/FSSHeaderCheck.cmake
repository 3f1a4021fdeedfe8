# fss_add_header_check(<target> BASE_DIR <dir> HEADERS <h>... LIBS <lib>...)
# "Every public header compiles on its own": one generated translation unit per header, which includes
# only that header (twice, so a missing include guard fails too), compiled with FSS's warning flags into
# an object library. Nothing links it: the build fails when a header misses an include of its own.
function(fss_add_header_check target)
  cmake_parse_arguments(ARG "" "BASE_DIR" "HEADERS;LIBS" ${ARGN})
  set(sources)
  foreach(header ${ARG_HEADERS})
    file(RELATIVE_PATH rel "${ARG_BASE_DIR}" "${header}")
    string(MAKE_C_IDENTIFIER "${rel}" id)
    set(tu "${CMAKE_CURRENT_BINARY_DIR}/${target}/${id}.cpp")
    file(CONFIGURE OUTPUT "${tu}" CONTENT "// Generated: ${rel} must compile on its own.\n#include <${rel}>\n#include <${rel}>\n" @ONLY)
    list(APPEND sources "${tu}")
  endforeach()
  add_library(${target} OBJECT ${sources})
  target_link_libraries(${target} PRIVATE ${ARG_LIBS})
  fss_target_warnings(${target})
  # Only whether it compiles matters: no optimisation or debug information (parsing dominates anyway,
  # ~10 s per header that includes CGAL).
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE -O0 -g0)
  endif()
endfunction()
