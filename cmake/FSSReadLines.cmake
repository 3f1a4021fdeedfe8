# Helpers of the source checks run as scripts (cmake -P): FormatCheck, LayeringCheck, SizeCheck.

# fss_read_lines(<file> <out>): the lines of <file> as a CMake list, one element per line (empty lines kept),
# with ';', '[' and ']' replaced by <SC>, <LB> and <RB> so that CMake's list syntax cannot split or join
# lines. Used by the source checks (LayeringCheck, SizeCheck) to report exact line numbers.
function(fss_read_lines file out)
  file(READ "${file}" text)
  string(REGEX REPLACE "\n$" "" text "${text}") # the newline ending the last line opens no line
  string(REPLACE ";" "<SC>" text "${text}")
  string(REPLACE "[" "<LB>" text "${text}")
  string(REPLACE "]" "<RB>" text "${text}")
  string(REPLACE "\n" ";" text "${text}")
  set(${out} "${text}" PARENT_SCOPE)
endfunction()

# fss_cpp_sources(<out> ROOT <tree> DIRS <dir>... [EXCLUDE <path-regex relative to ROOT>]): every .h and
# .cpp under the given top-level folders of <tree>, sorted, minus those whose path relative to <tree>
# matches EXCLUDE. Fails when nothing is found (a wrong ROOT must not pass a check silently).
function(fss_cpp_sources out)
  cmake_parse_arguments(ARG "" "ROOT;EXCLUDE" "DIRS" ${ARGN})
  set(globs "")
  foreach(dir ${ARG_DIRS})
    list(APPEND globs "${ARG_ROOT}/${dir}/*.h" "${ARG_ROOT}/${dir}/*.cpp")
  endforeach()
  file(GLOB_RECURSE sources ${globs})
  if(ARG_EXCLUDE)
    string(REGEX REPLACE "([][+.*()^$?|\\\\])" "\\\\\\1" root_regex "${ARG_ROOT}")
    list(FILTER sources EXCLUDE REGEX "^${root_regex}/(${ARG_EXCLUDE})")
  endif()
  list(SORT sources)
  if(NOT sources)
    message(FATAL_ERROR "no C++ source found under ${ARG_ROOT} (${ARG_DIRS})")
  endif()
  set(${out} "${sources}" PARENT_SCOPE)
endfunction()
