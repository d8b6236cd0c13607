/// \file
/// \brief The double-precision coupled system that kelp::sim runs, instantiated once in the
/// compiled library (src/instantiation.cpp): a program on kelp::sim that calls
/// `kelp::system::step`, `initial_state` or `energy` on doubles, or builds a `SystemModeld` and
/// its workspace, links the library's code instead of compiling the system's templates again
/// (Pinocchio's explicit-instantiation pattern). kelp::kelp stays header-only for every scalar:
/// these declarations are kelp::sim's, seen only by its consumers, who link it.
#pragma once

#include "kelp/sim/export.hpp"
#include "kelp/system/system.hpp"

namespace kelp {
namespace system {

extern template class KELP_SIM_API SystemModel<double>;
extern template struct KELP_SIM_API SystemWorkspace<double>;
extern template KELP_SIM_API SystemReport<double> step<double>(const SystemModel<double>&,
                                                               SystemWorkspace<double>&,
                                                               SystemState<double>&,
                                                               const SystemInputs<double>&,
                                                               double, SystemStepOptions);
extern template KELP_SIM_API SystemState<double> initial_state<double>(
    const SystemModel<double>&, SystemWorkspace<double>&, const vehicle::VehicleState<double>&,
    const vehicle::VehicleState<double>&, double, tether::StaticOptions<double>);
extern template KELP_SIM_API SystemEnergy<double> energy<double>(const SystemModel<double>&,
                                                                 const SystemState<double>&);

}  // namespace system
}  // namespace kelp
