/// \file
/// \brief The version of the compiled kelp::sim library a program runs with.
#pragma once

#include "kelp/sim/export.hpp"
#include "kelp/version.hpp"

namespace kelp {
namespace sim {

/// \brief kelp's version as "MAJOR.MINOR.PATCH", as the library was built (the summary's
/// `kelp_version` when a program sets none).
KELP_SIM_API const char* version() noexcept;

}  // namespace sim
}  // namespace kelp
