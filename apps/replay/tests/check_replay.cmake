# Run by CTest (example_replay): kelp-tethered-pair writes replay.html at the end of a run;
# kelp-replay makes the same page again from the run directory; it fails clearly on a directory
# that is not a run and without a template; kelp-tethered-pair without a template still
# completes the run and says once that replay.html is left out.
file(REMOVE_RECURSE "${OUT}")
file(MAKE_DIRECTORY "${OUT}")
set(ENV{KELP_REPLAY_TEMPLATE} "${TEMPLATE}")
execute_process(COMMAND "${PAIR}" --duration 20 --seed 2 --quiet --no-plots --out "${OUT}/run"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "kelp-tethered-pair failed (${rc}):\n${out}\n${err}")
endif()
if(NOT EXISTS "${OUT}/run/replay.html")
  message(FATAL_ERROR "kelp-tethered-pair wrote no replay.html:\n${out}\n${err}")
endif()
file(READ "${OUT}/run/replay.html" page)
foreach(needle "window.KELP_REPLAY_DATA = {" "\"format\":\"kelp-replay\""
        "\"source\":\"kelp-tethered-pair\"" "</script></body></html>")
  string(FIND "${page}" "${needle}" at)
  if(at LESS 0)
    message(FATAL_ERROR "replay.html lacks ${needle}")
  endif()
endforeach()
file(SHA256 "${OUT}/run/replay.html" first)

# kelp-replay on the run directory: the same page, byte for byte.
file(REMOVE "${OUT}/run/replay.html")
execute_process(COMMAND "${REPLAY}" "${OUT}/run" RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT EXISTS "${OUT}/run/replay.html")
  message(FATAL_ERROR "kelp-replay failed on a run directory (${rc}):\n${out}\n${err}")
endif()
file(SHA256 "${OUT}/run/replay.html" second)
if(NOT first STREQUAL second)
  message(FATAL_ERROR "kelp-replay made another page than kelp-tethered-pair for the same run")
endif()

# --json: the data alone.
execute_process(COMMAND "${REPLAY}" "${OUT}/run" --json "${OUT}/data.json" RESULT_VARIABLE rc
                OUTPUT_VARIABLE out ERROR_VARIABLE err)
file(READ "${OUT}/data.json" data)
string(JSON format GET "${data}" format)
string(JSON version GET "${data}" version)
string(JSON samples LENGTH "${data}" series t)
if(NOT rc EQUAL 0 OR NOT format STREQUAL "kelp-replay" OR NOT version EQUAL 1
   OR NOT samples EQUAL 201)
  message(FATAL_ERROR "kelp-replay --json: rc ${rc}, format ${format}, version ${version}, "
                      "${samples} samples (expected 201 at 10 Hz over 20 s):\n${err}")
endif()

# A fleet's run: kelp-tethered-pair writes its replay.html (data version 2), kelp-replay the same
# page again, and its data alone.
execute_process(COMMAND "${PAIR}" --scenario "${SCENARIOS}/rov_docking.json" --duration 10 --quiet
                        --out "${OUT}/fleet"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR NOT EXISTS "${OUT}/fleet/replay.html")
  message(FATAL_ERROR "kelp-tethered-pair wrote no replay.html for a fleet (${rc}):\n${out}\n${err}")
endif()
file(SHA256 "${OUT}/fleet/replay.html" fleet_first)
file(REMOVE "${OUT}/fleet/replay.html")
execute_process(COMMAND "${REPLAY}" "${OUT}/fleet" RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err)
file(SHA256 "${OUT}/fleet/replay.html" fleet_second)
if(NOT rc EQUAL 0 OR NOT fleet_first STREQUAL fleet_second)
  message(FATAL_ERROR "kelp-replay on a fleet's run (${rc}): another page than the run's:\n${err}")
endif()
execute_process(COMMAND "${REPLAY}" "${OUT}/fleet" --json "${OUT}/fleet.json" RESULT_VARIABLE rc
                OUTPUT_VARIABLE out ERROR_VARIABLE err)
file(READ "${OUT}/fleet.json" data)
string(JSON version GET "${data}" version)
string(JSON vehicle GET "${data}" vehicles 0 name)
string(JSON anchor GET "${data}" anchors 0 name)
string(JSON rope GET "${data}" tethers 0 name)
if(NOT rc EQUAL 0 OR NOT version EQUAL 2 OR NOT vehicle STREQUAL "rov" OR NOT anchor STREQUAL "dock"
   OR NOT rope STREQUAL "tether")
  message(FATAL_ERROR "kelp-replay --json on a fleet: rc ${rc}, version ${version}, vehicle "
                      "${vehicle}, anchor ${anchor}, tether ${rope}:\n${err}")
