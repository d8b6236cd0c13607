# run(<command> <args>...): runs a command from a packaging test script and stops the script with
# FATAL_ERROR naming the command when it fails. Included by run_consumer.cmake and
# run_eigen_only.cmake.
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "packaging: command failed (${rc}): ${ARGN}")
  endif()
endfunction()
