/// \file
/// \brief The checks every vehicle description passes (private to kelp::sim): the vehicle file's
/// reader and writer and the SDF importer call them.
#pragma once

#include <string>

#include "kelp/sim/vehicle_file.hpp"

namespace kelp {
namespace sim {
namespace detail {

/// Runs the library's own checks on `d` (vehicle::validate for the parameters and the
/// propulsion, the thruster allocation, the hull, the PWM mapping; one curve per thruster).
/// \throws scenario_error naming `file` and the check's message.
void check_vehicle(const VehicleDescription& d, const std::string& file);

}  // namespace detail
}  // namespace sim
}  // namespace kelp
