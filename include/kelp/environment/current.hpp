/// \file
/// \brief Ocean current: Fossen's 3-D current vector, depth profiles
/// (uniform, power-law, linear) and a seeded, bounded first-order Gauss–Markov variation of speed
/// and direction that keeps varying for any run length. The paper's current formula is in
/// `kelp/environment/paper.hpp`.
///
/// Frames: world NED, z down, mean sea surface at z = 0. Angles: β_c is the horizontal direction
/// the current flows TOWARDS (NED azimuth from north, clockwise) and α_c the vertical angle of
/// Fossen's 3-D current (positive: flowing downwards). Units SI.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <sstream>
#include <vector>

#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/fast_math.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/environment/limits.hpp"

namespace kelp {
namespace environment {

/// \brief Fossen's 3-D current velocity in NED [m/s] from speed and direction angles:
/// \f$ \mathbf v_c^n = V_c [\cos\alpha_c\cos\beta_c,\ \sin\beta_c,\ \sin\alpha_c\cos\beta_c]^T \f$
/// (Fossen 2021, §8.3, 3-D irrotational current). With α_c = 0 the current is horizontal and
/// flows towards the azimuth β_c. \param[in] speed V_c [m/s] \param[in] alpha α_c [rad]
/// \param[in] beta β_c [rad]
/// \tparam Scalar double, float or ceres::Jet.
/// \return v_c^n, NED [m/s].
/// \throws kelp::invalid_argument when V_c, α_c or β_c is not finite.
template <typename Scalar>
Vector3<Scalar> current_velocity_ned(const Scalar& speed, const Scalar& alpha, const Scalar& beta) {
  using std::cos;
  using std::sin;
  check_finite(speed, "current speed");
  check_finite(alpha, "current vertical angle alpha");
  check_finite(beta, "current direction beta");
  return Vector3<Scalar>(speed * cos(alpha) * cos(beta), speed * sin(beta),
                         speed * sin(alpha) * cos(beta));
}

/// \brief How the current speed varies with depth.
enum class CurrentProfileKind {
  uniform,    ///< the same speed at every depth
  power_law,  ///< V(z) = V_s ((h − z)/h)^p: zero at the seabed (p = 1/7 typical for tidal flow)
  linear      ///< V(z) = V_s (1 − (1 − r) z/h): from V_s at the surface to r V_s at the seabed
};

/// \brief A current depth profile; the factor multiplies the surface speed.
struct CurrentProfile {
  CurrentProfileKind kind = CurrentProfileKind::uniform;  ///< profile shape
  /// Depth h [m] of the seabed the profile decays to (needed by power_law and linear).
  double depth = std::numeric_limits<double>::infinity();
  /// Exponent p of the power law (> 0). 1/7 after DNV-RP-C205 (2010) eq. 4.1.2 (tidal current).
  double exponent = 1.0 / 7.0;
  /// Ratio r of the seabed speed to the surface speed for the linear profile (≥ 0).
  double bottom_ratio = 0.0;
};

/// \brief Throws `kelp::invalid_argument` naming the bad field of a profile.
/// \param p Profile to check: depth finite > 0 unless uniform, exponent finite > 0,
/// bottom_ratio finite ≥ 0.
/// \throws kelp::invalid_argument naming the bad field.
inline void validate(const CurrentProfile& p) {
  if (p.kind != CurrentProfileKind::uniform) check_positive(p.depth, "profile.depth");
  check_positive(p.exponent, "profile.exponent");
  check_non_negative(p.bottom_ratio, "profile.bottom_ratio");
}

namespace detail {

/// profile_factor() without the check of z, for the samplers that run per point inside a step
/// (Environment::sample_water, Environment::sample_unchecked): there a NaN position gives a NaN
/// factor, which the step reports as its numerical_error with the state unchanged (their
/// documented contract), instead of an invalid_argument from the middle of a step.
template <typename Scalar>
Scalar profile_factor_unchecked(const CurrentProfile& p, const Scalar& z) {
  using std::pow;
  if (p.kind == CurrentProfileKind::uniform || value_of(z) <= 0.0) return Scalar(1);
  if (value_of(z) >= p.depth)
    return p.kind == CurrentProfileKind::power_law ? Scalar(0) : Scalar(p.bottom_ratio);
  const Scalar s = z / Scalar(p.depth);
  if (p.kind == CurrentProfileKind::power_law) return pow(Scalar(1) - s, p.exponent);
  return Scalar(1) - Scalar(1.0 - p.bottom_ratio) * s;
}

}  // namespace detail

/// \brief Profile factor f(z) ∈ [0, 1] at NED depth z [m]: 1 above the surface (z ≤ 0),
/// the profile in between, and its seabed value at and below z = h (z = ±∞ give those limits).
/// \param[in] p a validated profile. \param[in] z NED depth [m], not NaN.
/// \tparam Scalar double, float or ceres::Jet.
/// \return f(z) [-]: 1 for a uniform profile; 0 (power law) or r (linear) at the seabed.
/// \throws kelp::invalid_argument when z is NaN (it has no depth, so no factor in [0, 1]).
template <typename Scalar>
Scalar profile_factor(const CurrentProfile& p, const Scalar& z) {
  if (std::isnan(value_of(z)))
    ::kelp::detail::throw_invalid_argument("profile_factor: z must not be NaN");
  return detail::profile_factor_unchecked(p, z);
}

/// \brief A first-order Gauss–Markov process x with bounds (Fossen 2021, §8.3.1:
/// V̇_c + μ V_c = w with V_min ≤ V_c ≤ V_max), written about its nominal value x̄:
/// \f$ \dot x = -\mu (x - \bar x) + w \f$, w white noise of intensity σ². Stationary: mean x̄,
/// variance σ²/(2μ) = σ² T/2, autocorrelation e^{−|τ|/T} (T = 1/μ the time constant).
struct GaussMarkov {
  double time_constant = 600.0;  ///< 1/μ [s] (> 0)
  double sigma = 0.0;            ///< σ [unit/√s] (≥ 0; 0 disables the variation)
  double lower = -std::numeric_limits<double>::infinity();  ///< lower bound (≤ nominal)
  double upper = std::numeric_limits<double>::infinity();   ///< upper bound (≥ nominal)
};

/// \brief Everything that defines a current.
struct CurrentParameters {
  double speed = 0.0;               ///< nominal surface speed V_c [m/s] (0 ≤ V_c ≤ 50)
  double direction = 0.0;           ///< β_c: NED azimuth the current flows towards [rad]
  double vertical_angle = 0.0;      ///< α_c [rad]
  CurrentProfile profile;           ///< depth profile
  GaussMarkov speed_variation;      ///< slow variation of V_c (bounds in m/s)
  GaussMarkov direction_variation;  ///< slow variation of β_c (bounds in rad, absolute)
  /// Number N of harmonics of each variation (≥ 1); more makes it closer to Gaussian.
  int n_harmonics = 128;
  /// Highest angular frequency [rad/s] (> 0) the variation contains (the Lorentzian spectrum is
  /// cut there; the default π rad/s keeps periods ≥ 2 s, far faster than any current changes).
  double max_frequency = kelp::pi;
  std::uint64_t seed = 1;  ///< seed of the variation (std::mt19937_64, portable)
};

/// \brief Throws `kelp::invalid_argument` naming the bad field of `p`.
/// \param p Current parameters to check.
/// \throws kelp::invalid_argument when the speed is not in [0, 50] m/s
/// (`limits::max_current_speed`), a direction or angle is not finite, the profile is invalid, a
/// variation's time constant is not finite and > 0, its σ is negative or not finite, its bounds
/// are NaN or do not enclose the nominal value, n_harmonics is not in [1, 2^20]
/// (`limits::max_components`) or max_frequency is not finite and > 0.
inline void validate(const CurrentParameters& p) {
  detail::check_in_range(p.speed, 0.0, limits::max_current_speed, "speed",
                         "finite and in [0, 50] m/s");
  check_finite(p.direction, "direction");
  check_finite(p.vertical_angle, "vertical_angle");
  validate(p.profile);
  for (const GaussMarkov* g : {&p.speed_variation, &p.direction_variation}) {
    const bool is_speed = g == &p.speed_variation;
    const double nominal = is_speed ? p.speed : p.direction;
    check_positive(g->time_constant, is_speed ? "speed_variation.time_constant"
                                              : "direction_variation.time_constant");
    check_non_negative(g->sigma, is_speed ? "speed_variation.sigma" : "direction_variation.sigma");
    KELP_CHECK(!std::isnan(g->lower) && !std::isnan(g->upper) && g->lower <= nominal &&
                   nominal <= g->upper,
               is_speed ? "speed_variation bounds must satisfy lower <= speed <= upper"
                        : "direction_variation bounds must satisfy lower <= direction <= upper");
  }
  KELP_CHECK(p.n_harmonics >= 1 && p.n_harmonics <= limits::max_components,
             "n_harmonics must be >= 1 and <= 1048576");
  check_positive(p.max_frequency, "max_frequency");
}

/// \brief A current evaluable at any NED point and time: nominal speed and direction, depth
/// profile and an optional slow, bounded Gauss–Markov variation.
///
/// The variation is a spectral representation of the Gauss–Markov process (Shinozuka & Deodatis
/// 1991, "Simulation of stochastic processes by spectral representation", Appl. Mech. Rev.
/// 44(4)): x(t) = x̄ + a Σ_k cos(ω_k t + φ_k), k = 1…N, a = √(2 σ_x²/N), σ_x² = σ²T/2, with
/// seeded phases φ_k ~ U[0, 2π) and frequencies drawn from the process's own (Lorentzian)
/// spectrum S(ω) ∝ 1/(μ² + ω²) by stratified inverse-CDF sampling, ω_k = μ tan(u_k atan(ω_max/μ)),
/// u_k ∈ [k/N, (k+1)/N). Then E[x] = x̄, Var x = σ_x² and, since the Cauchy distribution's
/// characteristic function is e^{−μ|τ|}, the autocorrelation is e^{−|τ|/T} (up to the cut at
/// ω_max, a relative O(μ/ω_max) change); by the central limit theorem x is close to Gaussian for
/// large N. The value is then clamped to [lower, upper].
///
/// This form has no state: any time can be evaluated directly (forwards, backwards, from many
/// simulations sharing one const model), the same seed gives bit-identical values, and the
/// random, incommensurate frequencies never repeat, so the current keeps varying for any run
/// length. Queries are `const`, thread-safe and allocation-free (O(N) per evaluation; the phase
/// is formed in double and reduced before the cosine). The current is treated as quasi-steady:
/// its slow time derivative is not reported as a fluid acceleration.
/// \tparam Scalar double, float or ceres::Jet (derivatives flow through position; time is a
/// double).
template <typename Scalar>
class CurrentModel {
 public:
  /// \brief No current.
  CurrentModel() = default;

