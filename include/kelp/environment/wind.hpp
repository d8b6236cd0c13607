/// \file
/// \brief Wind: a mean wind with gusts from a wind spectrum (Harris or
/// NORSEPP) with seeded phases, and the wind forces and yaw moment on a surface vessel from
/// coefficients (constant-coefficient model by default, an Isherwood-style table as option). The
/// paper's wind force formula is in `kelp/environment/paper.hpp`.
///
/// Frames: world NED; body x forward, y starboard, z down. The wind velocity is the velocity of
/// the air (the direction it blows TOWARDS), horizontal, at 10 m above the sea. Units SI.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <sstream>
#include <type_traits>
#include <vector>

#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/fast_math.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/environment/limits.hpp"

namespace kelp {
namespace environment {

/// \brief Harris wind-gust spectrum S(f) [(m/s)²/Hz] at frequency f [Hz]:
/// \f$ S(f) = \frac{4\kappa L U_{10}}{(2 + \tilde f^2)^{5/6}},\ \tilde f = L f / U_{10} \f$
/// with L = 1800 m and the surface drag coefficient κ = 0.0026 (Harris 1971, as given in
/// Fossen 2021 §10.1.3). Its integral over f ∈ (0, ∞) is ≈ 0.01736 U₁₀² (σ_u ≈ 0.13 U₁₀).
/// S = 0 for f ≤ 0 or U₁₀ ≤ 0.
/// \param f Frequency [Hz].
/// \param u10 Mean wind speed U₁₀ at 10 m [m/s].
/// \param length Length scale L [m] (default 1800 m).
/// \param kappa Surface drag coefficient κ [-] (default 0.0026).
/// \return S(f) [(m/s)²/Hz], ≥ 0.
/// \throws kelp::invalid_argument when f or U₁₀ is not finite, or L or κ is not finite and > 0.
inline double harris_spectrum(double f, double u10, double length = 1800.0, double kappa = 0.0026) {
  check_finite(f, "harris_spectrum: f");
  check_finite(u10, "harris_spectrum: u10");
  check_positive(length, "harris_spectrum: length");
  check_positive(kappa, "harris_spectrum: kappa");
  if (!(f > 0.0) || !(u10 > 0.0)) return 0.0;
  const double ft = length * f / u10;
  return 4.0 * kappa * length * u10 / std::pow(2.0 + ft * ft, 5.0 / 6.0);
}

/// \brief NORSEPP (Norwegian Petroleum Directorate / NORSOK N-003) wind spectrum
/// S(f) [(m/s)²/Hz] at height z [m]:
/// \f$ S(f) = \frac{320 (U_{10}/10)^2 (z/10)^{0.45}}{(1 + \tilde f^n)^{5/(3n)}},\quad
/// \tilde f = 172 f (z/10)^{2/3} (U_{10}/10)^{-3/4},\ n = 0.468 \f$
/// (NORSOK N-003 (2007) §6.3; DNV-RP-C205 (2010) eq. 2.3.2.12). S = 0 for f ≤ 0 or U₁₀ ≤ 0.
/// \param f Frequency [Hz].
/// \param u10 Mean wind speed U₁₀ at 10 m [m/s].
/// \param z Height above the sea surface [m] (default 10 m).
/// \return S(f) [(m/s)²/Hz], ≥ 0.
/// \throws kelp::invalid_argument when f or U₁₀ is not finite, or z is not finite and > 0.
inline double norsepp_spectrum(double f, double u10, double z = 10.0) {
  check_finite(f, "norsepp_spectrum: f");
  check_finite(u10, "norsepp_spectrum: u10");
  check_positive(z, "norsepp_spectrum: z");
  if (!(f > 0.0) || !(u10 > 0.0)) return 0.0;
  constexpr double n = 0.468;
  const double ft = 172.0 * f * std::pow(z / 10.0, 2.0 / 3.0) * std::pow(u10 / 10.0, -0.75);
  return 320.0 * (u10 / 10.0) * (u10 / 10.0) * std::pow(z / 10.0, 0.45) /
         std::pow(1.0 + std::pow(ft, n), 5.0 / (3.0 * n));
}

/// \brief Which gust spectrum a wind uses.
enum class GustSpectrum {
  none,    ///< steady mean wind
  harris,  ///< `harris_spectrum`
  norsepp  ///< `norsepp_spectrum` at 10 m
};

/// \brief A wind field: mean speed and direction plus longitudinal gusts.
struct WindParameters {
  double speed = 0.0;      ///< mean speed U₁₀ at 10 m [m/s] (0 ≤ U₁₀ ≤ 200)
  double direction = 0.0;  ///< NED azimuth the air moves TOWARDS [rad]
  GustSpectrum gust = GustSpectrum::none;  ///< gust spectrum
  int n_components = 64;                   ///< number of gust components (≥ 1)
  double f_min = 1e-4;     ///< lower end of the gust band [Hz] (> 0); frequencies are log-spaced
  double f_max = 1.0;      ///< upper end of the gust band [Hz] (> f_min)
  std::uint64_t seed = 1;  ///< seed of the gust phases (std::mt19937_64)
};

/// \brief Throws `kelp::invalid_argument` naming the bad field of `p`.
/// \throws kelp::invalid_argument when the speed is not in [0, 200] m/s
/// (`limits::max_wind_speed`), the direction is not finite, n_components is not in [1, 2^20]
/// (`limits::max_components`), f_min is not finite and > 0, or f_max is not finite and > f_min.
/// \param p Wind parameters to check.
inline void validate(const WindParameters& p) {
  detail::check_in_range(p.speed, 0.0, limits::max_wind_speed, "wind speed",
                         "finite and in [0, 200] m/s");
  check_finite(p.direction, "wind direction");
  KELP_CHECK(p.n_components >= 1 && p.n_components <= limits::max_components,
             "wind n_components must be >= 1 and <= 1048576");
  check_positive(p.f_min, "f_min");
  KELP_CHECK(std::isfinite(p.f_max) && p.f_max > p.f_min, "f_max must be finite and > f_min");
}

/// \brief Mean wind plus gusts u_g(t) = Σ a_j cos(2π f_j t + φ_j) along the mean direction,
/// a_j = √(2 ∫_bin S df) over log-spaced bins, φ_j seeded. Queries are `const` and
/// allocation-free.
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
class WindField {
 public:
  /// \brief No wind.
  WindField() = default;
  /// \brief Builds the gust components.
  /// \param p Wind parameters (copied); no gust components when gust is `none` or the speed 0.
  /// \throws kelp::invalid_argument naming the bad field, or naming f_min and f_max with their
  /// values when a gust frequency or amplitude is not finite (e.g. f_max = 1e300).
  explicit WindField(const WindParameters& p) : params_(p) {
    validate(p);
    cos_dir_ = std::cos(p.direction);
    sin_dir_ = std::sin(p.direction);
    if (p.gust == GustSpectrum::none || p.speed == 0.0) return;
    const auto n = static_cast<std::size_t>(p.n_components);
    std::mt19937_64 rng(p.seed);
    const double ratio = std::pow(p.f_max / p.f_min, 1.0 / static_cast<double>(n));
    omega_.resize(n);
    amp_.resize(n);
    phase_.resize(n);
    auto spectrum = [&p](double f) {
      return p.gust == GustSpectrum::harris ? harris_spectrum(f, p.speed)
                                            : norsepp_spectrum(f, p.speed);
    };
    for (std::size_t j = 0; j < n; ++j) {
      const double f0 = p.f_min * std::pow(ratio, static_cast<double>(j)), f1 = f0 * ratio;
      // Bin energy by Simpson's rule on 16 sub-intervals; the frequency sits at the geometric
      // centre of the bin.
      constexpr int m = 16;
      const double h = (f1 - f0) / m;
      double sum = spectrum(f0) + spectrum(f1);
      for (int i = 1; i < m; ++i) sum += (i % 2 ? 4.0 : 2.0) * spectrum(f0 + i * h);
      amp_[j] = std::sqrt(2.0 * sum * h / 3.0);
      omega_[j] = 2.0 * kelp::pi * std::sqrt(f0 * f1);
      phase_[j] = 2.0 * kelp::pi * static_cast<double>(rng() >> 11) * 0x1.0p-53;
      if (!(std::isfinite(amp_[j]) && std::isfinite(omega_[j]))) {
        std::ostringstream msg;
        msg.precision(9);
        msg << "wind gusts: f_min = " << p.f_min << " Hz and f_max = " << p.f_max
            << " Hz give a non-finite gust frequency or amplitude";
        ::kelp::detail::throw_invalid_argument(msg.str());
      }
    }
    // |ω_j t + φ_j| ≤ ω_max |t| + 2π stays within wrap_two_pi's exact range up to this |t|.
    time_fast_limit_ = (simd::kWrapTwoPiLimit - 8.0) / omega_.back();
  }

