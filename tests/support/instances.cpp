// The instances every test shares (tests/support/instances.hpp, system_instances.hpp), compiled
// once with the tests' own flags (assertions on, EIGEN_RUNTIME_NO_MALLOC).
#include "support/system_instances.hpp"

namespace kelp {
namespace environment {
namespace detail {

template void wave_accumulate_baseline<double>(const WaveComponentsView&, WaveBlock&, int, double,
                                               bool);
#ifdef KELP_X86_DISPATCH
template void wave_accumulate_avx2<double>(const WaveComponentsView&, WaveBlock&, int, double,
                                           bool);
template void wave_accumulate_avx512<double>(const WaveComponentsView&, WaveBlock&, int, double,
                                             bool);
template void wave_accumulate_avx2_exact<double>(const WaveComponentsView&, WaveBlock&, int, double,
                                                 bool);
#if KELP_PORTABLE_AVX512
template void wave_accumulate_avx512_exact<double>(const WaveComponentsView&, WaveBlock&, int,
                                                   double, bool);
#endif
#endif

}  // namespace detail
}  // namespace environment

namespace system {

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
