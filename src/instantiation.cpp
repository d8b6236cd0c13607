// The double-precision coupled system and wave kernels, instantiated once for every user of
// kelp::sim (kelp/sim/instantiation.hpp declares what is here).
#include "kelp/sim/instantiation.hpp"

KELP_WAVE_KERNEL_INSTANCES(template)
KELP_SYSTEM_INSTANCES(template)
KELP_FLEET_INSTANCES(template)
KELP_TETHER_INSTANCES(template)
KELP_TETHER_STATICS_INSTANCES(template)
KELP_VEHICLE_INSTANCES(template)
