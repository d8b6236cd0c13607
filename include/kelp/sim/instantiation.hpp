/// \file
/// \brief The double-precision coupled system that kelp::sim runs, instantiated once in the
/// compiled library (src/instantiation.cpp): a program on kelp::sim that calls
/// `kelp::system::step`, `initial_state` or `energy` on doubles (the pair's or a fleet's:
/// kelp/system/fleet.hpp), steps a tether alone (`kelp::tether::step`, `advance`) in kelp's
/// Environment or solves its statics (`static_initial_state`, `solve_static_equilibrium`), builds a
/// vehicle model or a thruster allocation or steps a vehicle by RK4 (kelp/vehicle/instances.hpp),
/// or samples the sea's waves, links the library's code instead of compiling the system's templates
/// and the wave kernel's instruction sets again (Pinocchio's explicit-instantiation pattern; the
/// classes' inline members are left to the compiler). kelp::kelp stays header-only for every
/// scalar: these declarations are kelp::sim's, seen only by its consumers, who link it.
#pragma once

#include "kelp/environment/environment.hpp"
#include "kelp/environment/wave_kernels.hpp"
#include "kelp/sim/export.hpp"
#include "kelp/system/fleet.hpp"
#include "kelp/system/system.hpp"
#include "kelp/tether/driver.hpp"
#include "kelp/tether/initial_state.hpp"
#include "kelp/vehicle/instances.hpp"

KELP_WAVE_KERNEL_INSTANCES(extern template KELP_SIM_API)
KELP_SYSTEM_INSTANCES(extern template KELP_SIM_API)
KELP_FLEET_INSTANCES(extern template KELP_SIM_API)
KELP_TETHER_INSTANCES(extern template KELP_SIM_API)
KELP_TETHER_STATICS_INSTANCES(extern template KELP_SIM_API)
KELP_VEHICLE_INSTANCES(extern template KELP_SIM_API)