  /// \brief Builds the current and draws its harmonics.
  /// \param p Current parameters (copied); the harmonics are drawn from p.seed only when a
  /// variation's σ > 0.
  /// \throws kelp::invalid_argument naming the bad field (see `validate(const
  /// CurrentParameters&)`), or naming a variation's σ and time constant with their values when
  /// its amplitude or a frequency is not finite (e.g. σ = 1e300).
  explicit CurrentModel(const CurrentParameters& p) : params_(p) {
    validate(p);
    varying_ = p.speed_variation.sigma > 0.0 || p.direction_variation.sigma > 0.0;
    if (!varying_) return;
    std::mt19937_64 rng(p.seed);
    draw(p.speed_variation, rng, speed_, "speed_variation");
    draw(p.direction_variation, rng, direction_, "direction_variation");
  }

  /// \brief A constant current of the given NED velocity [m/s], uniform in depth.
  /// \throws kelp::invalid_argument naming `current` when not finite or not 3 entries, or
  /// naming the speed when |v| > 50 m/s.
  /// \tparam Derived Any Eigen vector expression with 3 entries.
  /// \param v_ned Current velocity, NED [m/s] (a vertical component gives α_c ≠ 0).
  /// \return A current without variation whose velocity is v_ned at every depth and time.
  template <typename Derived>
  static CurrentModel constant(const Eigen::MatrixBase<Derived>& v_ned) {
    KELP_CHECK(v_ned.size() == 3, "current must have 3 entries (NED)");
    check_all_finite(v_ned, "current");
    const double u = value_of(v_ned(0)), v = value_of(v_ned(1)), w = value_of(v_ned(2));
    CurrentParameters p;
    p.speed = std::sqrt(u * u + v * v + w * w);
    // Invert Fossen's parametrisation u = V cos α cos β, v = V sin β, w = V sin α cos β with
    // α ∈ [−π/2, π/2] (so cos α ≥ 0): β is then the horizontal azimuth the current flows towards
    // (atan2(v, u) for a horizontal current), and tan α = w/u.
    p.vertical_angle =
        u != 0.0 ? std::atan(w / u) : (w != 0.0 ? std::copysign(kelp::pi / 2, w) : 0.0);
    p.direction = std::atan2(v, std::copysign(std::hypot(u, w), u));
    return CurrentModel(p);
  }

