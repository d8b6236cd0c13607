/// \file
/// \brief Wave spectra (Pierson–Moskowitz, JONSWAP) and the linear dispersion relation.
///
/// Spectra are one-sided wave-elevation spectra S(ω) [m² s / rad] over the angular frequency ω
/// [rad/s], parametrised by the significant wave height Hs [m] and the peak period Tp [s], so that
/// the elevation variance is m₀ = ∫ S(ω) dω = Hs² / 16.
#pragma once

#include <algorithm>
#include <cmath>

#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"

namespace kelp {
namespace environment {

/// \brief Which spectral shape a sea uses.
enum class SpectrumKind {
  pierson_moskowitz,  ///< two-parameter (Hs, Tp) Pierson–Moskowitz / ITTC / Bretschneider form
  jonswap             ///< JONSWAP: Pierson–Moskowitz times a peak enhancement γ^r
};

/// \brief Parameters of a wave spectrum.
struct WaveSpectrum {
  SpectrumKind kind = SpectrumKind::jonswap;  ///< spectral shape
  double significant_height = 0.0;            ///< Hs [m] (≥ 0; 0 means a calm sea)
  double peak_period = 8.0;                   ///< Tp [s] (> 0)
  double peak_enhancement = 3.3;              ///< JONSWAP γ [-] (≥ 1; ignored by PM)
};

/// \brief Throws `kelp::invalid_argument` naming the field unless the spectrum is usable:
/// Hs finite and ≥ 0, Tp finite and > 0, γ finite and ≥ 1.
inline void validate(const WaveSpectrum& s) {
  check_non_negative(s.significant_height, "significant_height");
  check_positive(s.peak_period, "peak_period");
  KELP_CHECK(std::isfinite(s.peak_enhancement) && s.peak_enhancement >= 1.0,
             "peak_enhancement must be finite and >= 1");
}

/// \brief Pierson–Moskowitz spectrum in (Hs, Tp) form [m² s / rad].
///
/// \f$ S(\omega) = \frac{5}{16} H_s^2 \omega_p^4 \omega^{-5}
///     \exp\!\left(-\frac{5}{4}(\omega_p/\omega)^4\right) \f$, ω_p = 2π/Tp
/// (DNV-RP-C205 (2010) eq. 3.5.5.1; Fossen 2021 §10.2.1, modified PM). Its integral is exactly
/// Hs²/16. \tparam Scalar double, float or a Jet. \param[in] omega angular frequency [rad/s]
/// \param[in] hs significant wave height [m] \param[in] tp peak period [s]
template <typename Scalar>
Scalar pierson_moskowitz(const Scalar& omega, const Scalar& hs, const Scalar& tp) {
  using std::exp;
  if (!(value_of(omega) > 0.0)) return Scalar(0);
  const Scalar wp = Scalar(2.0 * kelp::pi) / tp;
  const Scalar r = wp / omega;
  const Scalar r4 = (r * r) * (r * r);
  return Scalar(5.0 / 16.0) * hs * hs * r4 / omega * exp(Scalar(-1.25) * r4);
}

/// \brief The JONSWAP normalising factor A_γ = 1 − 0.287 ln γ (DNV-RP-C205 (2010) eq. 3.5.5.4),
/// which makes the JONSWAP variance Hs²/16 to within about 1 % for 1 ≤ γ ≤ 7.
inline double jonswap_normalisation(double gamma) { return 1.0 - 0.287 * std::log(gamma); }

/// \brief JONSWAP spectrum [m² s / rad] with peak enhancement γ.
///
/// \f$ S_J(\omega) = A_\gamma S_{PM}(\omega)\,
///     \gamma^{\exp(-(\omega-\omega_p)^2 / (2\sigma^2\omega_p^2))} \f$ with σ = 0.07 for
/// ω ≤ ω_p and 0.09 above, A_γ = 1 − 0.287 ln γ (DNV-RP-C205 (2010) §3.5.5). γ = 1 gives PM.
/// \param[in] omega [rad/s] \param[in] hs [m] \param[in] tp [s] \param[in] gamma γ [-] (≥ 1)
template <typename Scalar>
Scalar jonswap(const Scalar& omega, const Scalar& hs, const Scalar& tp, double gamma) {
  using std::exp;
  using std::log;
  if (!(value_of(omega) > 0.0)) return Scalar(0);
  const Scalar wp = Scalar(2.0 * kelp::pi) / tp;
  const double sigma = value_of(omega) <= value_of(wp) ? 0.07 : 0.09;
  const Scalar d = (omega - wp) / (Scalar(sigma) * wp);
  const Scalar peak = exp(Scalar(std::log(gamma)) * exp(Scalar(-0.5) * d * d));
  return Scalar(jonswap_normalisation(gamma)) * pierson_moskowitz(omega, hs, tp) * peak;
}

/// \brief S(ω) of a `WaveSpectrum` [m² s / rad] (0 for ω ≤ 0).
inline double spectral_density(const WaveSpectrum& s, double omega) {
  if (s.kind == SpectrumKind::pierson_moskowitz)
    return pierson_moskowitz(omega, s.significant_height, s.peak_period);
  return jonswap(omega, s.significant_height, s.peak_period, s.peak_enhancement);
}

/// \brief Wave number k [rad/m] from the linear dispersion relation ω² = g k tanh(k h).
///
/// Deep water (h = +∞, or k h > 20 where tanh differs from 1 by < 1e-17): k = ω²/g
/// (Fossen 2021 §10.2; DNV-RP-C205 eq. 3.2.2). Finite depth: Newton iteration on
/// f(k) = g k tanh(k h) − ω² from the larger of the deep- and shallow-water estimates. Both lie
/// below the root (tanh x < 1 and tanh x < x); f is increasing, so Newton converges in a few
/// iterations (the tests check the relation to 1e-13 for depths of 1–500 m).
/// \param[in] omega angular frequency [rad/s] (> 0) \param[in] g gravity [m/s²] (> 0)
/// \param[in] depth water depth h [m] (> 0, +∞ for deep water)
inline double wave_number(double omega, double g, double depth) {
  check_positive(omega, "omega");
  check_positive(g, "gravity");
  KELP_CHECK(!std::isnan(depth) && depth > 0.0, "depth must be > 0 (or +infinity)");
  const double k_deep = omega * omega / g;
  if (std::isinf(depth) || k_deep * depth > 20.0) return k_deep;
  // Start from the larger of the deep- and shallow-water estimates (both ≤ the root).
  double k = std::max(k_deep, omega / std::sqrt(g * depth));
  for (int it = 0; it < 100; ++it) {
    const double th = std::tanh(k * depth);
    const double f = g * k * th - omega * omega;
    const double df = g * th + g * k * depth * (1.0 - th * th);
    const double step = f / df;
    k -= step;
    if (std::abs(step) <= 1e-15 * k) break;
  }
  return k;
}

/// \brief Angular frequency ω [rad/s] of a wave of number k [rad/m] in depth h [m]:
/// ω = √(g k tanh(k h)) (deep water when h = +∞).
inline double wave_frequency(double k, double g, double depth) {
  if (std::isinf(depth)) return std::sqrt(g * k);
  return std::sqrt(g * k * std::tanh(k * depth));
}

}  // namespace environment
}  // namespace kelp
