# Driver for one packaging test (see CMakeLists.txt). Fails with FATAL_ERROR on any step.
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})

include(${CMAKE_CURRENT_LIST_DIR}/run_command.cmake)

if(MODE STREQUAL "install")
  run(${CMAKE_COMMAND} --install ${KELP_BINARY_DIR} --prefix ${WORK_DIR}/prefix)
  set(prefix_args -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix)
  if(NOT EXISTS ${WORK_DIR}/prefix/share/cmake/kelp/kelpConfigVersion.cmake)
    message(FATAL_ERROR "packaging: kelpConfigVersion.cmake was not installed")
  endif()
else()
  set(prefix_args -Dkelp_DIR=${KELP_BINARY_DIR})
endif()

# Each header compiles on its own: checked once, against the build tree, kelp::sim's headers with
# the sim component and the others without Ceres (the Ceres header stands first in the ALL check of
# step 2). Against the prefix, all the headers compile in one translation unit, which proves they
# are found and complete at a fraction of the cost; there, step 1 has no header check of its own
# when step 2 runs (step 2's unit includes the same headers, the Ceres ones before them); step 3
# checks kelp::sim's headers in one unit too (they declare; the compiled library defines, so that
# unit costs a few CPU seconds).
if(MODE STREQUAL "install")
  if(WITH_CERES)
    set(header_check NONE)
  else()
    set(header_check ALL)
  endif()
  set(sim_header_check ALL)
else()
  set(header_check EACH)
  set(sim_header_check EACH)
endif()

# 1. Without a component: kelp::kelp only; neither Ceres nor nlohmann-json may be pulled in (they
#    are hidden from find_package, so a find_dependency on either fails the configure).
run(${CMAKE_COMMAND} -S ${CONSUMER_SOURCE_DIR} -B ${WORK_DIR}/plain -DCMAKE_BUILD_TYPE=Release
    -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DKELP_CONSUMER_WITH_CERES=OFF
    -DKELP_CONSUMER_HEADER_CHECK=${header_check} -DCMAKE_DISABLE_FIND_PACKAGE_Ceres=ON
    -DCMAKE_DISABLE_FIND_PACKAGE_nlohmann_json=ON ${prefix_args})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/plain -j 2)
run(${WORK_DIR}/plain/hello_kelp)

# 2. With the ceres component: kelp::ceres and every header, the Ceres ones included.
if(WITH_CERES)
  run(${CMAKE_COMMAND} -S ${CONSUMER_SOURCE_DIR} -B ${WORK_DIR}/ceres -DCMAKE_BUILD_TYPE=Release
      -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DKELP_CONSUMER_WITH_CERES=ON
      -DKELP_CONSUMER_HEADER_CHECK=ALL ${prefix_args})
  run(${CMAKE_COMMAND} --build ${WORK_DIR}/ceres -j 2)
  run(${WORK_DIR}/ceres/hello_kelp)
endif()

# 3. With the sim component: kelp::sim's headers (each on its own against the build tree) and
#    hello_sim, which loads a scenario file and runs 10 s of the closed loop through the public API
#    (hello_kelp is not built again: steps 1 and 2 build and run it). nlohmann-json is hidden from
#    find_package and its header from the compiler: kelp::sim's consumers need none.
if(WITH_SIM)
  run(${CMAKE_COMMAND} -S ${CONSUMER_SOURCE_DIR} -B ${WORK_DIR}/sim -DCMAKE_BUILD_TYPE=Release
      -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DKELP_CONSUMER_WITH_SIM=ON
      -DKELP_CONSUMER_HEADER_CHECK=${sim_header_check} -DCMAKE_DISABLE_FIND_PACKAGE_Ceres=ON
      -DCMAKE_DISABLE_FIND_PACKAGE_nlohmann_json=ON ${prefix_args})
  run(${CMAKE_COMMAND} --build ${WORK_DIR}/sim -j 2)
  execute_process(COMMAND ${WORK_DIR}/sim/hello_sim WORKING_DIRECTORY ${WORK_DIR}/sim
                  RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "packaging: hello_sim failed (${rc})")
  endif()
endif()