  /// \brief The parameters the current was built from.
  /// \return The parameters (default ones for the default-constructed, zero current).
  const CurrentParameters& parameters() const { return params_; }
  /// \brief True when the current is zero everywhere and always.
  /// \return True when the nominal speed is 0 and neither speed nor direction varies.
  bool is_zero() const { return params_.speed == 0.0 && !varying_; }

  /// \brief Surface speed V_c(t) [m/s] at time t [s].
  /// \param t Time [s].
  /// \return V_c(t) [m/s], within the speed variation's bounds.
  /// \throws kelp::invalid_argument when the current varies and t is not finite.
  double speed_at(double t) const {
    return varying_ ? speed_.value(t, params_.speed, params_.speed_variation) : params_.speed;
  }
  /// \brief Direction β_c(t) [rad] at time t [s].
  /// \param t Time [s].
  /// \return β_c(t) [rad], NED azimuth the current flows towards (not wrapped), within the
  /// direction variation's bounds.
  /// \throws kelp::invalid_argument when the current varies and t is not finite.
  double direction_at(double t) const {
    return varying_ ? direction_.value(t, params_.direction, params_.direction_variation)
                    : params_.direction;
  }
  /// \brief Current velocity at the surface, NED [m/s], at time t [s].
  /// \param t Time [s].
  /// \return current_velocity_ned(V_c(t), α_c, β_c(t)) [m/s].
  /// \throws kelp::invalid_argument when the current varies and t is not finite.
  Vector3<Scalar> surface_velocity(double t) const {
    return current_velocity_ned(Scalar(speed_at(t)), Scalar(params_.vertical_angle),
                                Scalar(direction_at(t)));
  }
  /// \brief Current velocity at NED point p [m] and time t [s], NED [m/s]: the surface velocity
  /// times profile_factor(z). Above the surface (z < 0) the surface value is returned; z = ±∞
  /// give the surface and seabed values, as profile_factor's.
  /// \throws kelp::invalid_argument when p has not 3 entries or one of them is NaN (a point
  /// without a depth has no current; as profile_factor), or when the current varies and t is not
  /// finite. The samplers of the steps (Environment::sample_water, sample_unchecked) apply the
  /// profile without this check: there a NaN node gives NaN, which the step reports as
  /// numerical_error with the state unchanged.
  /// \tparam Derived Any Eigen vector expression with 3 entries.
  /// \param p Point, NED [m] (only its depth z = p(2) matters).
  /// \param t Time [s].
  /// \return Current velocity, NED [m/s].
  template <typename Derived>
  Vector3<Scalar> velocity(const Eigen::MatrixBase<Derived>& p, double t) const {
    KELP_CHECK(p.size() == 3, "CurrentModel::velocity: p must have 3 entries");
    if (std::isnan(value_of(p(0))) || std::isnan(value_of(p(1))) || std::isnan(value_of(p(2))))
      ::kelp::detail::throw_invalid_argument("CurrentModel::velocity: p must not be NaN");
    return surface_velocity(t) * detail::profile_factor_unchecked(params_.profile, Scalar(p(2)));
  }

