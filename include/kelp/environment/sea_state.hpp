/// \file
/// \brief Sea-state presets `calm`, `moderate` and `rough` from the paper's evaluation, and a
/// builder that turns a sea state into an `Environment`.
///
/// The paper's evaluation table (Buchholz et al., "Tethered Multi-Robot Systems in Marine
/// Environments", Heriot-Watt University) gives "wave height" 3 and 4.5 (written with the
/// unit m/s), wind 3 and 4.5 m/s and current 0.5 and 1.0 m/s. kelp reads the wave height as the
/// SIGNIFICANT wave height Hs [m]. The paper gives no period; kelp picks Tp = 4.5 √Hs (Tp in s,
/// Hs in m), inside the range 3.6 √Hs ≤ Tp ≤ 5 √Hs where DNV-RP-C205 (2010) §3.5.5.5 recommends
/// the JONSWAP spectrum, with that section's peak enhancement γ = exp(5.75 − 1.15 Tp/√Hs):
/// moderate Hs = 3 m, Tp ≈ 7.79 s, γ ≈ 1.77; rough Hs = 4.5 m, Tp ≈ 9.55 s, γ ≈ 1.77.
/// Directions are not in the paper either: waves and wind travel towards north (0 rad), the
/// current flows towards north-east (π/4), so that it has a cross component for a north-going
/// vehicle.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/environment/current.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/environment/spectra.hpp"
#include "kelp/environment/waves.hpp"
#include "kelp/environment/wind.hpp"

