/// \file
/// \brief The double-precision coupled system that kelp::sim runs, instantiated once in the
/// compiled library (src/instantiation.cpp): a program on kelp::sim that calls
/// `kelp::system::step`, `initial_state` or `energy` on doubles links the library's code instead
/// of compiling the system's templates again (Pinocchio's explicit-instantiation pattern; the
/// classes' inline members are left to the compiler). kelp::kelp stays header-only for every
/// scalar: these declarations are kelp::sim's, seen only by its consumers, who link it.
#pragma once

#include "kelp/environment/wave_kernels.hpp"
#include "kelp/sim/export.hpp"
#include "kelp/system/system.hpp"

namespace kelp {
namespace environment {
namespace detail {

// The wave kernel for each instruction set (kelp/environment/wave_kernels.hpp).
extern template KELP_SIM_API void wave_accumulate_baseline<double>(const WaveComponentsView&,
                                                                   WaveBlock&, int, double, bool);
#ifdef KELP_X86_DISPATCH
extern template KELP_SIM_API void wave_accumulate_avx2<double>(const WaveComponentsView&,
                                                               WaveBlock&, int, double, bool);
extern template KELP_SIM_API void wave_accumulate_avx512<double>(const WaveComponentsView&,
                                                                 WaveBlock&, int, double, bool);
extern template KELP_SIM_API void wave_accumulate_avx2_exact<double>(const WaveComponentsView&,
                                                                     WaveBlock&, int, double, bool);
#if KELP_PORTABLE_AVX512
extern template KELP_SIM_API void wave_accumulate_avx512_exact<double>(const WaveComponentsView&,
                                                                       WaveBlock&, int, double,
                                                                       bool);
#endif
#endif

}  // namespace detail
}  // namespace environment

namespace system {

extern template KELP_SIM_API SystemReport<double> step<double>(const SystemModel<double>&,
                                                               SystemWorkspace<double>&,
                                                               SystemState<double>&,
                                                               const SystemInputs<double>&, double,
                                                               SystemStepOptions);
extern template KELP_SIM_API SystemState<double> initial_state<double>(
    const SystemModel<double>&, SystemWorkspace<double>&, const vehicle::VehicleState<double>&,
    const vehicle::VehicleState<double>&, double, tether::StaticOptions<double>);
extern template KELP_SIM_API SystemEnergy<double> energy<double>(const SystemModel<double>&,
                                                                 const SystemState<double>&);

}  // namespace system
}  // namespace kelp
