# kelp-mission (a MAVLink client that flies the tethered mission on ArduSub and ArduRover SITL),
# its MAVLink codec (mavlink/*.hpp, header-only) and their tests. Included by CMakeLists.txt
# beside this file once nlohmann_json and CLI11 were found.

# kelp-mission: the MAVLink client that flies the mission (mission/*.hpp, mission.cpp).
add_executable(kelp-mission mission.cpp)
target_include_directories(kelp-mission PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
target_link_libraries(kelp-mission PRIVATE kelp_warnings CLI11::CLI11)
target_compile_features(kelp-mission PRIVATE cxx_std_17)
install(TARGETS kelp-mission RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT sitl)

if(KELP_BUILD_TESTS)
  # The codec: CRC, definitions, framing, parser against corrupt and random input.
  kelp_add_test(test_sitl_mavlink SIM SOURCES tests/mavlink/test_codec.cpp
                INCLUDES ${CMAKE_CURRENT_SOURCE_DIR})

  # Cross-check against node-mavlink (npm), both directions. node/crosscheck.js drives
  # kelp-mavlink-vectors; node-mavlink is installed by scripts/install-deps (npm ci in
  # tests/mavlink/node). Without node or node_modules the test fails with a message.
  add_executable(kelp-mavlink-vectors tests/mavlink/vectors.cpp)
  target_include_directories(kelp-mavlink-vectors PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}
                                                          ${CMAKE_CURRENT_SOURCE_DIR}/tests/mavlink)
  target_link_libraries(kelp-mavlink-vectors PRIVATE kelp_warnings nlohmann_json::nlohmann_json)
  target_compile_features(kelp-mavlink-vectors PRIVATE cxx_std_17)
  find_program(KELP_NODE_EXECUTABLE node)
  if(KELP_NODE_EXECUTABLE)
    add_test(NAME sitl_mavlink_node_crosscheck
             COMMAND ${KELP_NODE_EXECUTABLE}
                     ${CMAKE_CURRENT_SOURCE_DIR}/tests/mavlink/node/crosscheck.js
                     $<TARGET_FILE:kelp-mavlink-vectors>)
  else()
    kelp_add_node_missing_test(sitl_mavlink_node_crosscheck)
  endif()
  set_tests_properties(sitl_mavlink_node_crosscheck PROPERTIES TIMEOUT 120)

  # kelp-mission's logic against fake autopilots (threads serving loopback TCP).
  find_package(Threads REQUIRED)
  kelp_add_test(test_sitl_mission SIM SOURCES tests/mavlink/test_mission.cpp
                INCLUDES ${CMAKE_CURRENT_SOURCE_DIR} ${CMAKE_CURRENT_SOURCE_DIR}/tests/mavlink
                LIBRARIES Threads::Threads)
  set_tests_properties(test_sitl_mission PROPERTIES TIMEOUT 120)
endif()