  /// \brief The parameters the field was built from.
  /// \return The parameters (default ones, no wind, for the default-constructed field).
  const WindParameters& parameters() const { return params_; }
  /// \brief Variance of the discretised gust Σ a_j²/2 [(m/s)²].
  /// \return Σ a_j²/2 [(m/s)²] (0 without gusts).
  double gust_variance() const {
    double v = 0.0;
    for (double a : amp_) v += 0.5 * a * a;
    return v;
  }
  /// \brief Wind speed U(t) = U₁₀ + u_g(t) [m/s] at time t [s].
  /// Time is a double for every Scalar; the phase is formed in double and reduced to [−π, π]
  /// (exactly, for any finite t; the fast reduction while |t| is below about 1e8/ω_max s).
  /// \param t Time [s].
  /// \return U(t) [m/s] (may be negative in a strong gust lull; not clamped).
  /// \throws kelp::invalid_argument when the field has gusts and t is not finite.
  Scalar speed(double t) const {
    double u = params_.speed, sn, cs;
    if (!(std::fabs(t) <= time_fast_limit_)) return Scalar(speed_exact(t));
    for (std::size_t j = 0; j < amp_.size(); ++j) {
      simd::fast_sincos(simd::wrap_two_pi(omega_[j] * t + phase_[j]), sn, cs);
      u += amp_[j] * cs;
    }
    return Scalar(u);
  }
  /// \brief Wind velocity (air motion) at 10 m, NED [m/s], at time t [s]; horizontal.
  /// \param t Time [s].
  /// \return U(t) (cos β, sin β, 0), β the mean direction [m/s]; zero when U₁₀ = 0.
  /// \throws kelp::invalid_argument as `speed`.
  Vector3<Scalar> velocity(double t) const {
    if (params_.speed == 0.0) return Vector3<Scalar>::Zero();
    const Scalar u = speed(t);
    return Vector3<Scalar>(u * Scalar(cos_dir_), u * Scalar(sin_dir_), Scalar(0));
  }

