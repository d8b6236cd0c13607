/// \file
/// \brief Irregular linear (Airy) waves: a spectrum discretised into N components with seeded
/// random phases and optional directional spreading; surface elevation, slope, and orbital
/// velocity and acceleration at any point, in deep water or finite depth; a batch query for many
/// points without heap allocation.
///
/// Time is a `double` for every Scalar: the phase φ − ω t is formed in double and reduced to
/// [−π, π] before anything is cast to Scalar, so a float model reads the same sea as a double one
/// after any run length.
///
/// Frames: world NED (x north, y east, z down), mean free surface at z = 0. The elevation ζ is
/// positive UP (the free surface lies at NED z = −ζ). A component travelling towards the NED
/// azimuth β (from north, clockwise) has the phase θ = k (x cos β + y sin β) − ω t + φ and
/// contributes ζ = a cos θ. Linear wave theory (Airy; e.g. DNV-RP-C205 (2010) Table 3-1, Fossen
/// 2021 §10.2) gives, at depth z ≥ 0 below the mean level, in NED:
/// \f[ \mathbf v = a\omega \left[ F_h \cos\theta\cos\beta,\; F_h\cos\theta\sin\beta,\;
///     -F_v\sin\theta \right],\qquad
///     \mathbf a = a\omega^2 \left[ F_h \sin\theta\cos\beta,\; F_h\sin\theta\sin\beta,\;
///     F_v\cos\theta \right] \f]
/// with F_h = F_v = e^{−k z} in deep water and F_h = cosh(k(h − z))/sinh(k h),
/// F_v = sinh(k(h − z))/sinh(k h) in water of depth h.
///
/// Assumptions (linear theory): small steepness; velocities are summed component by component;
/// near the free surface the profiles are taken as `WaveFieldParameters::stretching` says: by
/// default (`WaveStretching::vertical`) between the mean level and a crest (−ζ ≤ z < 0) the
/// kinematics are those at z = 0 (vertical extrapolation) and below it linear theory's; with
/// `WaveStretching::wheeler` the wetted column is stretched onto [0, h] (Wheeler 1970, see the
/// enum); above the free surface (z < −ζ) velocity and acceleration are zero; below a finite
/// seabed they are those at the seabed. Acceleration is the local (Eulerian) ∂v/∂t; the
/// single-point query also returns the velocity gradient ∇v, from which a body forms the convective
/// part (v·∇)v of the material acceleration (second order in the wave amplitude, but with a
/// non-zero mean: vehicle::surroundings uses it).
///
/// Regular waves (`RegularWave`: height, period or wavelength, direction, phase) are components
/// like the spectrum's, appended after them (`WaveFieldParameters::regular`): alone, or on top of
/// a spectral sea. A regular wave of height H has ζ = (H/2) cos θ with the θ above.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/fast_math.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/environment/limits.hpp"
#include "kelp/environment/spectra.hpp"
#include "kelp/environment/wave_kernels.hpp"
#include "kelp/environment/wave_stretching.hpp"

