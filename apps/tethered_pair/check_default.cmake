# The README's first picture must look competent: the default run (the embedded default scenario:
# moderate sea, 10 m tether, an 8 m square survey at 5 m, the "kelp" controller preset, the sea
# ramped in over 10 s) keeps the ROV on its survey (path error RMS <= 1 m), the boat on station
# over the ROV (horizontal distance RMS <= 3 m) and the tether slack (no end force above 30 N:
# no snapping taut), and flies the whole square. Run with -DPROGRAM=... -DOUT=...
file(REMOVE_RECURSE "${OUT}/default")
execute_process(COMMAND "${PROGRAM}" --quiet --no-plots --out "${OUT}/default"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the default run failed (${rc}):\n${out}\n${err}")
endif()
file(READ "${OUT}/default/summary.json" summary)
string(JSON auv_rms GET "${summary}" auv rms_path_error_m)
string(JSON waypoints GET "${summary}" auv waypoints_reached)
string(JSON asv_rms GET "${summary}" asv rms_distance_to_auv_m)
string(JSON tension GET "${summary}" tether max_tension_n)
message(STATUS "default run: AUV path error RMS ${auv_rms} m, ${waypoints} waypoints; boat "
               "${asv_rms} m RMS from the ROV; largest tether tension ${tension} N")
if(auv_rms GREATER 1.0 OR asv_rms GREATER 3.0 OR tension GREATER 30.0 OR waypoints LESS 4)
  message(FATAL_ERROR "the default run is out of its bounds: AUV RMS ${auv_rms} m (<= 1), boat "
                      "RMS ${asv_rms} m (<= 3), max tension ${tension} N (<= 30), waypoints "
                      "${waypoints} (4)")
endif()
