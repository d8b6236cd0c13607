/// \file
/// \brief Wave spectra (Pierson–Moskowitz, JONSWAP) and the linear dispersion relation.
///
/// Spectra are one-sided wave-elevation spectra S(ω) [m² s / rad] over the angular frequency ω
/// [rad/s], parametrised by the significant wave height Hs [m] and the peak period Tp [s], so that
/// the elevation variance is m₀ = ∫ S(ω) dω = Hs² / 16.
#pragma once

#include <algorithm>
#include <cmath>
#include <sstream>

#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/environment/limits.hpp"

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
  double significant_height = 0.0;            ///< Hs [m] (0 ≤ Hs ≤ 100; 0 means a calm sea)
  double peak_period = 8.0;                   ///< Tp [s] (0.1 ≤ Tp ≤ 1000)
  double peak_enhancement = 3.3;              ///< JONSWAP γ [-] (1 ≤ γ ≤ 20; ignored by PM)
};

/// \brief Throws `kelp::invalid_argument` naming the field and its value unless the spectrum is
/// usable: 0 ≤ Hs ≤ 100 m, 0.1 s ≤ Tp ≤ 1000 s, 1 ≤ γ ≤ 20 (the generous physical bounds of
/// `kelp::environment::limits`; beyond them the spectral moments and the wave numbers of the
/// discretised sea overflow, or the JONSWAP normalisation turns the spectrum negative).
/// \throws kelp::invalid_argument when a field is NaN, infinite or out of those bounds.
/// \param s the spectrum (kind, Hs [m], Tp [s], γ [-]).
inline void validate(const WaveSpectrum& s) {
  detail::check_in_range(s.significant_height, 0.0, limits::max_significant_height,
                         "significant_height", "finite and in [0, 100] m");
  detail::check_in_range(s.peak_period, limits::min_peak_period, limits::max_peak_period,
                         "peak_period", "finite and in [0.1, 1000] s");
  detail::check_in_range(s.peak_enhancement, 1.0, limits::max_peak_enhancement, "peak_enhancement",
                         "finite and in [1, 20]");
}

namespace detail {
/// The preconditions shared by the spectra: ω not NaN, Hs finite and ≥ 0, Tp finite and > 0.
template <typename Scalar>
void check_spectrum_arguments(const Scalar& omega, const Scalar& hs, const Scalar& tp) {
  KELP_CHECK(!std::isnan(value_of(omega)), "spectrum: omega must not be NaN");
  check_non_negative(hs, "significant_height");
  check_positive(tp, "peak_period");
}
}  // namespace detail

/// \brief Pierson–Moskowitz spectrum in (Hs, Tp) form [m² s / rad].
///
/// \f$ S(\omega) = \frac{5}{16} H_s^2 \omega_p^4 \omega^{-5}
///     \exp\!\left(-\frac{5}{4}(\omega_p/\omega)^4\right) \f$, ω_p = 2π/Tp
/// (DNV-RP-C205 (2010) eq. 3.5.5.1; Fossen 2021 §10.2.1, modified PM). Its integral is exactly
/// Hs²/16. \tparam Scalar double, float or a Jet. \param[in] omega angular frequency [rad/s]
/// (S = 0 for ω ≤ 0 and ω = +∞) \param[in] hs significant wave height [m] \param[in] tp peak
/// period [s]
/// Where (ω_p/ω)⁴ > 10⁴ the factor e^{−1.25 (ω_p/ω)⁴} < 10⁻⁵⁰⁰⁰ and S is exactly 0 in double
/// (also when ω_p/ω overflows, e.g. for a tiny Tp), never ∞ · 0 = NaN.
/// \throws kelp::invalid_argument when ω is NaN, Hs is negative or not finite, Tp is not finite
/// and > 0, or S(ω) overflows (Hs so large that Hs² is not finite).
/// \return S(ω) [m² s / rad], ≥ 0.
template <typename Scalar>
Scalar pierson_moskowitz(const Scalar& omega, const Scalar& hs, const Scalar& tp) {
  using std::exp;
  detail::check_spectrum_arguments(omega, hs, tp);
  if (!(value_of(omega) > 0.0) || std::isinf(value_of(omega))) return Scalar(0);
  const Scalar wp = Scalar(2.0 * kelp::pi) / tp;
  const Scalar r = wp / omega;
  const Scalar r4 = (r * r) * (r * r);
  if (!(value_of(r4) <= 1e4)) return Scalar(0);
  const Scalar s = Scalar(5.0 / 16.0) * hs * hs * r4 / omega * exp(Scalar(-1.25) * r4);
  if (!is_finite(s)) {
    std::ostringstream msg;
    msg << "pierson_moskowitz: S(omega) is not finite for significant_height = " << value_of(hs)
        << " m, peak_period = " << value_of(tp) << " s, omega = " << value_of(omega) << " rad/s";
    ::kelp::detail::throw_invalid_argument(msg.str());
  }
  return s;
}

