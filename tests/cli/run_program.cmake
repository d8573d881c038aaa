# Runs one program with arguments and checks its exit code and output; called by the cli.* tests
# (tests/cli/CMakeLists.txt) as
#   cmake -DPROGRAM=<file> -DARGS=<a|b|...> -DEXPECT_CODE=<n> [-DSTDOUT_MATCH=<regex>]
#         [-DSTDERR_MATCH=<regex>] [-DEMULATOR=<cmd|...>] -P run_program.cmake
# ARGS and EMULATOR separate their words with '|' (a ';' would split the test's own command).
string(REPLACE "|" ";" _args "${ARGS}")
string(REPLACE "|" ";" _emulator "${EMULATOR}")
execute_process(
  COMMAND ${_emulator} "${PROGRAM}" ${_args}
  RESULT_VARIABLE _code
  OUTPUT_VARIABLE _out
  ERROR_VARIABLE _err)
list(JOIN _args " " _what)
set(_what "${PROGRAM} ${_what}")
if(NOT "${_code}" STREQUAL "${EXPECT_CODE}")
  message(FATAL_ERROR
          "${_what}: exit code ${_code}, expected ${EXPECT_CODE}\nstdout:\n${_out}\nstderr:\n${_err}")
endif()
if(DEFINED STDOUT_MATCH AND NOT _out MATCHES "${STDOUT_MATCH}")
  message(FATAL_ERROR "${_what}: stdout does not match '${STDOUT_MATCH}':\n${_out}")
endif()
if(DEFINED STDERR_MATCH AND NOT _err MATCHES "${STDERR_MATCH}")
  message(FATAL_ERROR "${_what}: stderr does not match '${STDERR_MATCH}':\n${_err}")
endif()