 private:
  /// U(t) with exactly reduced phases and the C library's cosine (huge or non-finite t).
  KELP_COLD double speed_exact(double t) const {
    if (amp_.empty()) return params_.speed;
    if (!std::isfinite(t))
      ::kelp::environment::detail::throw_bad_value("wind: time t", "finite", t);
    double u = params_.speed;
    for (std::size_t j = 0; j < amp_.size(); ++j)
      u += amp_[j] * std::cos(simd::reduce_phase_exact(omega_[j] * t + phase_[j]));
    return u;
  }

  WindParameters params_;
  double time_fast_limit_ = std::numeric_limits<double>::infinity();  ///< see speed()
  double cos_dir_ = 1.0, sin_dir_ = 0.0;
  std::vector<double> omega_, amp_, phase_;
};

/// \brief Double-precision wind field.
using WindFieldd = WindField<double>;
/// \brief Single-precision wind field.
using WindFieldf = WindField<float>;

/// \brief Projected areas and length of the hull above water.
struct WindAreas {
  double frontal_area = 0.0;    ///< A_Fw: frontal (transverse) projected area [m²]
  double lateral_area = 0.0;    ///< A_Lw: lateral projected area [m²]
  double length_overall = 0.0;  ///< L_oa [m], the yaw-moment arm
};

/// \brief The paper's constant coefficients resolved by the relative wind angle γ_rw
/// (Fossen 2021 §10.1.1, coefficients for a port/starboard-symmetric hull):
/// C_X = −c_x cos γ_rw, C_Y = c_y sin γ_rw, C_N = c_n sin 2γ_rw.
/// With γ_rw = 0 (head wind) |X| reduces to the paper's eq:wind.
struct ConstantWindCoefficients {
  double cx = 0.0;  ///< c_x [-] (≥ 0)
  double cy = 0.0;  ///< c_y [-] (≥ 0)
  double cn = 0.0;  ///< c_n [-]
  /// \brief (C_X, C_Y, C_N) at the relative wind angle γ_rw [rad].
  /// \param gamma Relative wind angle γ_rw [rad] (0: head wind).
  /// \return (C_X, C_Y, C_N) [-].
  /// \throws kelp::invalid_argument when γ_rw is not finite.
  Eigen::Vector3d operator()(double gamma) const { return at(gamma); }
  /// \brief The same for any scalar (a `ceres::Jet` γ keeps its derivatives).
  /// \tparam Scalar double, float or ceres::Jet.
  /// \param gamma Relative wind angle γ_rw [rad].
  /// \return (C_X, C_Y, C_N) [-].
  /// \throws kelp::invalid_argument when γ_rw is not finite.
  template <typename Scalar>
  Vector3<Scalar> at(const Scalar& gamma) const {
    check_finite(gamma, "relative wind angle gamma");
    return at_unchecked(gamma);
  }
  /// \brief `at` without the check (for callers that validated their inputs).
  /// \tparam Scalar double, float or ceres::Jet.
  /// \param gamma Relative wind angle γ_rw [rad] (a NaN gives NaN).
  /// \return (C_X, C_Y, C_N) [-].
  template <typename Scalar>
  Vector3<Scalar> at_unchecked(const Scalar& gamma) const {
    using std::cos;
    using std::sin;
    return Vector3<Scalar>(Scalar(-cx) * cos(gamma), Scalar(cy) * sin(gamma),
                           Scalar(cn) * sin(Scalar(2) * gamma));
  }
};

/// \brief Isherwood-style table of (C_X, C_Y, C_N) against the relative wind angle γ_rw ∈ [0, π],
/// linearly interpolated, mirrored for γ_rw < 0 with C_X even and C_Y, C_N odd (port/starboard
/// symmetry). Fill it from Isherwood (1972) or wind-tunnel data for the hull at hand; the values
/// use the sign convention of `ConstantWindCoefficients` (C_X < 0 in a head wind).
struct TabulatedWindCoefficients {
  std::vector<double> angle;  ///< γ_rw [rad], strictly increasing, from 0 to π
  std::vector<double> cx,     ///< C_X at those angles [-]
      cy,                     ///< C_Y at those angles [-]
      cn;                     ///< C_N at those angles [-]

