/// \file
/// \brief Umbrella header: everything in kelp that needs Eigen only. The Ceres catenary solver
/// (`kelp/ceres/catenary_solver.hpp`, target `kelp::ceres`) is included separately.
#pragma once

#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/rotation.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/environment/sea_state.hpp"
#include "kelp/environment/wave_loads.hpp"
#include "kelp/system/system.hpp"
#include "kelp/system/tether_attachment.hpp"
#include "kelp/tether/catenary.hpp"
#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/integrators.hpp"
#include "kelp/tether/lumped_mass.hpp"
#include "kelp/tether/presets.hpp"
#include "kelp/vehicle/integrators.hpp"
#include "kelp/vehicle/model.hpp"
#include "kelp/vehicle/presets.hpp"
#include "kelp/vehicle/state.hpp"
#include "kelp/vehicle/surroundings.hpp"
#include "kelp/vehicle/thrusters.hpp"
#include "kelp/vehicle/water.hpp"