/// \brief The JONSWAP normalising factor A_γ = 1 − 0.287 ln γ (DNV-RP-C205 (2010) eq. 3.5.5.4),
/// which makes the JONSWAP variance Hs²/16 to within about 1 % for 1 ≤ γ ≤ 7.
/// \throws kelp::invalid_argument unless 1 ≤ γ ≤ 20 (`limits::max_peak_enhancement`; γ < 1 is
/// not a peak enhancement, and A_γ reaches 0 at γ ≈ 32.6).
/// \param gamma the peak enhancement γ [-]. \return A_γ [-], in (0.14, 1].
inline double jonswap_normalisation(double gamma) {
  detail::check_in_range(gamma, 1.0, limits::max_peak_enhancement, "peak_enhancement",
                         "finite and in [1, 20]");
  return 1.0 - 0.287 * std::log(gamma);
}

/// \brief JONSWAP spectrum [m² s / rad] with peak enhancement γ.
///
/// \f$ S_J(\omega) = A_\gamma S_{PM}(\omega)\,
///     \gamma^{\exp(-(\omega-\omega_p)^2 / (2\sigma^2\omega_p^2))} \f$ with σ = 0.07 for
/// ω ≤ ω_p and 0.09 above, A_γ = 1 − 0.287 ln γ (DNV-RP-C205 (2010) §3.5.5). γ = 1 gives PM.
/// \param[in] omega [rad/s] \param[in] hs [m] \param[in] tp [s] \param[in] gamma γ [-] (1–20)
/// \throws kelp::invalid_argument when ω is NaN, Hs is negative or not finite, Tp is not finite
/// and > 0, or γ is not in [1, 20] (γ = 0 or NaN included).
/// \return S_J(ω) [m² s / rad], ≥ 0.
template <typename Scalar>
Scalar jonswap(const Scalar& omega, const Scalar& hs, const Scalar& tp, double gamma) {
  using std::exp;
  using std::log;
  detail::check_spectrum_arguments(omega, hs, tp);
  const double a_gamma = jonswap_normalisation(gamma);
  const Scalar pm = pierson_moskowitz(omega, hs, tp);
  // S_PM = 0 also covers ω ≤ 0 and an ω_p that overflows (then d below would be NaN).
  if (value_of(pm) == 0.0) return Scalar(0);
  const Scalar wp = Scalar(2.0 * kelp::pi) / tp;
  const double sigma = value_of(omega) <= value_of(wp) ? 0.07 : 0.09;
  const Scalar d = (omega - wp) / (Scalar(sigma) * wp);
  const Scalar peak = exp(Scalar(std::log(gamma)) * exp(Scalar(-0.5) * d * d));
  return Scalar(a_gamma) * pm * peak;
}

/// \brief S(ω) of a `WaveSpectrum` [m² s / rad] (0 for ω ≤ 0).
/// \throws kelp::invalid_argument as `pierson_moskowitz` / `jonswap` (NaN ω, bad Hs, Tp or γ).
/// \param s the spectrum. \param omega angular frequency [rad/s].
/// \return S(ω) [m² s / rad], ≥ 0.
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
/// \throws kelp::invalid_argument when ω or g is not finite and > 0, the depth is NaN or ≤ 0,
/// or the wave number ω²/g overflows or underflows (is not finite and > 0; e.g. ω = 1e200).
/// \return k [rad/m], > 0.
inline double wave_number(double omega, double g, double depth) {
  check_positive(omega, "omega");
  check_positive(g, "gravity");
  KELP_CHECK(!std::isnan(depth) && depth > 0.0, "depth must be > 0 (or +infinity)");
  const double k_deep = omega * omega / g;
  if (!(std::isfinite(k_deep) && k_deep > 0.0)) {
    std::ostringstream msg;
    msg << "wave_number: omega = " << omega << " rad/s and gravity = " << g
        << " m/s^2 give a wave number omega^2/g that is not finite and > 0";
    ::kelp::detail::throw_invalid_argument(msg.str());
  }
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
/// \throws kelp::invalid_argument when k is negative or not finite, g is not finite and > 0, the
/// depth is NaN or ≤ 0, or g k overflows.
/// \param k wave number [rad/m]. \param g gravity [m/s²]. \param depth water depth h [m] (+∞:
/// deep water). \return ω [rad/s], ≥ 0.
inline double wave_frequency(double k, double g, double depth) {
  check_non_negative(k, "wave number k");
  check_positive(g, "gravity");
  KELP_CHECK(!std::isnan(depth) && depth > 0.0, "depth must be > 0 (or +infinity)");
  KELP_CHECK(std::isfinite(g * k), "wave_frequency: g k overflows");
  if (std::isinf(depth)) return std::sqrt(g * k);
  return std::sqrt(g * k * std::tanh(k * depth));
}

}  // namespace environment
}  // namespace kelp
