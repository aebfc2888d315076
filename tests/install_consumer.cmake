# SPDX-License-Identifier: GPL-3.0-or-later
# Installs the built project into a temporary prefix, then configures, builds and runs
# tests/consumer against it with find_package(asperity CONFIG REQUIRED), linking asperity::${TARGET};
# then builds and runs the same consumer with pkg-config's flags for the installed asperity-core.pc
# (TARGET core) or asperity.pc (TARGET asperity), found through PKG_CONFIG_PATH alone.
file(REMOVE_RECURSE "${WORK_DIR}")
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
endfunction()
run(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${WORK_DIR}/prefix")
# The installed headers are the API (the Python module's and docs/library.md's): every quoted
# #include of an installed header names another installed header, so none reaches an internal one
# (CLI, I/O, checkpoints: src/app/, not installed, issue 43).
file(GLOB_RECURSE _headers "${WORK_DIR}/prefix/include/asperity/*.hpp" "${WORK_DIR}/prefix/include/asperity/*.h")
foreach(_h IN LISTS _headers)
  file(STRINGS "${_h}" _incs REGEX "^[ \t]*#[ \t]*include[ \t]*\"")
  foreach(_i IN LISTS _incs)
    string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*\"([^\"]+)\".*" "\\1" _name "${_i}")
    get_filename_component(_dir "${_h}" DIRECTORY)
    if(NOT EXISTS "${WORK_DIR}/prefix/include/${_name}" AND NOT EXISTS "${_dir}/${_name}")
      message(FATAL_ERROR "installed ${_h} includes \"${_name}\", which is not installed")
    endif()
  endforeach()
endforeach()
foreach(_internal atomic_file bounded_read interrupt output_staging mesh_io checkpoint option_table stream_report collective)
  if(EXISTS "${WORK_DIR}/prefix/include/asperity/app/${_internal}.hpp")
    message(FATAL_ERROR "internal header asperity/app/${_internal}.hpp was installed")
  endif()
endforeach()
run(${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/consumer" -B "${WORK_DIR}/build"
    -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=Release -DASPERITY_TARGET=${TARGET})
run(${CMAKE_COMMAND} --build "${WORK_DIR}/build")
run("${WORK_DIR}/build/consumer")
# pkg-config (issue 42 item 5): the installed .pc file, no other path given.
file(GLOB_RECURSE _pc "${WORK_DIR}/prefix/*/pkgconfig/asperity.pc")
if(NOT _pc)
  message(FATAL_ERROR "no pkgconfig/asperity.pc under ${WORK_DIR}/prefix")
endif()
get_filename_component(_pcdir "${_pc}" DIRECTORY)
get_filename_component(_libdir "${_pcdir}" DIRECTORY)
set(_module asperity)
if("${TARGET}" STREQUAL "core")
  set(_module asperity-core)
endif()
set(ENV{PKG_CONFIG_PATH} "${_pcdir}")
execute_process(COMMAND pkg-config --cflags --libs ${_module} RESULT_VARIABLE rc OUTPUT_VARIABLE flags
                ERROR_VARIABLE err OUTPUT_STRIP_TRAILING_WHITESPACE)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "pkg-config --cflags --libs ${_module} failed (${rc}): ${err}")
endif()
message(STATUS "pkg-config --cflags --libs ${_module}: ${flags}")
separate_arguments(flags UNIX_COMMAND "${flags}")
run(${CXX} -std=c++20 "${SOURCE_DIR}/tests/consumer/main.cpp" ${flags} -o "${WORK_DIR}/consumer-pkg-config")
run(${CMAKE_COMMAND} -E env LD_LIBRARY_PATH=${_libdir} "${WORK_DIR}/consumer-pkg-config")
