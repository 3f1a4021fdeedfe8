# design_citations: every citation of the design document in the sources points at a section that exists.
#
#   cmake -DROOT=<source dir> [-DLIST=ON] -P tests/design_citations.cmake
#
# A citation is "DESIGN.md" followed by section numbers, each a section sign and digits (N or N.M). The
# numbers that belong to one citation are those after "DESIGN.md" up to the end of its sentence or line,
# or, when the citation stands inside parentheses, up to the closing parenthesis (at most three lines
# further); so lists such as (DESIGN.md <N> "Stitch", <M>) are read whole, and the section numbers of
# other documents (the paper's, FIPS 180-4's) are not taken for ours. Section N exists when docs/DESIGN.md
# has a heading "## N. ..." (at any heading level), N.M when it has one "### N.M ...".
#
# Fails naming the file and line of every citation whose section does not exist. LIST=ON also prints every
# citation found (file:line: section).

cmake_minimum_required(VERSION 3.22)

if(NOT DEFINED ROOT)
  message(FATAL_ERROR "design_citations: pass the source folder as -DROOT=<dir>.")
endif()
get_filename_component(ROOT "${ROOT}" ABSOLUTE)
set(design "${ROOT}/docs/DESIGN.md")
if(NOT EXISTS "${design}")
  message(FATAL_ERROR "design_citations: ${design} does not exist.")
endif()

# Folders (and top-level files) whose citations are checked, and the kinds of files read there.
set(scan_dirs core widgets demo tests bench examples plugins cmake scripts)
set(scan_files CMakeLists.txt README.md)
set(extensions h hpp cpp cc cxx c in txt cmake md json sh ui qrc)

# ---- the sections of docs/DESIGN.md
set(sign "§") # U+00A7, two bytes in UTF-8; CMake's string functions count bytes
string(LENGTH "${sign}" sign_length)
file(STRINGS "${design}" headings REGEX "^#+ +[0-9]")
set(sections "")
foreach(heading IN LISTS headings)
  if(heading MATCHES "^#+ +([0-9]+(\\.[0-9]+)*)\\.?( |$)")
    list(APPEND sections "${CMAKE_MATCH_1}")
  endif()
endforeach()
if(NOT sections)
  message(FATAL_ERROR "design_citations: ${design} has no numbered section headings (\"## 1. ...\").")
endif()
list(JOIN sections ", " section_list)

# ---- the files to read
set(files "")
foreach(dir IN LISTS scan_dirs)
  foreach(ext IN LISTS extensions)
    file(GLOB_RECURSE found LIST_DIRECTORIES false "${ROOT}/${dir}/*.${ext}")
    list(APPEND files ${found})
  endforeach()
endforeach()
foreach(name IN LISTS scan_files)
  if(EXISTS "${ROOT}/${name}")
    list(APPEND files "${ROOT}/${name}")
  endif()
endforeach()
list(REMOVE_DUPLICATES files)
list(SORT files)

set(citations 0)
set(cited_files 0)
set(errors "")
foreach(path IN LISTS files)
  file(READ "${path}" content)
  string(FIND "${content}" "DESIGN.md" at)
  if(at EQUAL -1)
    continue()
  endif()
  file(RELATIVE_PATH relative "${ROOT}" "${path}")
  set(file_cited FALSE)
  set(line 1) # line of the first byte of `rest`
  set(rest "${content}")
  while(TRUE)
    string(FIND "${rest}" "DESIGN.md" at)
    if(at EQUAL -1)
      break()
    endif()
    string(SUBSTRING "${rest}" 0 ${at} before)
    string(REGEX REPLACE "[^\n]" "" newlines "${before}")
    string(LENGTH "${newlines}" n)
    math(EXPR line "${line} + ${n}")
    # Inside parentheses? Count them on the citation's line before it.
    string(FIND "${before}" "\n" line_start REVERSE)
    math(EXPR line_start "${line_start} + 1")
    string(SUBSTRING "${before}" ${line_start} -1 line_before)
    string(REGEX REPLACE "[^(]" "" opening "${line_before}")
    string(REGEX REPLACE "[^)]" "" closing "${line_before}")
    string(LENGTH "${opening}" opening)
    string(LENGTH "${closing}" closing)
    math(EXPR start "${at} + 9") # after "DESIGN.md"
    string(SUBSTRING "${rest}" ${start} -1 rest)
    # The citation's scope: to the end of the sentence or line, or to the closing parenthesis (at most three
    # lines on).
    string(SUBSTRING "${rest}" 0 800 scope)
    if(opening GREATER closing)
      string(FIND "${scope}" ")" end)
      string(SUBSTRING "${scope}" 0 ${end} scope)
      if(scope MATCHES "^([^\n]*\n[^\n]*\n[^\n]*\n[^\n]*)\n")
        set(scope "${CMAKE_MATCH_1}")
      endif()
    else()
      if(scope MATCHES "^([^\n]*)")
        set(scope "${CMAKE_MATCH_1}")
      endif()
      string(FIND "${scope}" ". " end) # the end of the sentence
      if(NOT end EQUAL -1)
        string(SUBSTRING "${scope}" 0 ${end} scope)
      endif()
    endif()
    # A further citation in the scope starts a scope of its own.
    string(FIND "${scope}" "DESIGN.md" next)
    if(NOT next EQUAL -1)
      string(SUBSTRING "${scope}" 0 ${next} scope)
    endif()
    # Every section number in the scope.
    set(scope_line ${line})
    while(TRUE)
      string(FIND "${scope}" "${sign}" s)
      if(s EQUAL -1)
        break()
      endif()
      string(SUBSTRING "${scope}" 0 ${s} head)
      string(REGEX REPLACE "[^\n]" "" newlines "${head}")
      string(LENGTH "${newlines}" n)
      math(EXPR scope_line "${scope_line} + ${n}")
      math(EXPR s "${s} + ${sign_length}")
      string(SUBSTRING "${scope}" ${s} -1 scope)
      if(scope MATCHES "^([0-9]+(\\.[0-9]+)*)")
        set(number "${CMAKE_MATCH_1}")
        math(EXPR citations "${citations} + 1")
        set(file_cited TRUE)
        if(LIST)
          message("${relative}:${scope_line}: ${sign}${number}")
        endif()
        list(FIND sections "${number}" known)
        if(known EQUAL -1)
          string(APPEND errors "${relative}:${scope_line}: cites DESIGN.md ${sign}${number}, "
                               "but docs/DESIGN.md has no section ${number}.\n")
        endif()
      endif()
    endwhile()
  endwhile()
  if(file_cited)
    math(EXPR cited_files "${cited_files} + 1")
  endif()
endforeach()

if(errors)
  message("${errors}")
  message(FATAL_ERROR "design_citations: citations point at sections that docs/DESIGN.md does not have "
                      "(its sections: ${section_list}).")
endif()
message(STATUS "design_citations: ${citations} citations in ${cited_files} files, all pointing at "
               "sections of docs/DESIGN.md (${section_list}).")
