# kelp is header-only, so it is compiled with the user's flags. Under -ffast-math the wave
# kernels' phase reduction is folded away (the sea's surface elevation stops changing) and the
# NaN checks may be removed, so kelp refuses those flags with an #error naming the flag
# (kelp/core/compiler_checks.hpp). This script compiles SOURCE (which includes kelp):
#   - without such flags: it must compile (so that a refusal below is the #error, not a broken
#     command line);
#   - with each refused flag: the compiler must fail and its message name the flag.
# Arguments: CXX_COMPILER, CXX_COMPILER_ID, INCLUDE_DIRS ('|'-separated), SOURCE.
string(REPLACE "|" ";" dirs "${INCLUDE_DIRS}")
set(includes)
foreach(d IN LISTS dirs)
  if(d)
    list(APPEND includes "-I${d}")
  endif()
endforeach()

function(compile out_rc out_log)
  execute_process(COMMAND ${CXX_COMPILER} -std=c++17 -fsyntax-only -Wfatal-errors ${ARGN}
                          ${includes} ${SOURCE}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  set(${out_rc} "${rc}" PARENT_SCOPE)
  set(${out_log} "${out}${err}" PARENT_SCOPE)
endfunction()

compile(rc log -O2)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "refuse_fast_math: the control compile without -ffast-math failed:\n${log}")
endif()

# <flags separated by '|'> = <what the message must name>
set(cases "-ffast-math=-ffast-math" "-O2|-Ofast=-ffast-math"
          "-ffinite-math-only=-ffinite-math-only")
if(CXX_COMPILER_ID STREQUAL "GNU")  # GCC alone defines __ASSOCIATIVE_MATH__
  list(APPEND cases
       "-fassociative-math|-fno-signed-zeros|-fno-trapping-math=-fassociative-math")
endif()
foreach(case IN LISTS cases)
  string(REGEX REPLACE "=.*$" "" flags "${case}")
  string(REGEX REPLACE "^.*=" "" named "${case}")
  string(REPLACE "|" ";" flags "${flags}")
  compile(rc log ${flags})
  if(rc EQUAL 0)
    message(FATAL_ERROR "refuse_fast_math: kelp compiled with ${flags}; it must refuse")
  endif()
  string(FIND "${log}" "kelp does not support ${named}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR
            "refuse_fast_math: with ${flags} the compiler failed without naming ${named}:\n${log}")
  endif()
  message(STATUS "refused ${flags}: names ${named}")
endforeach()
