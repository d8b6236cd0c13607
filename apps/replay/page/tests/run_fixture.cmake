# Runs kelp-tethered-pair (PROGRAM) with ARGS into OUT and checks that it wrote replay.html (run by
# CTest as a fixture of the replay page's browser tests).
file(REMOVE_RECURSE "${OUT}")
execute_process(COMMAND "${PROGRAM}" ${ARGS} --quiet --no-plots --out "${OUT}"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message(STATUS "${out}${err}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "kelp-tethered-pair failed (${rc})")
endif()
if(NOT EXISTS "${OUT}/replay.html")
  message(FATAL_ERROR "kelp-tethered-pair wrote no ${OUT}/replay.html: the replay page's template "
                      "was not built (it needs Node.js and three.js in apps/replay/page/node_modules: "
                      "run scripts/install-deps test, or npm ci in apps/replay/page/, then cmake "
                      "again)")
endif()
file(SIZE "${OUT}/replay.html" size)
message(STATUS "replay.html: ${size} bytes")