namespace kelp {
namespace environment {

/// \brief JONSWAP peak enhancement recommended by DNV-RP-C205 (2010) §3.5.5.5 for a sea of
/// significant height Hs [m] and peak period Tp [s]: γ = 5 for Tp/√Hs ≤ 3.6,
/// exp(5.75 − 1.15 Tp/√Hs) in between, 1 for Tp/√Hs ≥ 5.
/// \param hs significant wave height Hs [m], > 0. \param tp peak period Tp [s], > 0.
/// \return γ in [1, 5].
/// \throws kelp::invalid_argument when hs or tp is not finite and > 0.
inline double dnv_peak_enhancement(double hs, double tp) {
  check_positive(hs, "significant_height");
  check_positive(tp, "peak_period");
  const double r = tp / std::sqrt(hs);
  if (r <= 3.6) return 5.0;
  if (r >= 5.0) return 1.0;
  return std::exp(5.75 - 1.15 * r);
}

/// \brief The numbers that define a sea state.
struct SeaState {
  double significant_height = 0.0;  ///< Hs [m]
  double peak_period = 8.0;         ///< Tp [s]
  double peak_enhancement = 1.0;    ///< JONSWAP γ [-]
  double wave_direction = 0.0;      ///< NED azimuth the waves travel towards [rad]
  double wind_speed = 0.0;          ///< mean U₁₀ [m/s]
  double wind_direction = 0.0;      ///< NED azimuth the wind blows towards [rad]
  double current_speed = 0.0;       ///< surface current [m/s]
  double current_direction = 0.0;   ///< NED azimuth the current flows towards [rad]
  /// Regular (Airy) waves on top of the JONSWAP sea, or alone when significant_height = 0
  /// (WaveFieldParameters::regular; none by default).
  std::vector<RegularWave> regular_waves;
};

/// \brief How `make_environment` discretises a sea state.
struct SeaStateOptions {
  int wave_components = 64;                  ///< wave components N
  int gust_components = 64;                  ///< wind gust components
  double spreading = 0.0;                    ///< directional spreading exponent s (0: long-crested)
  GustSpectrum gust = GustSpectrum::harris;  ///< gust spectrum (none for a steady wind)
  std::uint64_t seed = 1;                    ///< seed of waves (seed) and gusts (seed + 1)
  double seabed_depth = std::numeric_limits<double>::infinity();  ///< flat seabed [m]
  /// Start-up ramp T [s]: waves, current and wind come in over [0, T] (Environment::set_ramp;
  /// 0: the full sea from t = 0).
  double ramp = 0.0;
  /// Kinematics near the free surface, for the spectral and the regular waves alike
  /// (WaveFieldParameters::stretching: vertical extrapolation by default, or Wheeler's).
  WaveStretching stretching = WaveStretching::vertical;
};

namespace presets {

/// \brief Still water: no waves, wind or current.
/// \return the sea state.
inline SeaState calm() { return SeaState{}; }

/// \brief Builds the paper's sea state from its table row (wave height read as Hs; see file).
/// \param hs significant wave height [m], > 0 (Tp = 4.5 √Hs s, γ by dnv_peak_enhancement).
/// \param wind mean wind speed at 10 m [m/s]. \param current current speed [m/s] (both towards
/// the north-east, as the paper's figures). \return the sea state.
/// \throws kelp::invalid_argument when hs is not finite and > 0.
inline SeaState paper_sea_state(double hs, double wind, double current) {
  SeaState s;
  s.significant_height = hs;
  s.peak_period = 4.5 * std::sqrt(hs);
  s.peak_enhancement = dnv_peak_enhancement(hs, s.peak_period);
  s.wave_direction = 0.0;
  s.wind_speed = wind;
  s.wind_direction = 0.0;
  s.current_speed = current;
  s.current_direction = 0.25 * kelp::pi;
  return s;
}

/// \brief The paper's moderate sea: Hs = 3 m, Tp ≈ 7.79 s, wind 3 m/s, current 0.5 m/s.
/// \return the sea state (make_environment builds its Environment).
inline SeaState moderate() { return paper_sea_state(3.0, 3.0, 0.5); }

/// \brief The paper's rough sea: Hs = 4.5 m, Tp ≈ 9.55 s, wind 4.5 m/s, current 1.0 m/s.
/// \return the sea state (make_environment builds its Environment).
inline SeaState rough() { return paper_sea_state(4.5, 4.5, 1.0); }

}  // namespace presets

/// \brief An environment for a sea state: JONSWAP waves (and any regular waves), wind with
/// gusts and a constant, depth-uniform current, in seawater with standard gravity.
/// \tparam Scalar double or float.
/// \param s the sea state (heights [m], periods [s], speeds [m/s], NED azimuths [rad]).
/// \param o how the sea is built (wave and gust components, seed, spreading, seabed, ramp,
/// stretching).
/// \return the environment, ready for `sample` and the tether's and vehicles' steps.
/// \throws kelp::invalid_argument naming the bad field.
template <typename Scalar>
Environment<Scalar> make_environment(const SeaState& s, const SeaStateOptions& o = {}) {
  Environment<Scalar> env;
  env.set_seabed_depth(Scalar(o.seabed_depth));
  env.set_ramp(o.ramp);
  WaveFieldParameters w;
  w.spectrum.kind = SpectrumKind::jonswap;
  w.spectrum.significant_height = s.significant_height;
  w.spectrum.peak_period = s.peak_period;
  w.spectrum.peak_enhancement = s.peak_enhancement;
  w.n_components = o.wave_components;
  w.seed = o.seed;
  w.direction = s.wave_direction;
  w.spreading = o.spreading;
  w.depth = o.seabed_depth;
  w.gravity = kelp::standard_gravity;
  w.regular = s.regular_waves;
  w.stretching = o.stretching;
  env.set_waves(WaveField<Scalar>(w));
  WindParameters wp;
  wp.speed = s.wind_speed;
  wp.direction = s.wind_direction;
  wp.gust = o.gust;
  wp.n_components = o.gust_components;
  wp.seed = o.seed + 1;
  env.set_wind(WindField<Scalar>(wp));
  CurrentParameters cp;
  cp.speed = s.current_speed;
  cp.direction = s.current_direction;
  env.set_current(CurrentModel<Scalar>(cp));
  return env;
}

}  // namespace environment
}  // namespace kelp
