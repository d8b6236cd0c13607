/// \file
/// \brief KELP_SIM_API: marks what the compiled kelp::sim library exports.
///
/// The library is built with hidden visibility (`-fvisibility=hidden`), so that a shared build
/// (`-DBUILD_SHARED_LIBS=ON`) exports its public API only; every public class and function of
/// kelp::sim carries this mark. In a static build it changes nothing.
#pragma once

#if defined(__GNUC__) || defined(__clang__)
#define KELP_SIM_API __attribute__((visibility("default")))
#else
#define KELP_SIM_API
#endif
