# Driver for the Eigen-only packaging tests (see CMakeLists.txt). Fails with FATAL_ERROR on any step.
#
# A machine with only Eigen, CMake and a compiler is simulated by configuring kelp's source tree
# with CMAKE_DISABLE_FIND_PACKAGE_<name> for every optional dependency.
#   MODE=install:  the README's install recipe, `cmake -S . -B build` then
#                  `cmake --install build --prefix <prefix>`, must succeed and say what it skips,
#                  and the consumer project must build and run against the prefix (no ceres).
#   MODE=required: an explicit -DKELP_BUILD_TESTS=ON (or BENCHMARKS) with the dependency missing
#                  must stop the configure with an error naming the dependency.
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})

set(no_optional_deps
    -DCMAKE_DISABLE_FIND_PACKAGE_Catch2=ON -DCMAKE_DISABLE_FIND_PACKAGE_benchmark=ON
    -DCMAKE_DISABLE_FIND_PACKAGE_Ceres=ON -DCMAKE_DISABLE_FIND_PACKAGE_nlohmann_json=ON
    -DCMAKE_DISABLE_FIND_PACKAGE_CLI11=ON)

include(${CMAKE_CURRENT_LIST_DIR}/run_command.cmake)

if(MODE STREQUAL "install")
  execute_process(
    COMMAND ${CMAKE_COMMAND} -S ${KELP_SOURCE_DIR} -B ${WORK_DIR}/build
            -DCMAKE_CXX_COMPILER=${CXX_COMPILER} ${no_optional_deps}
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message("${out}${err}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "packaging: configuring kelp with Eigen alone failed (${rc})")
  endif()
  foreach(expected "kelp's tests are skipped" "kelp's benchmarks are skipped")
    string(FIND "${out}${err}" "${expected}" at)
    if(at EQUAL -1)
      message(FATAL_ERROR "packaging: the configure did not say \"${expected}\"")
    endif()
  endforeach()
  run(${CMAKE_COMMAND} --install ${WORK_DIR}/build --prefix ${WORK_DIR}/prefix)
  foreach(file share/cmake/kelp/kelpConfig.cmake share/cmake/kelp/kelpConfigVersion.cmake
               share/cmake/kelp/kelpTargets.cmake include/kelp/kelp.hpp)
    if(NOT EXISTS ${WORK_DIR}/prefix/${file})
      message(FATAL_ERROR "packaging: ${file} was not installed")
    endif()
  endforeach()
  if(EXISTS ${WORK_DIR}/prefix/share/cmake/kelp/kelpCeresTargets.cmake)
    message(FATAL_ERROR "packaging: kelp::ceres was installed although Ceres was not found")
  endif()
  run(${CMAKE_COMMAND} -S ${CONSUMER_SOURCE_DIR} -B ${WORK_DIR}/consumer -DCMAKE_BUILD_TYPE=Release
      -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DKELP_CONSUMER_WITH_CERES=OFF
      -DKELP_CONSUMER_HEADER_CHECK=ALL -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_DISABLE_FIND_PACKAGE_Ceres=ON)
  run(${CMAKE_COMMAND} --build ${WORK_DIR}/consumer -j 2)
  run(${WORK_DIR}/consumer/hello_kelp)
elseif(MODE STREQUAL "required")
  foreach(part TESTS:Catch2 BENCHMARKS:benchmark)
    string(REPLACE ":" ";" part "${part}")
    list(GET part 0 option)
    list(GET part 1 package)
    execute_process(
      COMMAND ${CMAKE_COMMAND} -S ${KELP_SOURCE_DIR} -B ${WORK_DIR}/${option}
              -DCMAKE_CXX_COMPILER=${CXX_COMPILER} ${no_optional_deps} -DKELP_BUILD_${option}=ON
      RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(rc EQUAL 0)
      message(FATAL_ERROR "packaging: -DKELP_BUILD_${option}=ON without ${package} configured")
    endif()
    string(FIND "${err}" "KELP_BUILD_${option}=ON but ${package}" at)
    if(at EQUAL -1)
      message(FATAL_ERROR "packaging: the error does not name ${package}:\n${err}")
    endif()
    message(STATUS "packaging: -DKELP_BUILD_${option}=ON without ${package} fails as it should")
  endforeach()
else()
  message(FATAL_ERROR "packaging: unknown MODE '${MODE}'")
endif()