endif()

# Not a run directory: a clear error naming the missing file, nothing written.
file(MAKE_DIRECTORY "${OUT}/not-a-run")
file(WRITE "${OUT}/not-a-run/notes.txt" "hello\n")
execute_process(COMMAND "${REPLAY}" "${OUT}/not-a-run" RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err)
if(NOT rc EQUAL 1 OR NOT err MATCHES "is not a kelp run directory: it has no timeseries.csv"
   OR EXISTS "${OUT}/not-a-run/replay.html")
  message(FATAL_ERROR "kelp-replay on a directory that is not a run: rc ${rc}, stderr:\n${err}")
endif()
execute_process(COMMAND "${REPLAY}" "${OUT}/does-not-exist" RESULT_VARIABLE rc
                OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 1 OR NOT err MATCHES "is not a directory")
  message(FATAL_ERROR "kelp-replay on a missing directory: rc ${rc}, stderr:\n${err}")
endif()

# No template: kelp-replay fails saying so; kelp-tethered-pair completes and says so once.
set(ENV{KELP_REPLAY_TEMPLATE} "${OUT}/no-such-template.html")
execute_process(COMMAND "${REPLAY}" "${OUT}/run" RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "KELP_REPLAY_TEMPLATE=.*does not exist")
  message(FATAL_ERROR "kelp-replay without a template: rc ${rc}, stderr:\n${err}")
endif()
execute_process(COMMAND "${PAIR}" --duration 2 --quiet --no-plots --out "${OUT}/bare"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(REGEX MATCHALL "no replay.html" notes "${err}")
list(LENGTH notes count)
if(NOT rc EQUAL 0 OR NOT count EQUAL 1 OR EXISTS "${OUT}/bare/replay.html"
   OR NOT EXISTS "${OUT}/bare/summary.json")
  message(FATAL_ERROR "kelp-tethered-pair without a template: rc ${rc}, ${count} notes, "
                      "stderr:\n${err}")
endif()

# A kelp-sweep run kept with --keep-series is a run directory: kelp-replay tells it from its place.
if(SWEEP)
  set(ENV{KELP_REPLAY_TEMPLATE} "${TEMPLATE}")
  file(WRITE "${OUT}/sweep.json"
       "{\"base\": {\"duration\": 4, \"sea\": \"calm\"}, \"axes\": [{\"path\": \"/tether/length\", "
       "\"values\": [10]}], \"seeds\": [1]}")
  execute_process(COMMAND "${SWEEP}" --sweep "${OUT}/sweep.json" --out "${OUT}/sweep" --jobs 1
                          --quiet --no-plot --keep-series
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  file(GLOB kept LIST_DIRECTORIES true "${OUT}/sweep/runs/*")
  list(FILTER kept EXCLUDE REGEX "\\.json$")
  list(LENGTH kept count)
  if(NOT rc EQUAL 0 OR NOT count EQUAL 1)
    message(FATAL_ERROR "kelp-sweep --keep-series: rc ${rc}, ${count} run directories:\n${err}")
  endif()
  execute_process(COMMAND "${REPLAY}" "${kept}" RESULT_VARIABLE rc OUTPUT_VARIABLE out
                  ERROR_VARIABLE err)
  file(READ "${kept}/replay.html" page)
  string(FIND "${page}" "\"source\":\"kelp-sweep\"" at)
  if(NOT rc EQUAL 0 OR at LESS 0)
    message(FATAL_ERROR "kelp-replay on a kept sweep run: rc ${rc}, source found at ${at}:\n${err}")
  endif()
endif()

# --out: the page elsewhere; nothing written for a directory that is not a run.
set(ENV{KELP_REPLAY_TEMPLATE} "${TEMPLATE}")
execute_process(COMMAND "${REPLAY}" "${OUT}/run" --out "${OUT}/elsewhere.html" RESULT_VARIABLE rc
                OUTPUT_VARIABLE out ERROR_VARIABLE err)
file(SHA256 "${OUT}/elsewhere.html" third)
if(NOT rc EQUAL 0 OR NOT third STREQUAL first)
  message(FATAL_ERROR "kelp-replay --out: rc ${rc}, another page than the run's:\n${err}")
endif()
execute_process(COMMAND "${REPLAY}" "${OUT}/not-a-run" --out "${OUT}/nothing.html"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 1 OR EXISTS "${OUT}/nothing.html")
  message(FATAL_ERROR "kelp-replay --out on a directory that is not a run: rc ${rc}:\n${err}")
endif()
