/// \file
/// \brief The largest stable explicit time step of a tether: the line linearised into damped
/// oscillators (axial and bending stiffness, seabed spring, internal dashpots, drag, seabed
/// dashpot), bounded node by node with Gershgorin's theorem, and each oscillator's eigenvalues
/// kept inside the stability region of the explicit scheme.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/environment/limits.hpp"

#include "kelp/tether/model.hpp"
#include "kelp/tether/stepping.hpp"

namespace kelp::tether {

/// \brief Settings of estimate_stable_dt.
/// \tparam Scalar double, float or ceres::Jet (the estimate is computed on the value parts).
template <typename Scalar>
struct StableDtOptions {
  /// Water density ρ [kg/m³] for the drag's damping rate (0: a line in air or vacuum). The
  /// masses are the structural ones whatever ρ: a node at or above the surface has no added mass.
  Scalar water_density = Scalar(kelp::seawater_density);
  /// Factor in (0, 1] on the stability limit.
  Scalar safety = Scalar(0.8);
  /// Bound [m/s] on a node's speed relative to the water, |u_water − v|, for the drag's
  /// linearised damping rate ρ d l_i max(Cdn, π Cdt) |v_r| / m_i. 5 m/s covers the paper's
  /// vehicles (≤ 2 m/s), currents and rough-sea orbital velocities together; raise it for a line
  /// towed fast or whipping in a snap load.
  Scalar max_relative_speed = Scalar(5);
  /// Include seabed contact (spring k_b d l_i and dashpot c_b d l_i on a node that touches the
  /// seabed). Set it when the environment has a seabed the line can reach: on the default
  /// seabed (c_b = 3·10⁵ Pa s/m, MoorDyn's) the dashpot alone limits RK4 to ≈ 8e-5 s on any line
  /// of μ = 0.07 kg/m, d = 8 mm.
  bool seabed_contact = false;
};

/// \brief Double-precision options.
using StableDtOptionsd = StableDtOptions<double>;
/// \brief Single-precision options.
using StableDtOptionsf = StableDtOptions<float>;

namespace detail {

/// Number of segment springs on node i of a line of n segments (1 at an end, else 2).
inline int node_springs(int i, int n) { return (i > 0 ? 1 : 0) + (i < n ? 1 : 0); }

/// Water densities from 0 (air, vacuum) to the environment's `limits::max_fluid_density` (1e5
/// kg/m³, seven times mercury's); NaN and Inf refused.
template <typename Scalar>
void check_water_density(const Scalar& rho) {
  check_non_negative(rho, "water_density");
  check_at_most(rho, ::kelp::environment::limits::max_fluid_density, "water_density");
}

/// The line linearised about a taut state, as a family of damped oscillators
/// ẍ + c ẋ + ω² x = 0 with ω² = s + s_b + κ and c = α + β s for every axial eigenvalue
/// s ∈ [0, s_max] of M⁻¹K (Gershgorin bounds, structural node masses).
struct LinearisedLine {
  double s_max = 0;        ///< axial: max_i Σ_j ‖K_ij‖ / m_i [1/s²]
  double bending = 0;      ///< bending: max_i 16 EI/(l³ m_i) [1/s²]
  double bed_spring = 0;   ///< seabed spring κ = max_i k_b d l_i / m_i [1/s²]
  double bed_damping = 0;  ///< seabed dashpot max_i c_b d l_i / m_i [1/s]
  double drag = 0;         ///< drag max_i ρ d l_i max(Cdn, π Cdt) V / m_i [1/s]
  double beta = 0;         ///< internal damping BA/EA [s] (the dashpots are β × the springs)
};

template <typename Scalar>
LinearisedLine linearise_line(const TetherModel<Scalar>& model, double water_density,
                              double max_speed, bool seabed) {
  const TetherParameters<Scalar>& p = model.parameters();
  const int n = model.segments();
  const double l = value_of(model.segment_length()), k = value_of(model.axial_spring());
  const double ei = value_of(p.bending_stiffness), d = value_of(p.diameter);
  const double drag_coefficient =
      std::max(value_of(p.normal_drag), kelp::pi * value_of(p.tangential_drag));
  LinearisedLine line;
  line.beta = value_of(p.internal_damping) / value_of(p.axial_stiffness);
  for (int i = model.first_free_node(); i <= model.last_free_node(); ++i) {
    const double m = value_of(model.node_mass(i)), li = value_of(model.node_length(i));
    // Row i of K: diagonal Σ k over the node's springs, off-diagonal −k each (3×3 blocks of
    // norm ≤ EA/l: the tension's geometric stiffness T/|d| is below EA/l), so Σ_j ‖K_ij‖ =
    // 2 k (springs).
    line.s_max = std::max(line.s_max, 2.0 * node_springs(i, n) * k / m);
    if (ei > 0) line.bending = std::max(line.bending, 16.0 * ei / (l * l * l * m));
    line.drag = std::max(line.drag, water_density * d * li * drag_coefficient * max_speed / m);
    if (seabed) {
      line.bed_spring = std::max(line.bed_spring, value_of(p.seabed_stiffness) * d * li / m);
      line.bed_damping = std::max(line.bed_damping, value_of(p.seabed_damping) * d * li / m);
    }
  }
  return line;
}

/// True when the scheme is stable for the oscillator ẍ + c ẋ + ω² x = 0 at step h.
/// Symplectic Euler (v⁺ = v + h(−ω²x − c v), x⁺ = x + h v⁺) has the amplification matrix of
/// determinant 1 − hc and trace 2 − h²ω² − hc; Jury's conditions |det| ≤ 1, |tr| ≤ 1 + det give
/// hc ≤ 2 and h²ω² + 2hc ≤ 4 (i.e. hω ≤ 2(√(1 + ζ²) − ζ), Bathe §9.4). RK2 and RK4: both
/// eigenvalues λ = (−c ± √(c² − 4ω²))/2 have |R(hλ)| ≤ 1 with R(z) = Σ_{k≤p} z^k/k!
/// (Hairer–Wanner, Solving ODEs II, §IV.2).
inline bool oscillator_stable(Integrator integ, double h, double w2, double c) {
  if (integ == Integrator::symplectic_euler) {
    const double det = 1.0 - h * c, tr = 2.0 - h * h * w2 - h * c;
    return std::abs(det) <= 1.0 && std::abs(tr) <= 1.0 + det;
  }
  // λ = (−c ± √(c² − 4ω²))/2, complex arithmetic written out (std::complex's product goes
  // through the library's NaN-checking __muldc3).
  const double disc = c * c - 4.0 * w2;
  const double root = std::sqrt(std::abs(disc));
  const double re[2] = {disc >= 0 ? 0.5 * (-c + root) : -0.5 * c,
                        disc >= 0 ? 0.5 * (-c - root) : -0.5 * c};
  const double im[2] = {disc >= 0 ? 0.0 : 0.5 * root, disc >= 0 ? 0.0 : -0.5 * root};
  // Taylor coefficients of R(z) from the highest power down (Horner).
  static constexpr double rk2[] = {0.5, 1.0, 1.0};
  static constexpr double rk4[] = {1.0 / 24.0, 1.0 / 6.0, 0.5, 1.0, 1.0};
  const double* coef = integ == Integrator::rk4 ? rk4 : rk2;
  const int terms = integ == Integrator::rk4 ? 5 : 3;
  for (int k = 0; k < 2; ++k) {
    const double zr = h * re[k], zi = h * im[k];
    double rr = coef[0], ri = 0.0;
    for (int j = 1; j < terms; ++j) {
      const double tr = rr * zr - ri * zi + coef[j];
      ri = rr * zi + ri * zr;
      rr = tr;
    }
    // A relative 1e-13 above 1: the rounding of |R|² where the region touches the axis.
    if (rr * rr + ri * ri > 1.0 + 1e-13) return false;
  }
  return true;
}

/// True when every oscillator of the linearised line is stable at step h: the axial eigenvalue s
/// sampled at 65 points of [0, s_max] (uniform in √s, i.e. in frequency), each with and without
/// drag and with and without seabed contact (a node may be off the seabed or at rest).
inline bool line_stable(Integrator integ, double h, const LinearisedLine& line) {
  constexpr int samples = 64;
  const double alphas[2] = {0.0, line.drag};
  for (int bed = 0; bed < (line.bed_spring > 0 || line.bed_damping > 0 ? 2 : 1); ++bed)
    for (const double alpha : alphas)
      for (int j = 0; j <= samples; ++j) {
        const double f = double(j) / samples, s = line.s_max * f * f;
        const double w2 = s + line.bending + (bed ? line.bed_spring : 0.0);
        const double c = alpha + (bed ? line.bed_damping : 0.0) + line.beta * s;
        if (!oscillator_stable(integ, h, w2, c)) return false;
      }
  return true;
}

}  // namespace detail

/// \brief Largest angular frequency of the line [rad/s], bounded by Gershgorin's theorem.
/// Axial chain: ω²_a ≤ max_i Σ_j ‖K_ij‖ / m_i = max_i 2 k_i / m_i, with k_i the sum of the
/// segment spring constants EA/l on free node i and m_i its structural mass (an interior node:
/// ω_a = 2√(EA/(l μ l)), the top of the lumped chain's spectrum 2√(k/m) sin(jπ/(2N))). Bending
/// (EI > 0): the discrete bending stiffness is (EI/l³)·DᵀD with D the second difference
/// (‖DᵀD‖ ≤ 16), so ω²_b ≤ 16 EI/(l³ m_i). Returns √(ω²_a + ω²_b). The masses are structural:
/// added mass only lowers the frequencies, and a node at or above the surface has none. 0 for a
/// line without a free node (one segment between two kinematic ends: no mode is integrated).
/// \param[in] water_density ρ [kg/m³], checked only (kept for the callers of earlier versions,
/// where it lowered the frequency by the tangential added mass).
/// \throws kelp::invalid_argument for a water density ρ outside [0, 1e5] kg/m³ or NaN.
/// \tparam Scalar double, float or ceres::Jet (computed on the value parts).
/// \param[in] model the tether (EA, EI, l and the free nodes' structural masses).
/// \return √(ω²_a + ω²_b) [rad/s], ≥ 0 (a value, no derivative parts for a Jet).
template <typename Scalar>
Scalar highest_axial_frequency(const TetherModel<Scalar>& model, Scalar water_density) {
  detail::check_water_density(water_density);
  const detail::LinearisedLine line = detail::linearise_line(model, 0.0, 0.0, false);
  return Scalar(std::sqrt(line.s_max + line.bending));
}

/// \brief Estimated largest stable explicit time step [s]: `safety` × the largest h for which
/// the linearised line is stable under the scheme.
///
/// The line is linearised into damped oscillators ẍ + c ẋ + ω² x = 0, one per eigenvalue s of
/// the axial stiffness M⁻¹K (s ∈ [0, s_max], s_max the Gershgorin bound of
/// highest_axial_frequency), with
/// - ω² = s + ω²_b + κ: bending (16 EI/(l³ m)) and the seabed spring κ = k_b d l_i / m_i;
/// - c = α + β s: internal damping is stiffness-proportional (each segment's dashpot BA/l beside
///   its spring EA/l, β = BA/EA: Rayleigh damping, decoupled by the same modes; damping ratio
///   ζ = β ω/2, largest for the stiffest mode), plus the mass-proportional rates α of the seabed
///   dashpot c_b d l_i / m_i and of the drag linearised at `max_relative_speed` V,
///   ρ d l_i max(Cdn, π Cdt) V / m_i (∂(|v|v)/∂v has norm 2|v|); drag and seabed are taken
///   present and absent, since a node may be at rest or off the seabed.
/// Node masses are structural: the lightest effective mass is a node's in air, with no added
/// mass; the free end nodes carry half a segment's mass and one spring, the same ratio as an
/// interior node.
///
/// Every oscillator's eigenvalues hλ must lie in the scheme's stability region (Hairer–Wanner,
/// Solving Ordinary Differential Equations II, §IV.2, Fig. 2.1): for the undamped line
/// h ω_max ≤ 2 for symplectic Euler (Bathe, Finite Element Procedures, §9.4: the central
/// difference method), 2√2 ≈ 2.83 for RK4 (its interval on the imaginary axis), and on the
/// negative real axis h c ≤ 2 (symplectic Euler, RK2) and 2.785 (RK4). RK2 — kelp's is the
/// explicit midpoint rule, R(z) = 1 + z + z²/2 like every two-stage second-order scheme (Heun's
/// too) — is unstable on the imaginary axis except at 0 (|R(iy)|² = 1 + y⁴/4): it needs the
/// internal damping, which with β > 0 makes it stable for h³ s_max ≲ 4β (|R|² ≈ 1 − hβs +
/// h⁴s²/4 for the slow modes) and hω_max inside the region's lobe for the fast ones. The largest
/// h is found by bisection on this test (65 values of s, ≤ 4 drag/seabed cases, ~30 halvings to
/// 1e-9: some 10⁴ complex polynomial evaluations, ~0.1–0.3 ms, no allocation).
///
/// Symplectic Euler and the one-sided spring: a segment's elastic force is EA·max(0, ε), so a
/// line near zero strain switches its springs on and off. Symplectic Euler conserves a modified
/// energy whose ratio to the true one swings between 1 ± hω/2 along an oscillation (Hairer,
/// Lubich, Wanner, Geometric Numerical Integration, ch. IX, backward error analysis: the modified
/// Hamiltonian of the linear oscillator); at every slack–taut switch the true energy carries over
/// and the modified one jumps, so the energy random-walks with steps ~ hω/2. Drag and internal
/// damping hold it; a line in air without internal damping does not: measured on the benchmark line
/// in vacuum with its end moving, 60 s, 100 segments: hω_max = 1 gains 9 MJ (blow-up), 0.7
/// gains 36 J (12 % of the work done), 0.5 gains 1 J (0.35 %); with ζ = 0.05 at the top mode,
/// hω_max = 1.6 gains nothing. Hence for symplectic Euler hω_max ≤ 0.5 + 1.5 min(1, ζ_max/0.05) as
/// well.
///
/// Left out: the tension's geometric stiffness beyond EA/l (it is below it), contact's landing
/// ramp (seabed_damping_depth), the surface band's buoyancy spring ρVg/d (tiny), added-mass rate
/// terms. Transverse (pendulum and bending) modes get no internal damping: RK2 relies on the
/// water's quadratic drag to hold their slow growth (rate ω y³/8 per second at y = hω ≪ 1).
///
/// A line of one segment with a free end has one free node (two with both ends free) and a
/// finite step like any other; a line of one segment between two kinematic ends has none and is
/// refused (see below).
/// \tparam Scalar double, float or ceres::Jet (computed on the value parts).
/// \param[in] model the tether.
/// \param[in] integrator the scheme the step is for.
/// \param[in] options water density (drag), safety factor, speed bound, seabed contact.
/// \return the step [s]; +infinity for the implicit schemes (unconditionally stable for the
/// linearised line; choose dt for accuracy, e.g. 10 ms).
/// \throws kelp::invalid_argument for ρ outside [0, 1e5] kg/m³ or NaN, a safety factor outside
/// (0, 1], a speed bound not finite in [0, 1e6] m/s, an Integrator value outside the enumeration,
/// a line without a free node (one segment with both ends kinematic: nothing is integrated, so
/// no step is limited by stability, whatever the scheme), or RK2 on a line without internal
/// damping (BA = 0: its axial modes grow at every step; give the line internal damping, e.g.
/// ζ = 0.2 at the highest mode, BA = 2ζ·EA/ω_max = 0.4·EA/ω_max with ω_max from
/// highest_axial_frequency, or use symplectic Euler or RK4).
template <typename Scalar>
Scalar estimate_stable_dt(const TetherModel<Scalar>& model, Integrator integrator,
                          const StableDtOptions<Scalar>& options) {
  check_positive(options.safety, "safety");
  check_at_most(options.safety, 1.0, "safety");
  detail::check_water_density(options.water_density);
  check_non_negative(options.max_relative_speed, "max_relative_speed");
  check_at_most(options.max_relative_speed, 1e6, "max_relative_speed");
  KELP_CHECK(is_valid(integrator), "integrator is not a kelp::tether::Integrator value");
  // One segment between two kinematic ends: no node is integrated (the step only moves the ends),
  // so there is no oscillator to bound. +∞ here would be a number a step then refuses as dt.
  KELP_CHECK(model.first_free_node() <= model.last_free_node(),
             "estimate_stable_dt: the line has no free node (one segment with both ends "
             "kinematic): nothing is integrated, so no time step is limited by stability; "
             "choose dt for the motion of the ends");
  if (is_implicit(integrator)) return std::numeric_limits<Scalar>::infinity();
  const detail::LinearisedLine line =
      detail::linearise_line(model, value_of(options.water_density),
                             value_of(options.max_relative_speed), options.seabed_contact);
  KELP_CHECK(integrator != Integrator::rk2 || line.beta > 0.0,
             "estimate_stable_dt: RK2 (explicit midpoint) amplifies undamped oscillations at "
             "every step; give the line internal damping (TetherParameters::internal_damping > "
             "0) or use symplectic Euler or RK4");
  // Bracket: stable at 0; grow the upper end until unstable (hω_max = 3 is beyond every
  // scheme's imaginary-axis limit, but a heavily damped line may be stable further out).
  const double w_max = std::sqrt(line.s_max + line.bending + line.bed_spring);
  double lo = 0.0, hi = 3.0 / w_max;
  for (int k = 0; k < 60 && detail::line_stable(integrator, hi, line); ++k) {
    lo = hi;
    hi *= 2.0;
  }
  for (int k = 0; k < 60 && hi - lo > 1e-9 * hi; ++k) {
    const double mid = 0.5 * (lo + hi);
    (detail::line_stable(integrator, mid, line) ? lo : hi) = mid;
  }
  KELP_CHECK(lo > 0.0, "estimate_stable_dt: no stable step found for this line");
  if (integrator == Integrator::symplectic_euler) {
    // The one-sided spring: hω_max ≤ 0.5 on an undamped line, rising to the linear limit at a
    // damping ratio of 0.05 at the highest mode (see the doc comment).
    const double zeta_top = 0.5 * line.beta * std::sqrt(line.s_max);
    const double cap = (0.5 + 1.5 * std::min(1.0, zeta_top / 0.05)) / w_max;
    lo = std::min(lo, cap);
  }
  return options.safety * Scalar(lo);
}

/// \brief estimate_stable_dt with StableDtOptions{water_density, safety} (drag at 5 m/s relative
/// speed, no seabed contact). \param[in] water_density ρ [kg/m³] for the drag (0: in air).
/// \param[in] safety factor in (0, 1] on the stability limit.
/// \throws as estimate_stable_dt(const TetherModel&, Integrator, const StableDtOptions&).
/// \tparam Scalar double, float or ceres::Jet.
/// \param[in] model the tether.
/// \param[in] integrator the scheme the step is for.
/// \return the step [s]; +infinity for the implicit schemes.
template <typename Scalar>
Scalar estimate_stable_dt(const TetherModel<Scalar>& model, Integrator integrator,
                          Scalar water_density = Scalar(kelp::seawater_density),
                          Scalar safety = Scalar(0.8)) {
  StableDtOptions<Scalar> options;
  options.water_density = water_density;
  options.safety = safety;
  return estimate_stable_dt(model, integrator, options);
}

}  // namespace kelp::tether
