/// \file
/// \brief kelp's version: the one place the number is written. CMake reads it from here
/// (CMakeLists.txt: the project's version, the shared library's SONAME, the Debian packages),
/// kelp::sim::version() and the programs' summaries report it, and Python's `kelp.__version__` is
/// this string.
#pragma once

/// \brief Major version: incremented for changes that break the API once kelp reaches 1.0.
#define KELP_VERSION_MAJOR 0
/// \brief Minor version: new features; before 1.0 it may also change the API (CHANGELOG.md says
/// what to change).
#define KELP_VERSION_MINOR 2
/// \brief Patch version: fixes only.
#define KELP_VERSION_PATCH 0
/// \brief The version as "MAJOR.MINOR.PATCH".
#define KELP_VERSION_STRING "0.2.0"
/// \brief The version as one integer, MAJOR · 10000 + MINOR · 100 + PATCH (0.2.0: 200), for
/// preprocessor comparisons: `#if KELP_VERSION >= 200`.
#define KELP_VERSION (KELP_VERSION_MAJOR * 10000 + KELP_VERSION_MINOR * 100 + KELP_VERSION_PATCH)

namespace kelp {

/// \brief The version of the kelp headers a program was compiled with, "MAJOR.MINOR.PATCH"
/// (KELP_VERSION_STRING). kelp::sim::version() gives the compiled library's.
/// \return a string literal, never null.
constexpr const char* header_version() noexcept { return KELP_VERSION_STRING; }

}  // namespace kelp
