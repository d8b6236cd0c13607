# Runs kelp-tethered-pair twice on a short default scenario (run by CTest): both runs must succeed,
# write every output (non-empty PNG plots included, run.mcap: the ROS 2 bag, on by default) and give
# bit-identical time series and bags. A third run with --no-mcap writes no bag.
foreach(run a b)
  file(REMOVE_RECURSE "${OUT}/${run}")
  execute_process(COMMAND "${PROGRAM}" --duration 20 --seed 3 --quiet --out "${OUT}/${run}"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "run ${run} failed (${rc}):\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
  foreach(f timeseries.csv nodes.csv summary.json run.mcap trajectories.png depth.png tension.png
            errors.png tether.png)
    if(NOT EXISTS "${OUT}/${run}/${f}")
      message(FATAL_ERROR "run ${run} did not write ${f}")
    endif()
    file(SIZE "${OUT}/${run}/${f}" size)
    if(size LESS 100)
      message(FATAL_ERROR "run ${run}: ${f} is nearly empty (${size} bytes)")
    endif()
  endforeach()
endforeach()
foreach(f timeseries.csv nodes.csv run.mcap)
  file(SHA256 "${OUT}/a/${f}" ha)
  file(SHA256 "${OUT}/b/${f}" hb)
  if(NOT ha STREQUAL hb)
    message(FATAL_ERROR "the same seed gave different ${f}")
  endif()
endforeach()
file(REMOVE_RECURSE "${OUT}/no_mcap")
execute_process(COMMAND "${PROGRAM}" --duration 1 --quiet --no-plots --no-mcap --out "${OUT}/no_mcap"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR EXISTS "${OUT}/no_mcap/run.mcap" OR NOT EXISTS "${OUT}/no_mcap/timeseries.csv")
  message(FATAL_ERROR "--no-mcap: expected the CSV log and no run.mcap (${rc}):\n${out}\n${err}")
endif()
# summary.json reports the tether solver's work: one report per 10 ms step of the 20 s run, every
# step committed by Newton's method (at least one correction each), no explicit fallback (off by
# default) and the worst residual within the tolerance.
file(READ "${OUT}/a/summary.json" summary)
string(JSON solver GET "${summary}" tether_solver)
message(STATUS "tether_solver: ${solver}")
string(JSON steps GET "${solver}" steps)
string(JSON newton GET "${solver}" newton_iterations)
string(JSON fallbacks GET "${solver}" explicit_fallbacks)
string(JSON enabled GET "${solver}" explicit_fallback)
string(JSON worst GET "${solver}" worst_residual_m_s)
string(JSON tolerance GET "${solver}" residual_tolerance_m_s)
if(NOT steps EQUAL 2000 OR newton LESS 2000 OR NOT fallbacks EQUAL 0 OR enabled
   OR worst GREATER tolerance)
  message(FATAL_ERROR "summary.json: tether_solver is not that of 2000 converged implicit steps "
                      "without fallback: ${solver}")
endif()
