// The coupled system's (the pair's and a fleet's) double-precision step, initial state and energy
// and the tether's step, advance and static solves in kelp's Environment, instantiated once for the
// tests (tests/support/instances.cpp) and declared extern here, beside the wave kernels of
// instances.hpp: the tests of tests/system/ include this header first instead (their units
// otherwise compile the whole tether and vehicle step again, ~40 CPU s each).
#pragma once

#include "kelp/environment/environment.hpp"
#include "kelp/system/fleet.hpp"
#include "kelp/system/system.hpp"
#include "kelp/tether/driver.hpp"
#include "kelp/tether/initial_state.hpp"
#include "support/instances.hpp"

KELP_SYSTEM_INSTANCES(extern template)
KELP_FLEET_INSTANCES(extern template)
KELP_TETHER_INSTANCES(extern template)
KELP_TETHER_STATICS_INSTANCES(extern template)
