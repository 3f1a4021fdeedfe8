# Compiler launcher, linker and warning flags for FSS's own targets.

# ccache when present (speeds up rebuilds of the CGAL translation units a lot).
find_program(FSS_CCACHE ccache)
if(FSS_CCACHE AND NOT CMAKE_CXX_COMPILER_LAUNCHER)
  set(CMAKE_C_COMPILER_LAUNCHER "${FSS_CCACHE}")
  set(CMAKE_CXX_COMPILER_LAUNCHER "${FSS_CCACHE}")
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