namespace kelp {
namespace environment {

/// \brief A regular (Airy) wave of given height, period or wavelength, direction and phase:
/// ζ = (H/2) cos(k (x cos β + y sin β) − ω t + φ), with ω² = g k tanh(k h) (deep water: ω² = g k)
/// for the wave field's depth h and gravity g.
struct RegularWave {
  double height = 0.0;      ///< crest-to-trough height H = 2 A [m] (0 ≤ H ≤ 100; 0: no wave)
  double period = 0.0;      ///< period T = 2π/ω [s], or 0 when `wavelength` is given
  double wavelength = 0.0;  ///< wavelength λ = 2π/k [m], or 0 when `period` is given
  /// Direction the wave travels TOWARDS, NED azimuth from north, clockwise [rad] (the spectral
  /// components' convention).
  double direction = 0.0;
  double phase = 0.0;  ///< phase φ [rad]: the crest is at the origin when φ − ω t = 0
};

/// \brief Wave number k [rad/m] of a regular wave in water of depth h (+∞: deep) and gravity g:
/// 2π/λ, or the root of the dispersion relation for ω = 2π/T (`wave_number`).
/// \param w The wave (wavelength > 0, else period > 0 is used; not checked: see validate).
/// \param g Gravitational acceleration [m/s²].
/// \param depth Water depth h [m] (+∞: deep water).
/// \return k [rad/m].
inline double regular_wave_number(const RegularWave& w, double g, double depth) {
  if (w.wavelength > 0.0) return 2.0 * kelp::pi / w.wavelength;
  return wave_number(2.0 * kelp::pi / w.period, g, depth);
}

/// \brief Angular frequency ω [rad/s] of a regular wave: 2π/T, or ω = √(g k tanh(k h)) for
/// k = 2π/λ (`wave_frequency`).
/// \param w The wave (wavelength > 0, else period > 0 is used; not checked: see validate).
/// \param g Gravitational acceleration [m/s²].
/// \param depth Water depth h [m] (+∞: deep water).
/// \return ω [rad/s].
inline double regular_wave_frequency(const RegularWave& w, double g, double depth) {
  if (w.wavelength > 0.0) return wave_frequency(2.0 * kelp::pi / w.wavelength, g, depth);
  return 2.0 * kelp::pi / w.period;
}

/// \brief Throws `kelp::invalid_argument` naming the offending field (`regular.height` and so
/// on) unless the wave is one linear theory describes in water of depth h and gravity g.
///
/// \throws kelp::invalid_argument when height is not in [0, 100] m, not exactly one of period
/// (finite, in [0.1, 1000] s) and wavelength (finite, in (0, 1e6] m) is given (> 0; the other
/// 0), direction or phase is not finite, or the wave is steeper than the breaking limit
/// H/λ = tanh(k h)/7 (Miche 1944; Michell's 1893 deep-water 1/7 when h is infinite; linear
/// theory is meaningless beyond).
/// \param w The wave to check.
/// \param g Gravitational acceleration [m/s²] (the field's; assumed valid).
/// \param depth Water depth h [m] (+∞: deep water; the field's, assumed valid).
inline void validate(const RegularWave& w, double g, double depth) {
  detail::check_in_range(w.height, 0.0, limits::max_significant_height, "regular.height",
                         "finite and in [0, 100] m");
  KELP_CHECK(!std::isnan(w.period) && !std::isnan(w.wavelength) &&
                 (w.period > 0.0) != (w.wavelength > 0.0) && w.period >= 0.0 && w.wavelength >= 0.0,
             "regular: give exactly one of regular.period and regular.wavelength (> 0; the "
             "other 0), got period = " +
                 std::to_string(w.period) + " s and wavelength = " + std::to_string(w.wavelength) +
                 " m");
  if (w.period > 0.0)
    detail::check_in_range(w.period, limits::min_peak_period, limits::max_peak_period,
                           "regular.period", "finite and in [0.1, 1000] s");
  else
    detail::check_positive_at_most(w.wavelength, 1e6, "regular.wavelength",
                                   "finite and in (0, 1e6] m");
  check_finite(w.direction, "regular.direction");
  check_finite(w.phase, "regular.phase");
  // Miche's limit H/λ ≤ tanh(k h)/7: Michell's 1/7 in deep water, lower in shallow water, where
  // a wave that tall would put its trough below the seabed.
  const double k = regular_wave_number(w, g, depth);
  const double lambda = 2.0 * kelp::pi / k;
  const double limit = lambda / 7.0 * (std::isinf(depth) ? 1.0 : std::tanh(k * depth));
  if (!(w.height <= limit)) {
    std::ostringstream msg;
    msg.precision(9);
    msg << "regular.height must be at most the breaking limit (wavelength / 7) tanh(k depth) = "
        << limit << " m (got " << w.height << " m for a wavelength of " << lambda << " m)";
    ::kelp::detail::throw_invalid_argument(msg.str());
  }
}

/// \brief How a wave spectrum (and any regular waves) becomes a sum of regular components.
struct WaveFieldParameters {
  /// Spectrum (shape, Hs, Tp, γ). Hs = 0 gives a calm sea with no components.
  WaveSpectrum spectrum;
  /// Number of components N (≥ 1).
  int n_components = 64;
  /// Seed of the phases, frequency jitter and directions (std::mt19937_64, portable).
  std::uint64_t seed = 1;
  /// Mean direction the waves travel TOWARDS, NED azimuth from north, clockwise [rad].
  double direction = 0.0;
  /// Spreading exponent 0 ≤ s ≤ 1000 of D(θ) ∝ cos^{2s}(θ − β̄), |θ − β̄| < π/2 (s = 1 is the ITTC
  /// cos² spreading; 0 means long-crested). Each component gets one direction drawn from D.
  double spreading = 0.0;
  /// Lower end of the frequency band, as a multiple of ω_p (> 0).
  double omega_min_factor = 0.5;
  /// Upper end of the frequency band, as a multiple of ω_p (> omega_min_factor). The default
  /// 5 ω_p leaves < 0.2 % of the PM variance out (∫_{5ωp}^∞ S ≈ 5/(64·625) Hs²).
  double omega_max_factor = 5.0;
  /// Place each frequency at a seeded random point of its bin (true) or at the bin centre
  /// (false). Jitter keeps the record from repeating every 2π/Δω.
  bool jitter = true;
  /// Water depth h [m] for the dispersion relation and the depth decay (+∞: deep water).
  double depth = std::numeric_limits<double>::infinity();
  /// Gravitational acceleration [m/s²].
  double gravity = kelp::standard_gravity;
  /// Regular waves added to the spectrum's components, after them (none by default). With
  /// spectrum.significant_height = 0 they alone make the sea. Each uses `depth` and `gravity`.
  std::vector<RegularWave> regular;
  /// Kinematics near the free surface (`WaveStretching`; vertical extrapolation by default).
  WaveStretching stretching = WaveStretching::vertical;
};

/// \brief Throws `kelp::invalid_argument` naming the offending field of `p` (and its value
/// where a bound applies).
///
/// \throws kelp::invalid_argument when the spectrum is out of its bounds (see
/// `validate(const WaveSpectrum&)`), n_components is not in [1, 2^20]
/// (`limits::max_components`), direction is not finite, spreading is not in [0, 1000]
/// (`limits::max_spreading`),
/// omega_min_factor is not finite and > 0, omega_max_factor is not finite and > omega_min_factor
/// or makes the highest wave number overflow, depth is NaN or ≤ 0, or gravity is not in (0, 1000]
/// m/s² (`limits::max_gravity`); also when stretching is not a WaveStretching value, there are
/// more than 2^20 regular waves or one of them is invalid (see `validate(const RegularWave&,
/// double, double)`).
/// \param p Wave field parameters to check.
inline void validate(const WaveFieldParameters& p) {
  validate(p.spectrum);
  KELP_CHECK(
      p.n_components >= 1 && p.n_components <= limits::max_components,
      "n_components must be >= 1 and <= 1048576 (got " + std::to_string(p.n_components) + ")");
  check_finite(p.direction, "direction");
  detail::check_in_range(p.spreading, 0.0, limits::max_spreading, "spreading",
                         "finite and in [0, 1000]");
  check_positive(p.omega_min_factor, "omega_min_factor");
  KELP_CHECK(std::isfinite(p.omega_max_factor) && p.omega_max_factor > p.omega_min_factor,
             "omega_max_factor must be finite and > omega_min_factor");
  KELP_CHECK(!std::isnan(p.depth) && p.depth > 0.0, "depth must be > 0 (or +infinity)");
  detail::check_positive_at_most(p.gravity, limits::max_gravity, "gravity",
                                 "finite and in (0, 1000] m/s^2");
  const double w_hi = p.omega_max_factor * 2.0 * kelp::pi / p.spectrum.peak_period;
  if (!std::isfinite(w_hi * w_hi / p.gravity))
    detail::throw_bad_value("omega_max_factor",
                            "such that the highest wave number (omega_max_factor 2 pi / "
                            "peak_period)^2 / gravity is finite",
                            p.omega_max_factor);
  KELP_CHECK(p.stretching == WaveStretching::vertical || p.stretching == WaveStretching::wheeler,
             "stretching must be WaveStretching::vertical or WaveStretching::wheeler");
  KELP_CHECK(p.regular.size() <= static_cast<std::size_t>(limits::max_components),
             "regular: at most 1048576 regular waves");
  for (const RegularWave& w : p.regular) validate(w, p.gravity, p.depth);
}

/// \brief Elevation and orbital kinematics at one point.
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
struct WaveKinematics {
  Scalar elevation = Scalar(0);                            ///< ζ at the point's (x, y) [m], up
  Vector3<Scalar> velocity = Vector3<Scalar>::Zero();      ///< orbital velocity, NED [m/s]
  Vector3<Scalar> acceleration = Vector3<Scalar>::Zero();  ///< ∂v/∂t, NED [m/s²]
  /// ∂v_i/∂x_k, NED [1/s] (symmetric and trace-free; zero above the free surface). Filled by the
  /// single-point query only; (v·∇)v = velocity_gradient · velocity is the convective part of
  /// the water's material acceleration.
  Eigen::Matrix<Scalar, 3, 3> velocity_gradient = Eigen::Matrix<Scalar, 3, 3>::Zero();
  /// Surface slope (∂ζ/∂x, ∂ζ/∂y) [-] at the point's (x, y), as `WaveField::slope` gives it
  /// (also above the free surface). Filled by the single-point query only, from the same sines.
  Eigen::Matrix<Scalar, 2, 1> slope = Eigen::Matrix<Scalar, 2, 1>::Zero();
};

/// \brief A linear irregular sea: N regular components with precomputed constants.
///
/// Construction discretises the spectrum (allocates once); every query is `const` and
/// allocation-free. For `double` and `float` the sums run in double precision through a
/// vectorisable kernel; other scalars (ceres::Jet) use the same formulas through ADL math.
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
class WaveField {
 public:
  /// \brief A calm sea (no components).
  WaveField() = default;

