# kelp_optional_part(<var> <description> [PACKAGES "<name> [version] [args...]" ...])
#
# Resolves one of kelp's optional parts (tests, benchmarks, examples) to ON or OFF.
# <var> is a cache entry with the values AUTO (default), ON or OFF; a normal variable of the same
# name set by a parent project before add_subdirectory(kelp) takes precedence.
#   AUTO: ON when kelp is the top-level project (KELP_TOP_LEVEL) and every package is found,
#         OFF otherwise; a STATUS message names what is skipped and why.
#   ON:   every package is required; a missing one is a FATAL_ERROR naming it.
#   OFF:  nothing is looked for.
# On return <var> is a normal variable holding ON or OFF in the caller's scope. Packages are
# looked for in the caller's directory, so their imported targets are visible there.
function(kelp_optional_part var description)
  cmake_parse_arguments(ARG "" "" "PACKAGES" ${ARGN})
  if(NOT DEFINED ${var})
    set(${var} AUTO CACHE STRING "Build ${description}: AUTO (if kelp is top-level and the \
dependencies are found), ON (dependencies required) or OFF")
    set_property(CACHE ${var} PROPERTY STRINGS AUTO ON OFF)
  endif()
  string(TOUPPER "${${var}}" value)

  if(value STREQUAL "AUTO")
    if(NOT KELP_TOP_LEVEL)
      set(${var} OFF PARENT_SCOPE)
      return()
    endif()
    set(missing)
    foreach(spec IN LISTS ARG_PACKAGES)
      separate_arguments(args UNIX_COMMAND "${spec}")
      list(GET args 0 name)
      find_package(${args} QUIET)
      if(NOT ${name}_FOUND)
        list(APPEND missing "${spec}")
      endif()
    endforeach()
    if(missing)
      list(JOIN missing ", " missing_text)
      message(STATUS "kelp: ${missing_text} not found; ${description} are skipped "
                     "(-D${var}=ON makes this an error)")
      set(${var} OFF PARENT_SCOPE)
    else()
      set(${var} ON PARENT_SCOPE)
    endif()
  elseif(${var})
    foreach(spec IN LISTS ARG_PACKAGES)
      separate_arguments(args UNIX_COMMAND "${spec}")
      list(GET args 0 name)
      find_package(${args} QUIET)
      if(NOT ${name}_FOUND)
        message(FATAL_ERROR "kelp: ${var}=${${var}} but ${spec} was not found. Install it (see the "
                            "Dependencies table in docs/install.md) or configure with -D${var}=OFF.")
      endif()
    endforeach()
    set(${var} ON PARENT_SCOPE)
  else()
    set(${var} OFF PARENT_SCOPE)
  endif()
endfunction()
