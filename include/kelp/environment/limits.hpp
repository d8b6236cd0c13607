/// \file
/// \brief Physical bounds on the parameters of the sea, the air and the vehicles that share its
/// water, and the range check that names a parameter and its value.
///
/// The bounds are generous: every sea, fluid and planet kelp is meant for lies well inside them,
/// with a wide margin. A value outside them is a unit mistake or garbage, and it would make a
/// derived quantity (spectral moments, wave numbers, amplitudes, buoyancy, accelerations)
/// overflow to ±Inf or turn into NaN long after the parameter was accepted. Models check them
/// where they are built; `kelp::invalid_argument` then names the parameter and the value.
#pragma once

#include <cmath>
#include <sstream>
#include <string>

#include "kelp/core/error.hpp"

namespace kelp {
namespace environment {
namespace limits {

/// Largest significant wave height Hs [m]. The largest Hs ever measured is about 19 m (North
/// Atlantic, 2013) and the highest single waves about 30 m; 100 m is several times that.
inline constexpr double max_significant_height = 100.0;
/// Smallest peak period Tp [s]. A 0.1 s wave is 1.6 cm long, already a capillary ripple rather
/// than a gravity wave (model-basin seas at 1:50 scale have Tp ≈ 1 s).
inline constexpr double min_peak_period = 0.1;
/// Largest peak period Tp [s]. Ocean swell stays below about 30 s; 1000 s is far beyond any
/// wind sea (tides and tsunamis are not spectral seas).
inline constexpr double max_peak_period = 1000.0;
/// Largest JONSWAP peak enhancement γ [-]. Measured seas have γ ≈ 1–7 (DNV-RP-C205 (2010)
/// §3.5.5.5 gives at most 5); the normalising factor A_γ = 1 − 0.287 ln γ falls to 0 at
/// γ ≈ 32.6, beyond which the spectrum would turn negative.
inline constexpr double max_peak_enhancement = 20.0;
/// Largest fluid (water or air) density [kg/m³]. Seawater is about 1025, brines about 1240,
/// mercury 13 546 and osmium, the densest element, 22 590.
inline constexpr double max_fluid_density = 1.0e5;
/// Largest gravitational acceleration [m/s²]: 100 g (the Sun's surface has 274 m/s²).
inline constexpr double max_gravity = 1000.0;
/// Largest mean wind speed U₁₀ [m/s]. The highest gust ever measured is 113 m/s.
inline constexpr double max_wind_speed = 200.0;
/// Largest current speed [m/s]. The fastest tidal races run at about 11 m/s.
inline constexpr double max_current_speed = 50.0;
/// Largest directional spreading exponent s of D(θ) ∝ cos^{2s}(θ − β̄) [-]. Swell reaches
/// s ≈ 75 (Mitsuyasu et al. 1975); at s = 1000 the spreading is ±2°, and beyond it the rejection
/// sampling of the directions would spin for nothing.
inline constexpr double max_spreading = 1000.0;
/// Largest number of components of a wave, gust or current-variation sum. A few hundred suffice
/// for any spectrum; the bound stops a typo from allocating gigabytes (a wave field keeps 22
/// doubles per component: 184 MB at this bound).
inline constexpr int max_components = 1 << 20;

}  // namespace limits

namespace detail {

/// Throws `kelp::invalid_argument`: "<field> must be <requirement> (got <value>)".
[[noreturn]] inline KELP_COLD void throw_bad_value(const char* field, const char* requirement,
                                                   double value) {
  std::ostringstream msg;
  msg.precision(9);
  msg << field << " must be " << requirement << " (got " << value << ")";
  ::kelp::detail::throw_invalid_argument(msg.str());
}

/// Throws `kelp::invalid_argument` naming `field` and the value unless lo ≤ x ≤ hi (NaN fails).
/// `requirement` describes the range for the message, e.g. "finite and in [0, 100] m".
inline void check_in_range(double x, double lo, double hi, const char* field,
                           const char* requirement) {
  if (!(x >= lo && x <= hi)) throw_bad_value(field, requirement, x);
}

/// Throws `kelp::invalid_argument` naming `field` and the value unless 0 < x ≤ hi.
inline void check_positive_at_most(double x, double hi, const char* field,
                                   const char* requirement) {
  if (!(x > 0.0 && x <= hi)) throw_bad_value(field, requirement, x);
}

}  // namespace detail
}  // namespace environment
}  // namespace kelp