 private:
  /// \cond PRIVATE
  /// The harmonics of one variation.
  struct Harmonics {
    std::vector<double> omega, phase;  ///< ω_k [rad/s], φ_k [rad]
    double amplitude = 0.0;            ///< a = √(2 σ_x² / N)
    /// |t| up to which ω_k t + φ_k stays in wrap_two_pi's exact range (one check per call).
    double time_fast_limit = std::numeric_limits<double>::infinity();
    /// x̄ + a Σ cos(ω_k t + φ_k), clamped to the bounds (x̄ when there are no harmonics).
    double value(double t, double nominal, const GaussMarkov& g) const {
      double sum = 0.0;
      if (std::fabs(t) <= time_fast_limit) {
        for (std::size_t k = 0; k < omega.size(); ++k) {
          double s, c;
          simd::fast_sincos(simd::wrap_two_pi(omega[k] * t + phase[k]), s, c);
          sum += c;
        }
      } else {
        sum = sum_exact(t);
      }
      const double x = nominal + amplitude * sum;
      return std::min(std::max(x, g.lower), g.upper);
    }
    /// Σ cos(ω_k t + φ_k) with exactly reduced phases (huge or non-finite t).
    KELP_COLD double sum_exact(double t) const {
      if (omega.empty()) return 0.0;
      if (!std::isfinite(t)) detail::throw_bad_value("current: time t", "finite", t);
      double sum = 0.0;
      for (std::size_t k = 0; k < omega.size(); ++k)
        sum += std::cos(simd::reduce_phase_exact(omega[k] * t + phase[k]));
      return sum;
    }
  };

