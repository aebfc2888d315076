# SPDX-License-Identifier: GPL-3.0-or-later
# scripts/run then scripts/test, in the order a newcomer runs them (issue 16 item 15): scripts/run
# configures build/release with the tests off, and the cache keeps options. The test command
# must turn every test on whatever was configured before, and ctest must fail when it finds none.
# Configure only (no build): a scratch directory configured as scripts/run does, then
# reconfigured by scripts/test's own Release configure line (ASPERITY_CONFIGURE_ONLY).
# cmake -DSOURCE_DIR=... -DWORK_DIR=... -P scripts_test.cmake
file(REMOVE_RECURSE ${WORK_DIR})
file(READ ${SOURCE_DIR}/scripts/run run_text)
string(REGEX MATCH "cmake -S \\. -B build/release ([^\n>]*)" run_line "${run_text}")
if(NOT run_line)
  message(FATAL_ERROR "scripts/run: no 'cmake -S . -B build/release' line found")
endif()
separate_arguments(run_options UNIX_COMMAND "${CMAKE_MATCH_1}")
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR} ${run_options}
                RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "configuring as scripts/run does failed: ${err}")
endif()
file(STRINGS ${WORK_DIR}/CMakeCache.txt before REGEX "^ASPERITY_BUILD_TESTS:")
if(NOT before MATCHES "=OFF")
  message(FATAL_ERROR "scripts/run no longer turns the tests off (${before}): this test proves nothing")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E env ASPERITY_CONFIGURE_ONLY=${WORK_DIR} ${SOURCE_DIR}/scripts/test
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "scripts/test's configure failed: ${err}")
endif()
foreach(option ASPERITY_BUILD_TESTS ASPERITY_BUILD_BENCH ASPERITY_BUILD_CLI ASPERITY_WITH_MPI)
  file(STRINGS ${WORK_DIR}/CMakeCache.txt line REGEX "^${option}:")
  if(NOT line MATCHES "=ON$")
    message(FATAL_ERROR "after scripts/run, scripts/test leaves ${option} off: ${line}")
  endif()
endforeach()
# Every ctest call of scripts/test fails on an empty test set.
file(STRINGS ${SOURCE_DIR}/scripts/test ctest_lines REGEX "^[ \t]*ctest ")
list(LENGTH ctest_lines n)
if(n EQUAL 0)
  message(FATAL_ERROR "scripts/test runs no ctest")
endif()
foreach(l IN LISTS ctest_lines)
  if(NOT l MATCHES "--no-tests=error")
    message(FATAL_ERROR "scripts/test: a ctest without --no-tests=error: ${l}")
  endif()
endforeach()
file(REMOVE_RECURSE ${WORK_DIR})
message(STATUS "scripts/test turns every test on after scripts/run (${n} ctest calls, all --no-tests=error)")
