# Runs vao-demo and checks its exit code, its output and the files it must write (a
# PASS_REGULAR_EXPRESSION alone would ignore the exit code).
#   cmake -DEXPECTED_EXIT_CODE=N [-DEXPECTED_OUTPUT=regex] [-DEXPECTED_FILES=a|b]
#         -P CheckDemo.cmake -- <vao-demo> <arguments...>
# Files are separated by '|': a ';' would split the -D argument in add_test.
set(command)
set(after_separator OFF)
foreach(i RANGE 1 ${CMAKE_ARGC})
  if(i LESS CMAKE_ARGC)
    if(after_separator)
      list(APPEND command "${CMAKE_ARGV${i}}")
    elseif(CMAKE_ARGV${i} STREQUAL "--")
      set(after_separator ON)
    endif()
  endif()
endforeach()
if(NOT command)
  message(FATAL_ERROR "usage: cmake -D... -P CheckDemo.cmake -- <vao-demo> <arguments...>")
endif()

string(REPLACE "|" ";" expected_files "${EXPECTED_FILES}")
if(expected_files)
  file(REMOVE ${expected_files}) # stale files from an earlier run must not pass
endif()

execute_process(COMMAND ${command} RESULT_VARIABLE exit_code OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}${err}")

if(NOT exit_code STREQUAL "${EXPECTED_EXIT_CODE}")
  message(FATAL_ERROR "vao-demo exited with '${exit_code}', expected ${EXPECTED_EXIT_CODE}")
endif()
if(DEFINED EXPECTED_OUTPUT AND NOT "${out}${err}" MATCHES "${EXPECTED_OUTPUT}")
  message(FATAL_ERROR "vao-demo did not print '${EXPECTED_OUTPUT}'")
endif()
foreach(file IN LISTS expected_files)
  if(NOT EXISTS "${file}")
    message(FATAL_ERROR "vao-demo did not write ${file}")
  endif()
endforeach()
