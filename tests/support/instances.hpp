// What every test executable shares instead of compiling it again: the double-precision wave
// kernels and coupled-system step, instantiated once (tests/support/instances.cpp, compiled with
// the tests' own flags into kelp_catch_main) and declared extern here. tests/CMakeLists.txt
// includes this header first in every test unit that does not link kelp::sim (which declares
// and provides the same instances itself: kelp/sim/instantiation.hpp). The float and Jet
// instances, and everything else, are still compiled by each test.
#pragma once

#include "kelp/environment/wave_kernels.hpp"

namespace kelp {
namespace environment {
namespace detail {

extern template void wave_accumulate_baseline<double>(const WaveComponentsView&, WaveBlock&, int,
                                                      double, bool);
#ifdef KELP_X86_DISPATCH
extern template void wave_accumulate_avx2<double>(const WaveComponentsView&, WaveBlock&, int,
                                                  double, bool);
extern template void wave_accumulate_avx512<double>(const WaveComponentsView&, WaveBlock&, int,
                                                    double, bool);
extern template void wave_accumulate_avx2_exact<double>(const WaveComponentsView&, WaveBlock&, int,
                                                        double, bool);
#if KELP_PORTABLE_AVX512
extern template void wave_accumulate_avx512_exact<double>(const WaveComponentsView&, WaveBlock&,
                                                          int, double, bool);
#endif
#endif

}  // namespace detail
}  // namespace environment
}  // namespace kelp
