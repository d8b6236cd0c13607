// The double-precision coupled system, instantiated once for every user of kelp::sim
// (kelp/sim/instantiation.hpp declares what is here).
#include "kelp/sim/instantiation.hpp"

namespace kelp {
namespace system {

template class SystemModel<double>;
template struct SystemWorkspace<double>;
template SystemReport<double> step<double>(const SystemModel<double>&, SystemWorkspace<double>&,
                                           SystemState<double>&, const SystemInputs<double>&,
                                           double, SystemStepOptions);
template SystemState<double> initial_state<double>(const SystemModel<double>&,
                                                   SystemWorkspace<double>&,
                                                   const vehicle::VehicleState<double>&,
                                                   const vehicle::VehicleState<double>&, double,
                                                   tether::StaticOptions<double>);
template SystemEnergy<double> energy<double>(const SystemModel<double>&,
                                             const SystemState<double>&);

}  // namespace system
}  // namespace kelp