  /// \brief (C_X, C_Y, C_N) at γ_rw [rad] (any finite value; wrapped to (−π, π]).
  /// \throws kelp::invalid_argument when γ_rw is not finite, or when the table is too short or
  /// its columns differ in length (the O(1) part of `validate(const
  /// TabulatedWindCoefficients&)`, checked on every call so a malformed table never reads out of
  /// bounds).
  /// \param gamma Relative wind angle γ_rw [rad].
  /// \return Interpolated (C_X, C_Y, C_N) [-].
  Eigen::Vector3d operator()(double gamma) const {
    check_finite(gamma, "relative wind angle gamma");
    KELP_CHECK(angle.size() >= 2, "wind table angle needs at least 2 entries");
    KELP_CHECK(cx.size() == angle.size() && cy.size() == angle.size() && cn.size() == angle.size(),
               "wind table cx, cy, cn must have as many entries as angle");
    gamma = std::remainder(gamma, 2.0 * kelp::pi);
    const double sign = gamma < 0.0 ? -1.0 : 1.0;
    const double g = std::abs(gamma);
    const auto it = std::upper_bound(angle.begin(), angle.end(), g);
    std::size_t i = static_cast<std::size_t>(std::max<std::ptrdiff_t>(1, it - angle.begin()));
    i = std::min(i, angle.size() - 1);
    const double f = (g - angle[i - 1]) / (angle[i] - angle[i - 1]);
    auto lerp = [&](const std::vector<double>& c) { return c[i - 1] + f * (c[i] - c[i - 1]); };
    return Eigen::Vector3d(lerp(cx), sign * lerp(cy), sign * lerp(cn));
  }
};

/// \brief Throws `kelp::invalid_argument` unless the table `t` is well formed: at least two
/// angles, running strictly increasing from 0 to π, and as many cx, cy, cn entries as angles,
/// all finite.
/// \param t Table to check (first angle within 1e-9 of 0, last within 1e-6 of π).
/// \throws kelp::invalid_argument naming the bad column.
inline void validate(const TabulatedWindCoefficients& t) {
  KELP_CHECK(t.angle.size() >= 2, "wind table angle needs at least 2 entries");
  KELP_CHECK(t.cx.size() == t.angle.size() && t.cy.size() == t.angle.size() &&
                 t.cn.size() == t.angle.size(),
             "wind table cx, cy, cn must have as many entries as angle");
  for (std::size_t i = 0; i < t.angle.size(); ++i) {
    check_finite(t.angle[i], "wind table angle");
    check_finite(t.cx[i], "wind table cx");
    check_finite(t.cy[i], "wind table cy");
    check_finite(t.cn[i], "wind table cn");
  }
  KELP_CHECK(std::abs(t.angle.front()) < 1e-9 && std::abs(t.angle.back() - kelp::pi) < 1e-6,
             "wind table angle must run from 0 to pi");
  for (std::size_t i = 1; i < t.angle.size(); ++i)
    KELP_CHECK(t.angle[i] > t.angle[i - 1], "wind table angle must be strictly increasing");
}

namespace detail {
/// `wind_load` without its input checks: for the vehicle dynamics, whose parameters are
/// validated when the model is built and whose state is checked by the integrators (a
/// non-finite stage state must end as the step's numerical_error, not as an invalid argument).
template <typename Scalar, typename Coefficients, typename Derived>
Vector3<Scalar> wind_load_unchecked(const Coefficients& coefficients, const WindAreas& areas,
                                    const Scalar& rho_air,
                                    const Eigen::MatrixBase<Derived>& wind_ned, const Scalar& psi,
                                    const Scalar& u, const Scalar& v) {
  using std::atan2;
  using std::cos;
  using std::sin;
  const Scalar cpsi = cos(psi), spsi = sin(psi);
  const Scalar wx = Scalar(wind_ned(0)), wy = Scalar(wind_ned(1));
  const Scalar u_rw = u - (cpsi * wx + spsi * wy);
  const Scalar v_rw = v - (-spsi * wx + cpsi * wy);
  const Scalar v2 = u_rw * u_rw + v_rw * v_rw;
  if (value_of(v2) == 0.0) return Vector3<Scalar>::Zero();
  const Scalar gamma = -atan2(v_rw, u_rw);
  // Constant coefficients are differentiated through γ; any other model (a table) is read at the
  // value of γ and carries no derivative with respect to it.
  Vector3<Scalar> c;
  if constexpr (std::is_same<Coefficients, ConstantWindCoefficients>::value)
    c = coefficients.at_unchecked(gamma);
  else
    c = coefficients(value_of(gamma)).template cast<Scalar>();
  const Scalar q = Scalar(0.5) * rho_air * v2;
  return Vector3<Scalar>(q * c(0) * Scalar(areas.frontal_area),
                         q * c(1) * Scalar(areas.lateral_area),
                         q * c(2) * Scalar(areas.lateral_area * areas.length_overall));
}
}  // namespace detail

/// \brief Wind force and yaw moment (X, Y, N) on a surface vessel, body frame [N, N, N·m]
/// (Fossen 2021 §10.1.1):
/// \f$ X = \tfrac12\rho_a V_{rw}^2 C_X(\gamma_{rw}) A_{Fw},\quad
///     Y = \tfrac12\rho_a V_{rw}^2 C_Y(\gamma_{rw}) A_{Lw},\quad
///     N = \tfrac12\rho_a V_{rw}^2 C_N(\gamma_{rw}) A_{Lw} L_{oa} \f$
/// with the relative velocity u_rw = u − u_w, v_rw = v − v_w (wind resolved in the body frame by
/// the heading ψ), V_rw² = u_rw² + v_rw² and γ_rw = −atan2(v_rw, u_rw).
/// Assumes a level hull (roll and pitch ignored) and wind at 10 m acting on the whole area.
/// \tparam Coefficients `ConstantWindCoefficients`, `TabulatedWindCoefficients` or any callable
/// γ ↦ Eigen::Vector3d (C_X, C_Y, C_N).
/// \param[in] coefficients coefficient model \param[in] areas projected areas and length
/// \param[in] rho_air [kg/m³] \param[in] wind_ned wind velocity (air motion) NED [m/s]
/// \param[in] psi heading [rad] \param[in] u surge velocity [m/s] \param[in] v sway velocity [m/s]
/// \tparam Scalar double, float or ceres::Jet.
/// \tparam Derived Any Eigen vector expression with 3 entries.
/// \return (X, Y, N), body frame [N, N, N·m]; zero when V_rw = 0.
/// \throws kelp::invalid_argument when ρ_air is not in (0, 1e5] kg/m³
/// (`limits::max_fluid_density`), an area or L_oa is negative or not finite, wind_ned has not 3
/// entries or one is not finite, or ψ, u or v is not finite.
template <typename Scalar, typename Coefficients, typename Derived>
Vector3<Scalar> wind_load(const Coefficients& coefficients, const WindAreas& areas,
                          const Scalar& rho_air, const Eigen::MatrixBase<Derived>& wind_ned,
                          const Scalar& psi, const Scalar& u, const Scalar& v) {
  detail::check_positive_at_most(value_of(rho_air), limits::max_fluid_density, "rho_air",
                                 "finite and in (0, 1e5] kg/m^3");
  check_non_negative(areas.frontal_area, "wind_areas.frontal_area");
  check_non_negative(areas.lateral_area, "wind_areas.lateral_area");
  check_non_negative(areas.length_overall, "wind_areas.length_overall");
  KELP_CHECK(wind_ned.size() == 3, "wind_ned must have 3 entries (NED)");
  check_all_finite(wind_ned, "wind_ned");
  check_finite(psi, "psi");
  check_finite(u, "u");
  check_finite(v, "v");
  return detail::wind_load_unchecked(coefficients, areas, rho_air, wind_ned, psi, u, v);
}

}  // namespace environment
}  // namespace kelp