  void draw(const GaussMarkov& g, std::mt19937_64& rng, Harmonics& h, const char* name) const {
    if (g.sigma == 0.0) return;
    const auto n = static_cast<std::size_t>(params_.n_harmonics);
    auto uniform = [&rng]() { return (static_cast<double>(rng() >> 11) + 0.5) * 0x1.0p-53; };
    const double mu = 1.0 / g.time_constant;
    const double variance = 0.5 * g.sigma * g.sigma * g.time_constant;
    const double span = std::atan(params_.max_frequency / mu);
    h.omega.resize(n);
    h.phase.resize(n);
    h.amplitude = std::sqrt(2.0 * variance / static_cast<double>(n));
    for (std::size_t k = 0; k < n; ++k) {
      const double u = (static_cast<double>(k) + uniform()) / static_cast<double>(n);
      h.omega[k] = mu * std::tan(u * span);
      h.phase[k] = 2.0 * kelp::pi * uniform();
    }
    bool ok = std::isfinite(h.amplitude);
    for (double w : h.omega) ok = ok && std::isfinite(w);
    if (!ok) {
      std::ostringstream msg;
      msg.precision(9);
      msg << name << ": sigma = " << g.sigma << ", time_constant = " << g.time_constant
          << " s and max_frequency = " << params_.max_frequency
          << " rad/s give a non-finite amplitude or frequency";
      ::kelp::detail::throw_invalid_argument(msg.str());
    }
    // ω_k ≤ max_frequency; |ω_k t + φ_k| ≤ max_frequency |t| + 2π.
    h.time_fast_limit = (simd::kWrapTwoPiLimit - 8.0) / params_.max_frequency;
  }

  CurrentParameters params_;
  bool varying_ = false;
  Harmonics speed_, direction_;
  /// \endcond
};

/// \brief Double-precision current model.
using CurrentModeld = CurrentModel<double>;
/// \brief Single-precision current model.
using CurrentModelf = CurrentModel<float>;

}  // namespace environment
}  // namespace kelp
