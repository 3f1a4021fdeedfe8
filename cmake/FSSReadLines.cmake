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
