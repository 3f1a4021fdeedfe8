# Compiler launcher, linker and warning flags for FSS's own targets.

# ccache when present (speeds up rebuilds of the CGAL translation units a lot).
find_program(FSS_CCACHE ccache)
# The tests use a precompiled header (tests/CMakeLists.txt); ccache caches such compilations only with
# these sloppiness settings (ccache manual, "Precompiled headers"): the header's content is still hashed.
if(FSS_CCACHE AND NOT CMAKE_CXX_COMPILER_LAUNCHER)
  set(_fss_ccache env "CCACHE_SLOPPINESS=pch_defines,time_macros,include_file_mtime,include_file_ctime"
      "${FSS_CCACHE}")
  set(CMAKE_C_COMPILER_LAUNCHER ${_fss_ccache})
  set(CMAKE_CXX_COMPILER_LAUNCHER ${_fss_ccache})
endif()

# Debug information: RelWithDebInfo (the default build type) keeps line tables only (-g1): backtraces,
# perf profiles and addr2line work, and a clean build costs about a fifth less CPU than with -g (measured on
# a test translation unit that includes CGAL: 30.5 s user with -g, 23.1 s with -g1). FSS_FULL_DEBUG_INFO=ON
# keeps the full -g (local variables in a debugger).
option(FSS_FULL_DEBUG_INFO "Full debug information (-g) in RelWithDebInfo builds instead of line tables (-g1)" OFF)
if(NOT FSS_FULL_DEBUG_INFO AND CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
  add_compile_options("$<$<CONFIG:RelWithDebInfo>:-g1>")
endif()

# lld, else gold, when present: linking Qt+VTK programs with ld.bfd costs about a second each.
if(NOT FSS_LINKER_CHOSEN AND CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
  include(CheckCXXSourceCompiles)
  foreach(ld lld gold)
    set(CMAKE_REQUIRED_LINK_OPTIONS "-fuse-ld=${ld}")
    check_cxx_source_compiles("int main() { return 0; }" FSS_HAS_LD_${ld})
    unset(CMAKE_REQUIRED_LINK_OPTIONS)
    if(FSS_HAS_LD_${ld})
      add_link_options("-fuse-ld=${ld}")
      break()
    endif()
  endforeach()
endif()

# fss_target_warnings(target): warnings are errors in our own code only.
function(fss_target_warnings target)
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE -Wall -Wextra -Werror)
    # CGAL and VTK headers trip a few GCC 12 false positives; those headers are included as SYSTEM.
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
      target_compile_options(${target} PRIVATE -Wno-maybe-uninitialized)
    endif()
  endif()
endfunction()
