/// \file
/// \brief The version of the compiled kelp::sim library a program runs with.
#pragma once

#include "kelp/sim/export.hpp"
#include "kelp/version.hpp"

namespace kelp {
namespace sim {

/// \brief kelp's version as "MAJOR.MINOR.PATCH", as the library was built (the summary's
/// `kelp_version` when a program sets none).
/// \return KELP_VERSION_STRING of the headers the library was compiled with (kelp/version.hpp);
/// a program built against other headers can compare it with kelp::header_version().
KELP_SIM_API const char* version() noexcept;

}  // namespace sim
}  // namespace kelp
