# Compiler launcher, linker and warning flags for FSS's own targets.

# ccache when present (speeds up rebuilds of the CGAL translation units a lot).
find_program(FSS_CCACHE ccache)
# The header checks use a precompiled header (cmake/FSSHeaderCheck.cmake); ccache caches such compilations only with
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

# Unity builds (FSS_UNITY_BUILD, ON by default): the sources of a library or program compile as few
# translation units, so CGAL's, Qt's, VTK's and the standard library's headers are parsed, and their
# templates instantiated, once per unit instead of once per file — most of a clean build's CPU time on two
# cores. Consequence for the code: the .cpp files of one unit must not define the same name in their
# anonymous namespaces. Developers who edit one file over and over may prefer -DFSS_UNITY_BUILD=OFF.
option(FSS_UNITY_BUILD "Compile each library's and program's sources as few translation units" ON)

# fss_unity_build(target [GROUPS_UNDER <dir>]): a unity build of target (when FSS_UNITY_BUILD is on); with
# GROUPS_UNDER, one unit per first-level folder under <dir> (core's modules), else one unit for all.
function(fss_unity_build target)
  cmake_parse_arguments(ARG "" "GROUPS_UNDER" "" ${ARGN})
  if(NOT FSS_UNITY_BUILD)
    return()
  endif()
  if(ARG_GROUPS_UNDER)
    set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_MODE GROUP)
    get_target_property(sources ${target} SOURCES)
    foreach(src ${sources})
      get_filename_component(abs "${src}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
      if(abs MATCHES "\\.cpp$" AND abs MATCHES "^${ARG_GROUPS_UNDER}/")
        file(RELATIVE_PATH rel "${ARG_GROUPS_UNDER}" "${abs}")
        string(REGEX REPLACE "/.*" "" group "${rel}")
        set_source_files_properties(${src} TARGET_DIRECTORY ${target} PROPERTIES UNITY_GROUP "${target}_${group}")
      endif()
    endforeach()
  else()
    set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_MODE BATCH UNITY_BUILD_BATCH_SIZE 0)
  endif()
  # GCC warns when a type of a named namespace holds one of an anonymous namespace in an included file,
  # because a header so included by two translation units would break the one-definition rule; in a unity
  # build the "included file" is a .cpp included exactly once, so the warning does not apply.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    target_compile_options(${target} PRIVATE -Wno-subobject-linkage)
  endif()
endfunction()
