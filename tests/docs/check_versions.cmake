# The release's version agrees everywhere it is written (CTest: docs_versions):
#   cmake -DROOT=<source dir> -DVERSION=<PROJECT_VERSION> -P check_versions.cmake
# include/kelp/version.hpp is the one source (CMakeLists.txt reads the project's version from it);
# this checks that its string matches its three numbers, and that CHANGELOG.md's newest release
# and CITATION.cff name the same version and date.
cmake_minimum_required(VERSION 3.16)
foreach(var ROOT VERSION)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "check_versions: -D${var}= is required")
  endif()
endforeach()
set(failures "")

file(READ "${ROOT}/include/kelp/version.hpp" header)
string(REGEX MATCH "#define KELP_VERSION_STRING \"([^\"]*)\"" _ "${header}")
if(NOT CMAKE_MATCH_1 STREQUAL VERSION)
  string(APPEND failures "\n  kelp/version.hpp: KELP_VERSION_STRING \"${CMAKE_MATCH_1}\", "
         "its numbers (the project's version) ${VERSION}")
endif()

file(READ "${ROOT}/CHANGELOG.md" changelog)
string(REGEX MATCH "\n## \\[([0-9]+\\.[0-9]+\\.[0-9]+)\\] - ([0-9-]+)\n" _ "${changelog}")
set(changelog_version "${CMAKE_MATCH_1}")
set(changelog_date "${CMAKE_MATCH_2}")
if(NOT changelog_version STREQUAL VERSION)
  string(APPEND failures "\n  CHANGELOG.md: newest release \"${changelog_version}\", "
         "kelp/version.hpp ${VERSION}")
endif()

file(READ "${ROOT}/CITATION.cff" citation)
string(REGEX MATCH "\nversion: \"?([^\"\n]*)\"?\n" _ "${citation}")
if(NOT CMAKE_MATCH_1 STREQUAL VERSION)
  string(APPEND failures "\n  CITATION.cff: version \"${CMAKE_MATCH_1}\", kelp/version.hpp ${VERSION}")
endif()
string(REGEX MATCH "\ndate-released: \"?([^\"\n]*)\"?\n" _ "${citation}")
if(NOT CMAKE_MATCH_1 STREQUAL changelog_date)
  string(APPEND failures "\n  CITATION.cff: date-released \"${CMAKE_MATCH_1}\", CHANGELOG.md's "
         "${changelog_version} \"${changelog_date}\"")
endif()

if(failures)
  message(FATAL_ERROR "check_versions: the version is not the same everywhere:${failures}")
endif()
message(STATUS "check_versions: ${VERSION} (${changelog_date}) in kelp/version.hpp, CMake, "
               "CHANGELOG.md and CITATION.cff")
