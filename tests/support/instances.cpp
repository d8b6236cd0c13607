// The instances every test shares (tests/support/instances.hpp, system_instances.hpp), compiled
// once with the tests' own flags (assertions on, EIGEN_RUNTIME_NO_MALLOC).
#include "support/system_instances.hpp"

KELP_WAVE_KERNEL_INSTANCES(template)
KELP_SYSTEM_INSTANCES(template)
KELP_FLEET_INSTANCES(template)
KELP_TETHER_INSTANCES(template)
KELP_TETHER_STATICS_INSTANCES(template)
KELP_VEHICLE_INSTANCES(template)
KELP_TEST_FLOAT_VEHICLE_INSTANCES(template)
