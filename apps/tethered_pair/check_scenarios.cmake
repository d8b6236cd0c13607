# Scenario files of kelp-tethered-pair (run by CTest):
#  - each kind of bad scenario is refused with a non-zero exit, a message naming the JSON path, and
#    no output directory;
#  - the calm hold scenario: after settling the AUV holds its depth within 5 cm and the boat keeps
#    within 1 m of its target (above the AUV);
#  - the winch dive (scenarios/winch_dive.json): the line paid out by at least 20 m and reeled back.
cmake_minimum_required(VERSION 3.19)  # string(JSON)

set(bad_unknown_key [=[{"tether": {"length": 10, "colour": "yellow"}}]=])
set(path_unknown_key "/tether/colour")
set(bad_wrong_type [=[{"duration": "long"}]=])
set(path_wrong_type "/duration")
set(bad_out_of_range [=[{"tether": {"length": -3}}]=])
set(path_out_of_range "/tether/length")
set(bad_non_finite [=[{"output": {"log_rate": 1e999}}]=])
# JSON has no NaN or infinity; a number beyond double is refused by the parser, named by its text.
set(path_non_finite "1e999")
set(bad_empty_waypoints [=[{"mission": {"waypoints": []}}]=])
set(path_empty_waypoints "/mission/waypoints")
set(bad_short_tether [=[{"tether": {"length": 5}, "vehicles": {"auv_start": [-30, 0, 5]}}]=])
set(path_short_tether "/tether/length")
set(bad_choice [=[{"sea": "stormy"}]=])
set(path_choice "/sea")
set(bad_vector [=[{"vehicles": {"asv_attachment": [0, "x", 0]}}]=])
set(path_vector "/vehicles/asv_attachment/1")
set(bad_gains [=[{"control": {"asv": {"linear": [0.5, -0.1, 0.05]}}}]=])
set(path_gains "/control/asv/linear")
set(bad_winch [=[{"tether": {"length": 10, "winch": {"strategy": "yank"}}}]=])
set(path_winch "/tether/winch/strategy")
set(bad_winch_range [=[{"tether": {"length": 10, "winch": {"min_length": 12}}}]=])
set(path_winch_range "/tether/length")
set(bad_regular_height [=[{"sea": {"regular": {"height": -1, "period": 6}}}]=])
set(path_regular_height "/sea/regular/height")
set(bad_regular_both [=[{"sea": {"regular": {"height": 1, "period": 6, "wavelength": 50}}}]=])
set(path_regular_both "/sea/regular")
set(bad_regular_steep [=[{"sea": {"regular": {"height": 4, "wavelength": 25}}}]=])
set(path_regular_steep "/sea/regular")
set(bad_not_json [=[{"duration": 10,]=])
set(path_not_json "not valid JSON")
# Nested 100000 levels deep (found by fuzz/fuzz_scenario): refused before parsing; it used to
# overflow the stack when the error message dumped the value.
string(REPEAT "[" 100000 open)
string(REPEAT "]" 100000 close)
set(bad_too_deep "{\"vehicles\": {\"asv_attachment\": ${open}${close}}}")
set(path_too_deep "nested more than 64 levels")

foreach(kind unknown_key wrong_type out_of_range non_finite empty_waypoints short_tether choice
             vector gains winch winch_range regular_height regular_both regular_steep not_json
             too_deep)
  set(file "${OUT}/${kind}.json")
  file(WRITE "${file}" "${bad_${kind}}")
  file(REMOVE_RECURSE "${OUT}/${kind}_out")
  execute_process(COMMAND "${PROGRAM}" --scenario "${file}" --out "${OUT}/${kind}_out" --quiet
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(rc EQUAL 0)
    message(FATAL_ERROR "${kind}: the bad scenario was accepted")
  endif()
  string(FIND "${err}" "${path_${kind}}" at)
  string(FIND "${err}" "${file}" at_file)
  if(at EQUAL -1 OR at_file EQUAL -1)
    message(FATAL_ERROR "${kind}: the message does not name the file and ${path_${kind}}: ${err}")
  endif()
  if(EXISTS "${OUT}/${kind}_out")
    message(FATAL_ERROR "${kind}: outputs were written for a bad scenario")
  endif()
  string(SUBSTRING "${err}" 0 300 shown)
  message(STATUS "${kind}: ${shown}")
endforeach()

# An explicit sea with only a current (no waves) is a valid scenario.
file(WRITE "${OUT}/current_only.json" [=[{"sea": {"current_speed": 0.3}, "duration": 5}]=])
file(REMOVE_RECURSE "${OUT}/current_only")
execute_process(COMMAND "${PROGRAM}" --scenario "${OUT}/current_only.json"
                        --out "${OUT}/current_only" --quiet --no-plots RESULT_VARIABLE rc
                        OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "current_only failed: ${out} ${err}")
endif()

file(REMOVE_RECURSE "${OUT}/calm")
execute_process(COMMAND "${PROGRAM}" --scenario "${SCENARIOS}/calm_hold.json" --out "${OUT}/calm"
                        --quiet --no-plots RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "calm_hold failed: ${out} ${err}")
endif()
file(READ "${OUT}/calm/summary.json" summary)
string(JSON depth GET "${summary}" auv second_half_max_depth_error_m)
string(JSON boat GET "${summary}" asv second_half_max_distance_to_auv_m)
message(STATUS "calm hold, second half: AUV depth error up to ${depth} m, boat up to ${boat} m "
               "from its target")
if(depth GREATER 0.05 OR boat GREATER 1.0)
  message(FATAL_ERROR "calm hold: depth error ${depth} m (limit 0.05), boat ${boat} m (limit 1)")
endif()

# The winch dive: the ROV dives from 5 m to 30 m and returns in the moderate sea while the boat's
# winch pays out and reels in by depth following: at least 20 m of payout change, back near the
# start's length, the summary's line mass following the length (0.5 m segments re-meshed at the
# winch), every waypoint reached, no fallback.
file(REMOVE_RECURSE "${OUT}/winch")
execute_process(COMMAND "${PROGRAM}" --scenario "${SCENARIOS}/winch_dive.json" --out "${OUT}/winch"
                        --quiet --no-plots RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "winch_dive failed: ${out} ${err}")
endif()
file(READ "${OUT}/winch/summary.json" summary)
string(JSON longest GET "${summary}" tether winch max_length_m)
string(JSON shortest GET "${summary}" tether winch min_length_m)
string(JSON inserted GET "${summary}" tether winch nodes_inserted)
string(JSON removed GET "${summary}" tether winch nodes_removed)
string(JSON mass0 GET "${summary}" tether line_mass_start_kg)
string(JSON mass1 GET "${summary}" tether line_mass_end_kg)
string(JSON length1 GET "${summary}" tether length_end_m)
string(JSON waypoints GET "${summary}" auv waypoints_reached)
string(JSON fallbacks GET "${summary}" tether_solver explicit_fallbacks)
message(STATUS "winch dive: line out ${shortest}..${longest} m (ends at ${length1} m), ${inserted} "
               "nodes inserted, ${removed} removed, line mass ${mass0} -> ${mass1} kg, "
               "${waypoints} waypoints")
if(longest LESS 30 OR length1 GREATER 15 OR waypoints LESS 4 OR NOT fallbacks EQUAL 0
   OR inserted LESS 40)
  message(FATAL_ERROR "winch dive: line out up to ${longest} m (>= 30), ends at ${length1} m "
                      "(<= 15), ${inserted} insertions (>= 40), ${waypoints} waypoints (4), "
                      "${fallbacks} fallbacks (0)")
endif()

# A fleet scenario runs through the same program (kelp/sim/fleet_run.hpp): the ROV's return to
# its dock writes its four outputs (run.mcap: checked by tests/ros2's ros2_mcap_node_check), and
# the summary names the fleet's parts.
file(REMOVE_RECURSE "${OUT}/fleet")
execute_process(COMMAND "${PROGRAM}" --scenario "${SCENARIOS}/rov_docking.json" --out "${OUT}/fleet"
                        --duration 20 --quiet --no-plots
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "rov_docking failed: ${out} ${err}")
endif()
foreach(f timeseries.csv nodes.csv summary.json run.mcap)
  if(NOT EXISTS "${OUT}/fleet/${f}")
    message(FATAL_ERROR "rov_docking: no ${f}")
  endif()
endforeach()
file(READ "${OUT}/fleet/summary.json" summary)
string(JSON simulated GET "${summary}" simulated_s)
string(JSON rope GET "${summary}" tethers tether to)
if(NOT simulated EQUAL 20 OR NOT rope STREQUAL "rov")
  message(FATAL_ERROR "rov_docking: simulated ${simulated} s (20), tether to \"${rope}\" (rov)")
endif()