  /// \brief Discretises `p.spectrum` into `p.n_components` components.
  ///
  /// Band [ω_min, ω_max] = [omega_min_factor, omega_max_factor]·ω_p split into N bins of width
  /// Δω; ω_j in bin j (centre or seeded random point); amplitude a_j = √(2 ∫_bin S dω) (the
  /// bin's energy by composite Simpson quadrature, rather than S(ω_j)Δω, so that a jittered
  /// frequency does not change the variance and Σ a_j²/2 equals the band's m₀ ≈ Hs²/16;
  /// Fossen 2021 §10.2.3 and DNV-RP-C205 §3.5 describe the S(ω_j)Δω form); phase
  /// φ_j ~ U[0, 2π); direction from the spreading function; k_j from the dispersion relation.
  /// \throws kelp::invalid_argument naming the bad field (see `validate(const
  /// WaveFieldParameters&)`), or naming the spectrum's parameters and their values when a derived
  /// quantity of the discretised sea (a frequency, wave number or amplitude) is not finite, or a
  /// wave number is 0.
  /// \param p Spectrum, discretisation and regular waves (copied). Regular waves of height 0 add
  /// no component.
  explicit WaveField(const WaveFieldParameters& p) : params_(p) {
    validate(p);
    const std::size_t n_spectral =
        p.spectrum.significant_height == 0.0 ? 0 : static_cast<std::size_t>(p.n_components);
    std::size_t n = n_spectral;
    for (const RegularWave& w : p.regular) n += w.height > 0.0 ? 1 : 0;
    if (n == 0) return;
    for (auto* v :
         {&omega_, &k_,   &amp_,  &phase_, &dir_, &kx_,  &ky_,  &cosb_, &sinb_, &aw_, &aw2_,
          &awc_,   &aws_, &aw2c_, &aw2s_,  &q_,   &e2h_, &gcc_, &gcs_,  &gss_,  &gc_, &gs_})
      v->resize(n);
    if (n_spectral > 0) {
      std::mt19937_64 rng(p.seed);
      auto uniform = [&rng]() { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
      const double wp = 2.0 * kelp::pi / p.spectrum.peak_period;
      const double w_lo = p.omega_min_factor * wp, w_hi = p.omega_max_factor * wp;
      const double dw = (w_hi - w_lo) / static_cast<double>(n_spectral);
      for (std::size_t j = 0; j < n_spectral; ++j) {
        const double u = p.jitter ? uniform() : 0.5;
        const double w = w_lo + (static_cast<double>(j) + u) * dw;
        const double a =
            std::sqrt(2.0 * bin_energy(p.spectrum, w_lo + static_cast<double>(j) * dw, dw));
        const double phase = 2.0 * kelp::pi * uniform();
        double beta = p.direction;
        if (p.spreading > 0.0) {
          // Rejection sampling of D(θ) ∝ cos^{2s}(θ) on (−π/2, π/2).
          for (int tries = 0; tries < 100000; ++tries) {
            const double th = (uniform() - 0.5) * kelp::pi;
            if (uniform() <= std::pow(std::cos(th), 2.0 * p.spreading)) {
              beta += th;
              break;
            }
          }
        }
        set_component(j, w, wave_number(w, p.gravity, p.depth), a, phase, beta);
      }
    }
    std::size_t j = n_spectral;
    for (const RegularWave& w : p.regular)
      if (w.height > 0.0)
        set_component(j++, regular_wave_frequency(w, p.gravity, p.depth),
                      regular_wave_number(w, p.gravity, p.depth), 0.5 * w.height,
                      simd::reduce_phase_exact(w.phase), w.direction);
    finite_depth_ = !std::isinf(p.depth);
    double amp_sum = 0.0;
    for (double a : amp_) amp_sum += a;
    trough_bound_ = amp_sum * (1.0 + 1e-9);
    // The spectrum's k and ω grow with j; a regular wave may exceed them: the largest of all.
    const double k_max = *std::max_element(k_.begin(), k_.end());
    const double omega_max = *std::max_element(omega_.begin(), omega_.end());
    z_exp_limit_ = 700.0 / k_max;
    check_derived();
    // The kernel's accurate range, checked once per query: |φ_j − ω_j t| ≤ 2π + ω_max |t| within
    // wrap_two_pi's exact range, |k_j (x cos β + y sin β) + α| ≤ k_max (|x| + |y|) + π within
    // fast_sincos's. (A regular wave's phase φ may be any finite number: reduced first.)
    time_fast_limit_ = (simd::kWrapTwoPiLimit - 8.0) / omega_max;
    position_fast_limit_ = (simd::kFastSinCosLimit - 8.0) / k_max;
  }

  /// \brief True for a calm sea (no components).
  /// \return size() == 0.
  bool empty() const { return omega_.empty(); }
  /// \brief Number of components.
  /// \return The spectral components (0 when Hs = 0, else n_components) followed by one per
  /// regular wave of height > 0.
  std::size_t size() const { return omega_.size(); }
  /// \brief The parameters the field was built from.
  /// \return The parameters (default ones for the calm default-constructed field).
  const WaveFieldParameters& parameters() const { return params_; }
  /// \brief Angular frequency ω_j [rad/s] of component j.
  /// \param j Component index, < size() (not checked).
  /// \return ω_j [rad/s].
  double omega(std::size_t j) const { return omega_[j]; }
  /// \brief Wave number k_j [rad/m] of component j.
  /// \param j Component index, < size() (not checked).
  /// \return k_j [rad/m].
  double wave_number_of(std::size_t j) const { return k_[j]; }
  /// \brief Amplitude a_j [m] of component j.
  /// \param j Component index, < size() (not checked).
  /// \return a_j [m] (half the height of a regular wave).
  double amplitude(std::size_t j) const { return amp_[j]; }
  /// \brief Phase φ_j [rad] of component j.
  /// \param j Component index, < size() (not checked).
  /// \return φ_j [rad] (a regular wave's reduced to [−π, π]).
  double phase(std::size_t j) const { return phase_[j]; }
  /// \brief Direction β_j [rad] (NED azimuth travelled towards) of component j.
  /// \param j Component index, < size() (not checked).
  /// \return β_j [rad].
  double direction(std::size_t j) const { return dir_[j]; }
  /// \brief Pins the instruction path of this field's batch kernel (kelp/core/kernel_path.hpp):
  /// `portable` gives the same bits on every CPU (the deterministic mode); `automatic` (the
  /// default) follows the process' policy (`simd::set_kernel_policy`, the `KELP_KERNEL`
  /// environment variable), else the widest path the CPU runs. Copies of the field keep it.
  /// \param path The path to pin, or `automatic` to unpin.
  /// \throws kelp::invalid_argument when the CPU (or the build) lacks `path`.
  void set_kernel(simd::KernelPath path) {
    if (path != simd::KernelPath::automatic) simd::resolve_kernel(path);  // checks support
    kernel_ = path;
  }
  /// \brief The path set by `set_kernel` (`automatic` unless pinned).
  /// \return The pinned path, or `automatic`.
  simd::KernelPath kernel() const { return kernel_; }
  /// \brief The concrete path this field's queries take now (`kernel()`, or the process' policy
  /// or the widest path when that is `automatic`).
  /// \return A concrete path (never `automatic`).
  /// \throws kelp::invalid_argument for a bad `KELP_KERNEL` (see `simd::kernel_policy`).
  simd::KernelPath active_kernel() const {
    return kernel_ == simd::KernelPath::automatic ? simd::active_kernel() : kernel_;
  }
  /// \brief `set_kernel(on ? portable : automatic)` (kept for existing callers).
  /// \param on True: pin the portable path; false: unpin.
  void set_force_baseline_kernel(bool on) {
    set_kernel(on ? simd::KernelPath::portable : simd::KernelPath::automatic);
  }
  /// \brief Variance of the discretised elevation Σ a_j²/2 [m²] (≈ Hs²/16).
  /// \return Σ a_j²/2 [m²] over all components, regular waves included (0 for a calm sea).
  double variance() const {
    double v = 0.0;
    for (double a : amp_) v += 0.5 * a * a;
    return v;
  }

  /// \brief The time part φ_j − ω_j t of component j's phase [rad], formed in double and reduced
  /// to [−π, π] (time is a double for every Scalar, so the phase does not lose precision as t
  /// grows, nor with a single-precision model; beyond the fast reduction's range, t ≳ 1e8 s, it
  /// is reduced as exactly as std::cos would). \param[in] j component \param[in] t time [s]
  /// \return φ_j − ω_j t reduced to [−π, π] [rad].
  /// \throws kelp::invalid_argument when t is not finite.
  double time_phase(std::size_t j, double t) const {
    const double x = phase_[j] - omega_[j] * t;
    if (std::fabs(x) <= simd::kWrapTwoPiLimit) return simd::wrap_two_pi(x);
    check_time(t);
    return simd::reduce_phase_exact(x);
  }

  /// \brief Surface elevation ζ(x, y, t) [m], positive up.
  /// \param[in] x NED north [m] \param[in] y NED east [m] \param[in] t time [s] (a double for
  /// every Scalar)
  /// \return ζ [m], positive up (0 for a calm sea).
  /// \throws kelp::invalid_argument when t is not finite (a NaN x or y gives NaN).
  Scalar elevation(const Scalar& x, const Scalar& y, double t) const {
    if constexpr (std::is_floating_point_v<Scalar>) {
      const double xd = x, yd = y;
      if (!fast_range(xd, yd, t)) return static_cast<Scalar>(elevation_exact(xd, yd, t));
      double z = 0.0;
      for (std::size_t j = 0; j < omega_.size(); ++j) {
        double s, c;
        simd::fast_sincos(kx_[j] * xd + ky_[j] * yd + fast_time_phase(j, t), s, c);
        z += amp_[j] * c;
      }
      return static_cast<Scalar>(z);
    } else {
      using std::cos;
      check_time(t);
      Scalar z(0);
      for (std::size_t j = 0; j < omega_.size(); ++j)
        z += Scalar(amp_[j]) *
             cos(Scalar(kx_[j]) * x + Scalar(ky_[j]) * y + Scalar(time_phase(j, t)));
      return z;
    }
  }

  /// \brief Surface slope (∂ζ/∂x, ∂ζ/∂y) [-] at (x, y, t): the rise of the surface per metre
  /// north and per metre east.
  /// \param[in] x NED north [m] \param[in] y NED east [m] \param[in] t time [s]
  /// \return (∂ζ/∂x, ∂ζ/∂y) [-].
  /// \throws kelp::invalid_argument when t is not finite (a NaN x or y gives NaN).
  Eigen::Matrix<Scalar, 2, 1> slope(const Scalar& x, const Scalar& y, double t) const {
    if constexpr (std::is_floating_point_v<Scalar>) {
      const double xd = x, yd = y;
      double sx = 0.0, sy = 0.0;
      if (!fast_range(xd, yd, t)) {  // huge t or position: the C library's sine
        for (std::size_t j = 0; j < omega_.size(); ++j) {
          const double s = std::sin(kx_[j] * xd + ky_[j] * yd + time_phase(j, t));
          sx -= kx_[j] * amp_[j] * s;
          sy -= ky_[j] * amp_[j] * s;
        }
        return Eigen::Matrix<Scalar, 2, 1>(static_cast<Scalar>(sx), static_cast<Scalar>(sy));
      }
      for (std::size_t j = 0; j < omega_.size(); ++j) {
        double s, c;
        simd::fast_sincos(kx_[j] * xd + ky_[j] * yd + fast_time_phase(j, t), s, c);
        sx -= kx_[j] * amp_[j] * s;
        sy -= ky_[j] * amp_[j] * s;
      }
      return Eigen::Matrix<Scalar, 2, 1>(static_cast<Scalar>(sx), static_cast<Scalar>(sy));
    } else {
      using std::sin;
      check_time(t);
      Scalar sx(0), sy(0);
      for (std::size_t j = 0; j < omega_.size(); ++j) {
        const Scalar s = Scalar(amp_[j]) *
                         sin(Scalar(kx_[j]) * x + Scalar(ky_[j]) * y + Scalar(time_phase(j, t)));
        sx -= Scalar(kx_[j]) * s;
        sy -= Scalar(ky_[j]) * s;
      }
      return Eigen::Matrix<Scalar, 2, 1>(sx, sy);
    }
  }

  /// \brief Elevation, orbital velocity and acceleration at NED point `p` and time `t`.
  /// \param[in] p NED position [m] \param[in] t time [s]
  /// \tparam Derived Any Eigen vector expression with 3 entries.
  /// \return Elevation, velocity, acceleration, and (this query only) velocity gradient and
  /// slope; all zero for a calm sea.
  /// \throws kelp::invalid_argument when t is not finite (a NaN position gives NaN).
  template <typename Derived>
  WaveKinematics<Scalar> kinematics(const Eigen::MatrixBase<Derived>& p, double t) const {
    WaveKinematics<Scalar> out;
    if (empty()) return out;
    if constexpr (std::is_floating_point_v<Scalar>) {
      Block b;
      b.x[0] = static_cast<double>(p(0));
      b.y[0] = static_cast<double>(p(1));
      b.z[0] = static_cast<double>(p(2));
      run_block(b, 1, t);
      out.elevation = static_cast<Scalar>(b.zeta[0]);
      out.velocity << static_cast<Scalar>(b.vx[0]), static_cast<Scalar>(b.vy[0]),
          static_cast<Scalar>(b.vz[0]);
      out.acceleration << static_cast<Scalar>(b.ax[0]), static_cast<Scalar>(b.ay[0]),
          static_cast<Scalar>(b.az[0]);
      out.slope << static_cast<Scalar>(b.sx), static_cast<Scalar>(b.sy);
      if (!(b.z[0] < -b.zeta[0])) {
        const double gzz = -b.gxx - b.gyy;
        out.velocity_gradient << b.gxx, b.gxy, b.gxz, b.gxy, b.gyy, b.gyz, b.gxz, b.gyz, gzz;
      }
    } else {
      generic_point(Vector3<Scalar>(p(0), p(1), p(2)), t, out);
    }
    return out;
  }

  /// \brief Orbital velocity and acceleration at many NED points (the columns of `points`);
  /// no heap allocation. Overwrites `velocity` and `acceleration` (3×n each).
  /// \param[in] points 3×n NED [m] \param[in] t time [s]
  /// \param[out] velocity 3×n NED [m/s] \param[out] acceleration 3×n NED [m/s²]
  /// \throws kelp::invalid_argument when the output sizes differ from the points' or t is not
  /// finite (a NaN position gives NaN at that point only).
  void kinematics(const Eigen::Ref<const Matrix3X<Scalar>>& points, double t,
                  Eigen::Ref<Matrix3X<Scalar>> velocity,
                  Eigen::Ref<Matrix3X<Scalar>> acceleration) const {
    batch(points, t, velocity, acceleration, nullptr);
  }

  /// \brief The same, plus the surface elevation ζ(x_i, y_i, t) above each point [m] (the sums
  /// share the phases, so this costs a few per cent more, far less than separate `elevation`
  /// calls).
  /// \param[in] points 3×n NED [m] \param[in] t time [s]
  /// \param[out] velocity 3×n NED [m/s] \param[out] acceleration 3×n NED [m/s²]
  /// \param[out] elevation n values [m], positive up
  /// \throws kelp::invalid_argument as the overload above, or when elevation has not n entries.
  void kinematics(const Eigen::Ref<const Matrix3X<Scalar>>& points, double t,
                  Eigen::Ref<Matrix3X<Scalar>> velocity, Eigen::Ref<Matrix3X<Scalar>> acceleration,
                  Eigen::Ref<VectorX<Scalar>> elevation) const {
    KELP_CHECK(elevation.size() == points.cols(),
               "wave kinematics: elevation must have one entry per point");
    batch(points, t, velocity, acceleration, elevation.data());
  }

 private:
  /// The batch queries; `elevation` (n values) is written when not null.
  void batch(const Eigen::Ref<const Matrix3X<Scalar>>& points, double t,
             Eigen::Ref<Matrix3X<Scalar>> velocity, Eigen::Ref<Matrix3X<Scalar>> acceleration,
             Scalar* elevation) const {
    KELP_CHECK(velocity.cols() == points.cols() && acceleration.cols() == points.cols(),
               "wave kinematics: velocity and acceleration must have as many columns as points");
    if (empty()) {
      velocity.setZero();
      acceleration.setZero();
      if (elevation != nullptr) std::fill(elevation, elevation + points.cols(), Scalar(0));
      return;
    }
    const Eigen::Index n = points.cols();
    if constexpr (std::is_floating_point_v<Scalar>) {
      Block b;
      b.need_zeta = elevation != nullptr;
      const double td = t;
      for (Eigen::Index i0 = 0; i0 < n; i0 += kBlock) {
        const int m = static_cast<int>(std::min<Eigen::Index>(kBlock, n - i0));
        for (int i = 0; i < m; ++i) {
          b.x[i] = static_cast<double>(points(0, i0 + i));
          b.y[i] = static_cast<double>(points(1, i0 + i));
          b.z[i] = static_cast<double>(points(2, i0 + i));
        }
        run_block(b, m, td);
        for (int i = 0; i < m; ++i) {
          velocity(0, i0 + i) = static_cast<Scalar>(b.vx[i]);
          velocity(1, i0 + i) = static_cast<Scalar>(b.vy[i]);
          velocity(2, i0 + i) = static_cast<Scalar>(b.vz[i]);
          acceleration(0, i0 + i) = static_cast<Scalar>(b.ax[i]);
          acceleration(1, i0 + i) = static_cast<Scalar>(b.ay[i]);
          acceleration(2, i0 + i) = static_cast<Scalar>(b.az[i]);
        }
        if (elevation != nullptr)
          for (int i = 0; i < m; ++i) elevation[i0 + i] = static_cast<Scalar>(b.zeta[i]);
      }
    } else {
      for (Eigen::Index i = 0; i < n; ++i) {
        WaveKinematics<Scalar> k;
        generic_point(Vector3<Scalar>(points.col(i)), t, k);
        velocity.col(i) = k.velocity;
        acceleration.col(i) = k.acceleration;
        if (elevation != nullptr) elevation[i] = k.elevation;
      }
    }
  }

  static constexpr int kBlock = detail::kWaveBlock;

  /// ∫ S dω over [w0, w0 + dw] by composite Simpson with 32 sub-intervals.
  static double bin_energy(const WaveSpectrum& spec, double w0, double dw) {
    constexpr int n = 32;
    const double h = dw / n;
    double sum = spectral_density(spec, w0) + spectral_density(spec, w0 + dw);
    for (int i = 1; i < n; ++i)
      sum += (i % 2 ? 4.0 : 2.0) * spectral_density(spec, w0 + static_cast<double>(i) * h);
    return sum * h / 3.0;
  }
  using Block = detail::WaveBlock;

  /// Evaluates m ≤ kBlock points (b.x, b.y, b.z) at time t into b's outputs.
  ///
  /// The vectorised kernel is accurate while every phase stays within the fast reductions' range
  /// (|t| ≤ time_fast_limit_, |x| + |y| ≤ position_fast_limit_: for the paper's moderate sea,
  /// Tp ≈ 7.8 s, about 6 years and 600 km from the origin; for Tp = 1 s about 10 months and
  /// 10 km). One compare per call and one per point decide it; beyond, the block is evaluated by
  /// `exact_block` (C library sin/cos after an exact phase reduction: slower, but as accurate as
  /// std::cos for any t and position).
  void run_block(Block& b, int m, double t) const {
    bool fast = std::fabs(t) <= time_fast_limit_;
    for (int i = 0; i < m; ++i) {
      b.ze[i] = profile_depth(b.z[i]);  // the kernel writes b's sums: no zeroing here
      fast &= std::fabs(b.x[i]) + std::fabs(b.y[i]) <= position_fast_limit_;  // NaN: false
    }
    if (!fast) {
      exact_block(b, m, t);
      return;
    }
    if (params_.stretching == WaveStretching::wheeler) {
      // First pass for the elevation above every point (the profiles' depth is irrelevant to
      // it), then the profiles at the stretched depths.
      const bool need_zeta = b.need_zeta;
      b.need_zeta = true;
      detail::wave_accumulate(view(), b, m, t, finite_depth_, active_kernel());
      b.need_zeta = need_zeta;
      for (int i = 0; i < m; ++i) b.ze[i] = profile_depth(wheeler_depth(b.z[i], b.zeta[i]));
    }
    detail::wave_accumulate(view(), b, m, t, finite_depth_, active_kernel());
    for (int i = 0; i < m; ++i) {
      if (b.z[i] < -b.zeta[i]) {  // above the free surface: no water, no orbital motion
        b.vx[i] = b.vy[i] = b.vz[i] = b.ax[i] = b.ay[i] = b.az[i] = 0.0;
      }
    }
  }

  /// Component j's constants from its frequency w, wave number k, amplitude a, phase and
  /// direction beta [rad].
  void set_component(std::size_t j, double w, double k, double a, double phase, double beta) {
    omega_[j] = w;
    k_[j] = k;
    amp_[j] = a;
    phase_[j] = phase;
    dir_[j] = beta;
    cosb_[j] = std::cos(beta);
    sinb_[j] = std::sin(beta);
    kx_[j] = k * cosb_[j];
    ky_[j] = k * sinb_[j];
    aw_[j] = a * w;
    aw2_[j] = a * w * w;
    awc_[j] = aw_[j] * cosb_[j];
    aws_[j] = aw_[j] * sinb_[j];
    aw2c_[j] = aw2_[j] * cosb_[j];
    aw2s_[j] = aw2_[j] * sinb_[j];
    gc_[j] = k * awc_[j];
    gs_[j] = k * aws_[j];
    gcc_[j] = gc_[j] * cosb_[j];
    gcs_[j] = gc_[j] * sinb_[j];
    gss_[j] = gs_[j] * sinb_[j];
    // 1 / (1 − e^{−2kh}): the common factor of cosh/sinh ratios written with decaying
    // exponentials only (no overflow for large k h).
    q_[j] = std::isinf(params_.depth) ? 1.0 : 1.0 / (-std::expm1(-2.0 * k * params_.depth));
    e2h_[j] = std::isinf(params_.depth) ? 0.0 : std::exp(-2.0 * k * params_.depth);
  }

  /// The depth at which the kernel takes the profiles for a point at depth z (or at a stretched
  /// depth): the crest region reads z = 0, a point below the seabed the seabed, and k z stays
  /// ≤ 700 (e^{−k z} < 1e-304 beyond).
  double profile_depth(double z) const {
    if (z < 0.0) z = 0.0;                                       // crest region: z = 0's
    if (finite_depth_ && z > params_.depth) z = params_.depth;  // below the seabed: the seabed's
    if (z > z_exp_limit_) z = z_exp_limit_;
    return z;
  }

  /// Wheeler's stretched depth z' = (z + ζ) h / (h + ζ) (deep water: z + ζ) of a point at depth
  /// z under a surface of elevation ζ (see WaveStretching::wheeler); a column with no water
  /// (h + ζ ≤ 0) reads the seabed's.
  template <typename T>
  T wheeler_depth(const T& z, const T& zeta) const {
    if (!finite_depth_) return z + zeta;
    const T column = T(params_.depth) + zeta;
    if (!(value_of(column) > 0.0)) return T(params_.depth);
    return (z + zeta) * (T(params_.depth) / column);
  }

  /// Throws `kelp::invalid_argument` naming the spectrum's parameters unless every derived
  /// constant of the discretised sea is finite (and every wave number > 0, so that the kernel's
  /// depth limit 700/k_max is finite).
  void check_derived() const {
    bool ok = std::isfinite(trough_bound_) && std::isfinite(z_exp_limit_);
    for (std::size_t j = 0; j < omega_.size(); ++j)
      ok = ok && std::isfinite(omega_[j]) && std::isfinite(k_[j]) && k_[j] > 0.0 &&
           std::isfinite(amp_[j]) && std::isfinite(aw2_[j]) && std::isfinite(gcc_[j]) &&
           std::isfinite(gss_[j]) && std::isfinite(q_[j]);
    if (ok) return;
    std::ostringstream msg;
    msg.precision(9);
    msg << "wave field: significant_height = " << params_.spectrum.significant_height
        << " m, peak_period = " << params_.spectrum.peak_period
        << " s, omega_min_factor = " << params_.omega_min_factor
        << ", omega_max_factor = " << params_.omega_max_factor << ", gravity = " << params_.gravity
        << " m/s^2 and depth = " << params_.depth
        << " m give a non-finite component frequency, wave number or amplitude";
    ::kelp::detail::throw_invalid_argument(msg.str());
  }

  /// Throws `kelp::invalid_argument` naming the time unless it is finite.
  static void check_time(double t) {
    if (!std::isfinite(t)) detail::throw_bad_value("wave field: time t", "finite", t);
  }

  /// True when the fast kernels are accurate for a query at (x, y) and time t (false for NaN).
  bool fast_range(double x, double y, double t) const {
    return std::fabs(t) <= time_fast_limit_ && std::fabs(x) + std::fabs(y) <= position_fast_limit_;
  }

  /// `time_phase` for |t| ≤ time_fast_limit_ (checked by the caller, once per query).
  double fast_time_phase(std::size_t j, double t) const {
    return simd::wrap_two_pi(phase_[j] - omega_[j] * t);
  }

  /// ζ(x, y, t) with the C library's cosine and exactly reduced time phases (any finite t).
  KELP_COLD double elevation_exact(double x, double y, double t) const {
    double z = 0.0;
    for (std::size_t j = 0; j < omega_.size(); ++j)
      z += amp_[j] * std::cos(kx_[j] * x + ky_[j] * y + time_phase(j, t));
    return z;
  }

  /// The block's sums by `generic_point` in double, point by point (the fallback of run_block).
  KELP_COLD void exact_block(Block& b, int m, double t) const {
    check_time(t);
    for (int i = 0; i < m; ++i) {
      WaveKinematics<double> k;
      generic_point<double>(Vector3<double>(b.x[i], b.y[i], b.z[i]), t, k);
      b.zeta[i] = k.elevation;
      b.vx[i] = k.velocity(0);
      b.vy[i] = k.velocity(1);
      b.vz[i] = k.velocity(2);
      b.ax[i] = k.acceleration(0);
      b.ay[i] = k.acceleration(1);
      b.az[i] = k.acceleration(2);
      if (i == 0) {
        b.gxx = k.velocity_gradient(0, 0);
        b.gxy = k.velocity_gradient(0, 1);
        b.gyy = k.velocity_gradient(1, 1);
        b.gxz = k.velocity_gradient(0, 2);
        b.gyz = k.velocity_gradient(1, 2);
        b.sx = k.slope(0);
        b.sy = k.slope(1);
      }
    }
  }

  /// The same sums with ADL math for automatic-differentiation scalars (T = Scalar), and in
  /// double for the floating-point fallback (T = double). The crest and seabed clamps use the
  /// value part only (they select a branch, not a derivative).
  template <typename T>
  void generic_point(const Vector3<T>& p, double t, WaveKinematics<T>& out) const {
    using std::cos;
    using std::exp;
    using std::sin;
    check_time(t);
    T z = p(2);
    if (params_.stretching == WaveStretching::wheeler) {
      T zeta(0);
      for (std::size_t j = 0; j < omega_.size(); ++j)
        zeta += T(amp_[j]) * cos(T(kx_[j]) * p(0) + T(ky_[j]) * p(1) + T(time_phase(j, t)));
      z = wheeler_depth(z, zeta);
    }
    if (value_of(z) < 0.0) z = T(0);
    if (finite_depth_ && value_of(z) > params_.depth) z = T(params_.depth);
    out = WaveKinematics<T>();
    for (std::size_t j = 0; j < omega_.size(); ++j) {
      const T th = T(kx_[j]) * p(0) + T(ky_[j]) * p(1) + T(time_phase(j, t));
      const T s = sin(th), c = cos(th);
      const T e = exp(T(-k_[j]) * z);
      T fh = e, fv = e;
      if (finite_depth_) {
        const T e2 = exp(T(-k_[j]) * (T(2.0 * params_.depth) - z));
        fh = (e + e2) * T(q_[j]);
        fv = (e - e2) * T(q_[j]);
      }
      out.elevation += T(amp_[j]) * c;
      out.slope -= Eigen::Matrix<T, 2, 1>(T(kx_[j]) * T(amp_[j]) * s, T(ky_[j]) * T(amp_[j]) * s);
      const T hv = T(aw_[j]) * fh * c, ha = T(aw2_[j]) * fh * s;
      out.velocity += Vector3<T>(hv * T(cosb_[j]), hv * T(sinb_[j]), -T(aw_[j]) * fv * s);
      out.acceleration += Vector3<T>(ha * T(cosb_[j]), ha * T(sinb_[j]), T(aw2_[j]) * fv * c);
      const T hs = fh * s, fvc = fv * c;
      const T gxx = -T(gcc_[j]) * hs, gxy = -T(gcs_[j]) * hs;
      const T gyy = -T(gss_[j]) * hs, gxz = -T(gc_[j]) * fvc;
      const T gyz = -T(gs_[j]) * fvc;
      Eigen::Matrix<T, 3, 3> g;
      g << gxx, gxy, gxz, gxy, gyy, gyz, gxz, gyz, -gxx - gyy;
      out.velocity_gradient += g;
    }
    if (value_of(p(2)) < -value_of(out.elevation)) {
      out.velocity.setZero();
      out.acceleration.setZero();
      out.velocity_gradient.setZero();
    }
  }

  detail::WaveComponentsView view() const {
    return {omega_.data(),       k_.data(),    amp_.data(), phase_.data(), kx_.data(),
            ky_.data(),          aw_.data(),   aw2_.data(), awc_.data(),   aws_.data(),
            aw2c_.data(),        aw2s_.data(), q_.data(),   e2h_.data(),   gcc_.data(),
            gcs_.data(),         gss_.data(),  gc_.data(),  gs_.data(),    omega_.size(),
            2.0 * params_.depth, trough_bound_};
  }

  WaveFieldParameters params_;
  bool finite_depth_ = false;
  simd::KernelPath kernel_ = simd::KernelPath::automatic;  ///< see set_kernel
  double z_exp_limit_ = std::numeric_limits<double>::infinity();
  /// |t| [s] and |x| + |y| [m] up to which the fast kernels are accurate (see run_block).
  double time_fast_limit_ = 0.0, position_fast_limit_ = 0.0;
  double trough_bound_ = 0.0;  ///< see `detail::WaveComponentsView::trough_bound`
  std::vector<double> omega_, k_, amp_, phase_, dir_, kx_, ky_, cosb_, sinb_, aw_, aw2_, awc_, aws_,
      aw2c_, aw2s_, q_, e2h_, gcc_, gcs_, gss_, gc_, gs_;
};

/// \brief Double-precision wave field.
using WaveFieldd = WaveField<double>;
/// \brief Single-precision wave field (sums still run in double).
using WaveFieldf = WaveField<float>;

}  // namespace environment
}  // namespace kelp
