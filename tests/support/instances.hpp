// What every test executable shares instead of compiling it again: the double-precision wave
// kernels and the vehicle's costliest code (a model's construction, the thruster allocation's
// pseudo-inverse, the RK4 steps: kelp/vehicle/instances.hpp), instantiated once
// (tests/support/instances.cpp, compiled with the tests' own flags into kelp_test_instances) and
// declared extern here. tests/CMakeLists.txt includes this header first in every test unit that
// does not link kelp::sim (which declares and provides the same instances itself:
// kelp/sim/instantiation.hpp); tests/system/ includes system_instances.hpp instead. The float and
// Jet instances, and everything else, are still compiled by each test, but for the float
// vehicle's construction below.
#pragma once

#include "kelp/environment/wave_kernels.hpp"
#include "kelp/vehicle/instances.hpp"

KELP_WAVE_KERNEL_INSTANCES(extern template)
KELP_VEHICLE_INSTANCES(extern template)

// The float vehicle's construction (its validation and mass-matrix factorisation, the thruster
// allocation's pseudo-inverse), which tests/vehicle and tests/control both build: once here.
#define KELP_TEST_FLOAT_VEHICLE_INSTANCES(prefix)                                             \
  prefix void kelp::vehicle::validate<float>(const kelp::vehicle::VehicleParameters<float>&); \
  prefix kelp::vehicle::VehicleModel<float>::VehicleModel(                                    \
      const kelp::vehicle::VehicleParameters<float>&);                                        \
  prefix Eigen::Index kelp::vehicle::detail::pseudo_inverse<float>(                           \
      const Eigen::Matrix<float, 6, Eigen::Dynamic>&, Eigen::Matrix<float, Eigen::Dynamic, 6>&);
KELP_TEST_FLOAT_VEHICLE_INSTANCES(extern template)
