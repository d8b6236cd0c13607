// The coupled system's double-precision step, initial state and energy, instantiated once for
// the tests (tests/support/instances.cpp) and declared extern here, beside the wave kernels of
// instances.hpp: the tests of tests/system/ include this header first instead (their units
// otherwise compile the whole tether and vehicle step again, ~40 CPU s each).
#pragma once

#include "kelp/system/system.hpp"
#include "support/instances.hpp"

namespace kelp {
namespace system {

extern template SystemReport<double> step<double>(const SystemModel<double>&,
                                                  SystemWorkspace<double>&, SystemState<double>&,
                                                  const SystemInputs<double>&, double,
                                                  SystemStepOptions);
extern template SystemState<double> initial_state<double>(const SystemModel<double>&,
                                                          SystemWorkspace<double>&,
                                                          const vehicle::VehicleState<double>&,
                                                          const vehicle::VehicleState<double>&,
                                                          double, tether::StaticOptions<double>);
extern template SystemEnergy<double> energy<double>(const SystemModel<double>&,
                                                    const SystemState<double>&);

}  // namespace system
}  // namespace kelp
