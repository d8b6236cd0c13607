/// \file
/// \brief A scenario's cable overrides on a tether preset: one function for the pair's tether
/// (world.cpp) and a fleet's (fleet_run.cpp). Private to the kelp::sim library.
#pragma once

#include <optional>

#include "kelp/tether/model.hpp"

namespace kelp {
namespace sim {

/// \brief The cable properties a scenario may set over its preset (unset: keep the preset's);
/// units as in kelp::tether::TetherParameters.
struct CableOverrides {
  std::optional<double> diameter, mass_per_length, axial_stiffness, internal_damping,
      internal_damping_ratio, normal_drag, tangential_drag, breaking_strength;
};

/// \brief Sets the given properties on `p`; a damping ratio replaces the preset's BA.
/// \throws kelp::invalid_argument when both internal_damping and internal_damping_ratio are set.
void apply_cable(const CableOverrides& c, kelp::tether::TetherParametersd& p);

}  // namespace sim
}  // namespace kelp
