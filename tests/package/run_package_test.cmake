# SPDX-License-Identifier: Apache-2.0
# Driver of the ctest entries package.* (cmake -P; arguments from tests/CMakeLists.txt):
#   MODE=install    cmake --install BUILD_DIR into WORK_DIR/prefix, check the exported files,
#                   then configure, build and run the consumer project (CONSUMER_DIR) against it.
#   MODE=core_only  configure SOURCE_DIR with -DHRCSENSE_WITH_APPS=OFF (no tests, benchmarks;
#                   the apps' dependencies disabled so that a search for one fails), build it
#                   with -j2 (in unity batches when the calling build uses them, UNITY), install
#                   it and build and run the consumer against that install.
cmake_minimum_required(VERSION 3.25)

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    string(JOIN " " command ${ARGN})
    message(FATAL_ERROR "package test: failed (${rc}): ${command}")
  endif()
endfunction()

# The exported files must not ask a consumer for sanitizer or fuzzer flags, nor point into
# the source or build tree.
function(check_export prefix)
  file(GLOB exported "${prefix}/lib*/cmake/hrcsense/*.cmake")
  if(NOT exported)
    message(FATAL_ERROR "package test: no package config installed under ${prefix}/lib*/cmake/hrcsense")
  endif()
  foreach(file IN LISTS exported)
    file(READ ${file} text)
    foreach(forbidden "-fsanitize" "nanoflann::" "${SOURCE_DIR}/" "${BUILD_DIR}/")
      if(NOT forbidden STREQUAL "/")
        string(FIND "${text}" "${forbidden}" at)
        if(NOT at EQUAL -1)
          message(FATAL_ERROR "package test: ${file} names '${forbidden}' (leaks into consumers)")
        endif()
      endif()
    endforeach()
  endforeach()
endfunction()

function(consume prefix)
  set(consumer_build ${WORK_DIR}/consumer)
  set(flags "")
  if(SANITIZE)
    # The installed static libraries were compiled with ASan/UBSan: the consumer chooses to
    # link the sanitizer runtimes itself (the package does not impose them).
    set(flags -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined)
  endif()
  run(${CMAKE_COMMAND} -S ${CONSUMER_DIR} -B ${consumer_build} -G ${GENERATOR}
      -DCMAKE_MAKE_PROGRAM=${MAKE_PROGRAM} -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
      -DCMAKE_BUILD_TYPE=${BUILD_TYPE} -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF
      ${flags} ${ARGN})
  run(${CMAKE_COMMAND} --build ${consumer_build} -j 2)
  run(${consumer_build}/hrcsense_consumer)
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)

if(MODE STREQUAL "install")
  run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
  check_export(${prefix})
  consume(${prefix} -DEXPECT_APPS=ON)
elseif(MODE STREQUAL "core_only")
  set(BUILD_DIR ${WORK_DIR}/build)
  # A REQUIRED search for any of these fails the configuration: none may be looked for.
  set(disabled "")
  foreach(package yaml-cpp CLI11 spdlog nlohmann_json PNG BZip2 PkgConfig GTest benchmark)
    list(APPEND disabled -DCMAKE_DISABLE_FIND_PACKAGE_${package}=ON)
  endforeach()
  run(${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${BUILD_DIR} -G ${GENERATOR}
      -DCMAKE_MAKE_PROGRAM=${MAKE_PROGRAM} -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DCMAKE_BUILD_TYPE=Release
      -DHRCSENSE_WITH_APPS=OFF -DBUILD_TESTING=OFF -DHRCSENSE_BUILD_BENCHMARKS=OFF -DHRCSENSE_WERROR=ON
      -DCMAKE_UNITY_BUILD=${UNITY} -DCMAKE_UNITY_BUILD_BATCH_SIZE=16 ${disabled})
  run(${CMAKE_COMMAND} --build ${BUILD_DIR} -j 2)
  run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
  check_export(${prefix})
  set(SANITIZE OFF)
  consume(${prefix} -DEXPECT_APPS=OFF -DCMAKE_BUILD_TYPE=Release)
else()
  message(FATAL_ERROR "package test: MODE must be install or core_only, not '${MODE}'")
endif()
message(STATUS "package test ${MODE}: passed")
