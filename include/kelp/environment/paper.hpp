/// \file
/// \brief The paper's disturbance formulas, exactly as written (Buchholz et al. 2025,
/// arXiv:2508.02264, eqs. (2)–(4)), and the small-body, linear-restoring wave loads of the same
/// era: the wave force F_wave = ρ g B L T k and its time-varying form at the encounter frequency,
/// the wind force ½ ρ_air V_w² C_x A_w and its lateral twin, the current component
/// V_c cos α_c cos β_c, the first-order wave force on a small body (ρ∇ I + M_A) Rᵀ u̇_f, and the
/// linear restoring that follows the local surface, G(η − η_s), with its wave part.
///
/// They are kept as named functions to check the paper against (tests and the paper sweep call
/// them); the simulation itself uses the fuller models (`environment.hpp`, `vehicle/model.hpp`).
/// `kelp/kelp.hpp` does not include this header. Shared terms are not repeated here: the
/// Froude–Krylov force is environment::froude_krylov_force (wave_loads.hpp), and the surface
/// vessel's restoring in the simulation is vehicle::restoring_force_surface_following, of which
/// surface_following_restoring() is the small-angle linearisation (Fossen 2021, §4.2).
///
/// Frames: world NED; body x forward, y starboard, z down. Units SI.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <string>
#include <type_traits>

#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/environment/limits.hpp"
#include "kelp/environment/wave_loads.hpp"

namespace kelp {
namespace environment {

/// \brief The paper's current formula (eq:current): v_c = V_c cos α_c cos β_c [m/s].
///
/// The paper writes this one component only. It is the first (north, x) component of Fossen's 3-D
/// current vector (`current_velocity_ned`); with α_c = β_c = 0 it is the whole current, flowing
/// north. \param[in] speed V_c [m/s] \param[in] alpha α_c vertical angle [rad]
/// \param[in] beta β_c horizontal direction [rad]
/// \return v_c [m/s], the north component of the current.
/// \throws kelp::invalid_argument when V_c, α_c or β_c is not finite.
template <typename Scalar>
Scalar paper_current(const Scalar& speed, const Scalar& alpha, const Scalar& beta) {
  using std::cos;
  check_finite(speed, "current speed");
  check_finite(alpha, "current vertical angle alpha");
  check_finite(beta, "current direction beta");
  return speed * cos(alpha) * cos(beta);
}

namespace detail {
/// The preconditions of the paper's wind forces (see `paper_wind_force`).
template <typename Scalar>
void check_paper_wind_arguments(const Scalar& rho_air, const Scalar& wind_speed, const Scalar& c,
                                const Scalar& area, const char* c_name, const char* area_name) {
  check_positive_at_most(value_of(rho_air), limits::max_fluid_density, "rho_air",
                         "finite and in (0, 1e5] kg/m^3");
  check_finite(wind_speed, "wind_speed");
  check_finite(c, c_name);
  check_non_negative(area, area_name);
}
}  // namespace detail

/// \brief The paper's wind force (eq:wind): F_wind = ½ ρ_air V_w² C_x A_w [N].
///
/// Implicit in the paper: V_w is the wind speed relative to the vessel, the force acts along the
/// wind, C_x is the drag coefficient for the frontal (transverse) projected area A_w, and both
/// are constant (independent of the wind's angle to the hull).
/// \param[in] rho_air air density [kg/m³] \param[in] wind_speed V_w [m/s]
/// \param[in] cx C_x [-] \param[in] frontal_area A_w [m²]
/// \throws kelp::invalid_argument when ρ_air is not in (0, 1e5] kg/m³
/// (`limits::max_fluid_density`), V_w or C_x is not finite, the area is negative or not finite,
/// or the force overflows.
/// \return F_wind [N], along the wind.
template <typename Scalar>
Scalar paper_wind_force(const Scalar& rho_air, const Scalar& wind_speed, const Scalar& cx,
                        const Scalar& frontal_area) {
  detail::check_paper_wind_arguments(rho_air, wind_speed, cx, frontal_area, "cx", "frontal_area");
  const Scalar f = Scalar(0.5) * rho_air * wind_speed * wind_speed * cx * frontal_area;
  check_finite(f, "paper_wind_force: the force");
  return f;
}

/// \brief The lateral twin of the paper's wind force: F = ½ ρ_air V_w² C_y A_lw [N], with the
/// lateral coefficient C_y and the lateral projected area A_lw (paper, text after eq:wind).
/// \param[in] rho_air air density [kg/m³] \param[in] wind_speed V_w [m/s]
/// \param[in] cy C_y [-] \param[in] lateral_area A_lw [m²]
/// \return F [N], across the hull.
/// \throws kelp::invalid_argument as `paper_wind_force` (naming cy and lateral_area).
template <typename Scalar>
Scalar paper_wind_force_lateral(const Scalar& rho_air, const Scalar& wind_speed, const Scalar& cy,
                                const Scalar& lateral_area) {
  detail::check_paper_wind_arguments(rho_air, wind_speed, cy, lateral_area, "cy", "lateral_area");
  const Scalar f = Scalar(0.5) * rho_air * wind_speed * wind_speed * cy * lateral_area;
  check_finite(f, "paper_wind_force_lateral: the force");
  return f;
}

/// \brief The paper's wave parameter k = (2π/Λ) A [-] (eq:wave).
///
/// Although the paper calls it "a constant representing wave characteristics", k is the
/// maximum slope k_w A of a regular wave of amplitude A and wave number k_w = 2π/Λ (the wave
/// steepness), hence dimensionless. \param[in] amplitude A [m] \param[in] wavelength Λ [m]
/// \throws kelp::invalid_argument when A is negative or not finite, Λ is not finite and > 0, or
/// k overflows (A/Λ beyond 1e307).
/// \return k [-].
template <typename Scalar>
Scalar paper_wave_parameter(const Scalar& amplitude, const Scalar& wavelength) {
  check_non_negative(amplitude, "amplitude");
  check_positive(wavelength, "wavelength");
  const Scalar k = Scalar(2.0 * kelp::pi) / wavelength * amplitude;
  check_finite(k, "paper_wave_parameter: k = 2 pi A / wavelength");
  return k;
}

/// \brief The paper's wave force (eq:wave): F_wave = ρ g B L T k [N], k = (2π/Λ) A.
///
/// Assumptions the paper leaves implicit: ρ g B L T is the weight of water displaced by a box
/// hull of beam B, length L and draft T (an upper bound of the real displacement), and
/// multiplying it by the wave slope k gives the amplitude of the horizontal Froude–Krylov force
/// of a long regular wave on a hull short compared with Λ; A is the wave AMPLITUDE (half the
/// height); the force is horizontal, along the wave direction.
/// \param[in] rho water density [kg/m³] \param[in] g gravity [m/s²] \param[in] beam B [m]
/// \param[in] length L [m] \param[in] draft T [m] \param[in] amplitude A [m]
/// \param[in] wavelength Λ [m]
/// \throws kelp::invalid_argument when ρ is not in (0, 1e5] kg/m³
/// (`limits::max_fluid_density`), g is not in (0, 1000] m/s² (`limits::max_gravity`), B, L or T
/// is negative or not finite, A or Λ is invalid (see `paper_wave_parameter`), or the force
/// overflows.
/// \return F_wave [N], the amplitude of the horizontal force along the wave's direction.
template <typename Scalar>
Scalar paper_wave_force(const Scalar& rho, const Scalar& g, const Scalar& beam,
                        const Scalar& length, const Scalar& draft, const Scalar& amplitude,
                        const Scalar& wavelength) {
  detail::check_positive_at_most(value_of(rho), limits::max_fluid_density, "rho",
                                 "finite and in (0, 1e5] kg/m^3");
  detail::check_positive_at_most(value_of(g), limits::max_gravity, "gravity",
                                 "finite and in (0, 1000] m/s^2");
  check_non_negative(beam, "beam");
  check_non_negative(length, "length");
  check_non_negative(draft, "draft");
  const Scalar f = rho * g * beam * length * draft * paper_wave_parameter(amplitude, wavelength);
  check_finite(f, "paper_wave_force: the force rho g B L T k");
  return f;
}

/// \brief A regular wave and a hull for the time-varying form of the paper's wave force.
struct PaperWave {
  double rho = kelp::seawater_density;      ///< water density [kg/m³]
  double gravity = kelp::standard_gravity;  ///< [m/s²]
  double beam = 0.0;                        ///< B [m]
  double length = 0.0;                      ///< L [m]
  double draft = 0.0;                       ///< T [m]
  double amplitude = 0.0;                   ///< A [m]
  double wavelength = 1.0;                  ///< Λ [m] (> 0)
  double direction = 0.0;                   ///< NED azimuth the wave travels towards [rad]
  double phase = 0.0;                       ///< phase at t = 0 [rad]
};

/// \brief Throws `kelp::invalid_argument` naming the bad field of `w`.
/// \throws kelp::invalid_argument when rho is not in (0, 1e5] kg/m³
/// (`limits::max_fluid_density`), gravity is not in (0, 1000] m/s² (`limits::max_gravity`), a
/// length or the amplitude is negative or not finite, the wavelength is not finite and > 0, the
/// direction or phase is not finite, or the force ρ g B L T k overflows.
/// \param w the wave and hull.
inline void validate(const PaperWave& w) {
  detail::check_positive_at_most(w.rho, limits::max_fluid_density, "rho",
                                 "finite and in (0, 1e5] kg/m^3");
  detail::check_positive_at_most(w.gravity, limits::max_gravity, "gravity",
                                 "finite and in (0, 1000] m/s^2");
  check_non_negative(w.beam, "beam");
  check_non_negative(w.length, "length");
  check_non_negative(w.draft, "draft");
  check_non_negative(w.amplitude, "amplitude");
  check_positive(w.wavelength, "wavelength");
  check_finite(w.direction, "direction");
  check_finite(w.phase, "phase");
  paper_wave_force(w.rho, w.gravity, w.beam, w.length, w.draft, w.amplitude, w.wavelength);
}

/// \brief Encounter frequency ω_e = ω − (ω²/g) U cos β [rad/s] of a deep-water wave of
/// frequency ω seen from a vessel at forward speed U, β being the angle from the vessel's heading
/// to the wave's direction of travel (β = 0 following sea, π head sea)
/// (Fossen 2021, §10.2.2, eq. for the encounter frequency).
/// \param omega wave frequency ω [rad/s] \param g gravity [m/s²] \param speed U [m/s]
/// \param beta β [rad]
/// \return ω_e [rad/s] (negative in a following sea whose waves are slower than the vessel).
/// \throws kelp::invalid_argument when ω, U or β is not finite, g is not finite and > 0, or ω_e
/// overflows.
template <typename Scalar>
Scalar encounter_frequency(const Scalar& omega, const Scalar& g, const Scalar& speed,
                           const Scalar& beta) {
  using std::cos;
  check_finite(omega, "omega");
  check_positive(g, "gravity");
  check_finite(speed, "speed");
  check_finite(beta, "beta");
  const Scalar we = omega - omega * omega / g * speed * cos(beta);
  check_finite(we, "encounter_frequency: omega_e");
  return we;
}

/// \brief The paper's wave force as a time-varying load on the ASV, body frame (X, Y, N)
/// [N, N, N·m]: F(t) = F_wave cos(ω_e t + phase), resolved by the relative wave direction
/// β = direction − ψ into X = F(t) cos β and Y = F(t) sin β; N = 0.
///
/// ω = √(2π g / Λ) from deep-water dispersion, ω_e from `encounter_frequency`. Assumes the
/// vessel's heading and speed vary slowly compared with the wave period (ω_e t is evaluated with
/// the current ψ and U).
/// \param[in] w wave and hull \param[in] t time [s] (a double for every Scalar)
/// \param[in] psi heading [rad]
/// \param[in] speed forward speed U [m/s]
/// \throws kelp::invalid_argument when `w` is invalid (see `validate(const PaperWave&)`), or t,
/// ψ or U is not finite.
/// \return (X, Y, N) [N, N, N·m], body frame.
template <typename Scalar>
Vector3<Scalar> paper_wave_load(const PaperWave& w, double t, const Scalar& psi,
                                const Scalar& speed) {
  using std::cos;
  using std::sin;
  validate(w);
  check_finite(t, "t");
  check_finite(psi, "psi");
  check_finite(speed, "speed");
  const double f =
      paper_wave_force(w.rho, w.gravity, w.beam, w.length, w.draft, w.amplitude, w.wavelength);
  const double omega = std::sqrt(2.0 * kelp::pi * w.gravity / w.wavelength);
  if constexpr (std::is_floating_point_v<Scalar>) {
    // Time is a double for every Scalar: ω_e t is formed (and reduced) in double, then cast.
    const double beta = w.direction - static_cast<double>(psi);
    const double we = encounter_frequency(omega, w.gravity, static_cast<double>(speed), beta);
    const double ft = f * std::cos(std::remainder(we * t + w.phase, 2.0 * kelp::pi));
    return Vector3<Scalar>(static_cast<Scalar>(ft * std::cos(beta)),
                           static_cast<Scalar>(ft * std::sin(beta)), Scalar(0));
  } else {
    const Scalar beta = Scalar(w.direction) - psi;
    const Scalar we = encounter_frequency(Scalar(omega), Scalar(w.gravity), speed, beta);
    const Scalar ft = Scalar(f) * cos(we * Scalar(t) + Scalar(w.phase));
    return Vector3<Scalar>(ft * cos(beta), ft * sin(beta), Scalar(0));
  }
}

/// \brief First-order wave force on a small submerged body, body frame [N]:
/// \f$ \mathbf F = (\rho \nabla\, \mathbf I + \mathbf M_A)\, \mathbf R^T \dot{\mathbf u}_f \f$
/// — the Froude–Krylov (undisturbed-pressure) force ρ∇ u̇_f plus the added-mass (diffraction)
/// force M_A u̇_f, i.e. the inertia term of Morison's equation with C_M = 1 + C_A
/// (DNV-RP-C205 (2010) §6.2; Faltinsen 1990 ch. 3).
///
/// Assumptions: the body is small compared with the wavelength (D/Λ ≲ 0.2), so the fluid
/// acceleration u̇_f is uniform over it and evaluated at its reference point; the moment of this
/// force is neglected; drag is left to the vehicle's damping on the velocity relative to the water.
/// The added mass multiplies the known FLUID acceleration (an input from the environment), not the
/// body's own acceleration, which stays in the vehicle's mass matrix.
/// \param[in] rho water density [kg/m³] \param[in] displaced_volume ∇ [m³]
/// \param[in] added_mass translational added mass: a 3×3 matrix or a 3-vector of its diagonal
/// (positive magnitudes −X_u̇, −Y_v̇, −Z_ẇ) [kg]
/// \param[in] R_nb rotation body → NED \param[in] fluid_acceleration_ned u̇_f NED [m/s²]
/// \throws kelp::invalid_argument when ρ is not in (0, 1e5] kg/m³ (`limits::max_fluid_density`),
/// ∇ is negative or not finite, added_mass is not 3×3 or 3×1, R_nb is not 3×3 or the
/// acceleration has not 3 entries, or an entry of them is not finite.
/// \return F [N], body frame.
template <typename Scalar, typename DerivedA, typename DerivedR, typename DerivedF>
Vector3<Scalar> small_body_wave_force(const Scalar& rho, const Scalar& displaced_volume,
                                      const Eigen::MatrixBase<DerivedA>& added_mass,
                                      const Eigen::MatrixBase<DerivedR>& R_nb,
                                      const Eigen::MatrixBase<DerivedF>& fluid_acceleration_ned) {
  detail::check_positive_at_most(value_of(rho), limits::max_fluid_density, "rho",
                                 "finite and in (0, 1e5] kg/m^3");
  check_non_negative(displaced_volume, "displaced_volume");
  KELP_CHECK(added_mass.rows() == 3 && (added_mass.cols() == 3 || added_mass.cols() == 1),
             "added_mass must be 3 x 3 or 3 x 1");
  KELP_CHECK(R_nb.rows() == 3 && R_nb.cols() == 3, "R_nb must be 3 x 3");
  KELP_CHECK(fluid_acceleration_ned.size() == 3, "fluid_acceleration_ned must have 3 entries");
  check_all_finite(added_mass, "added_mass");
  check_all_finite(R_nb, "R_nb");
  check_all_finite(fluid_acceleration_ned, "fluid_acceleration_ned");
  const Vector3<Scalar> a_b = R_nb.transpose() * fluid_acceleration_ned;
  Vector3<Scalar> f = froude_krylov_force(rho, displaced_volume, a_b);
  if constexpr (DerivedA::ColsAtCompileTime == 1) {
    f += added_mass.cwiseProduct(a_b);
  } else {
    f += added_mass * a_b;
  }
  return f;
}

/// \brief Linear hydrostatics of a surface vessel about its calm-water equilibrium.
struct SurfaceHydrostatics {
  double rho = kelp::seawater_density;      ///< water density [kg/m³]
  double gravity = kelp::standard_gravity;  ///< [m/s²]
  double waterplane_area = 0.0;             ///< A_wp [m²]
  double displaced_volume = 0.0;            ///< ∇ [m³]
  double gm_transverse = 0.0;               ///< GM_T [m]
  double gm_longitudinal = 0.0;             ///< GM_L [m]
};

/// \brief Throws `kelp::invalid_argument` naming the bad field of `h`.
/// \throws kelp::invalid_argument when rho is not in (0, 1e5] kg/m³
/// (`limits::max_fluid_density`), gravity is not in (0, 1000] m/s² (`limits::max_gravity`), the
/// waterplane area or displaced volume is negative or not finite, a metacentric height is not
/// finite, or a stiffness ρ g A_wp, ρ g ∇ GM overflows.
/// \param h the hydrostatics.
inline void validate(const SurfaceHydrostatics& h) {
  detail::check_positive_at_most(h.rho, limits::max_fluid_density, "rho",
                                 "finite and in (0, 1e5] kg/m^3");
  detail::check_positive_at_most(h.gravity, limits::max_gravity, "gravity",
                                 "finite and in (0, 1000] m/s^2");
  check_non_negative(h.waterplane_area, "waterplane_area");
  check_non_negative(h.displaced_volume, "displaced_volume");
  check_finite(h.gm_transverse, "gm_transverse");
  check_finite(h.gm_longitudinal, "gm_longitudinal");
  const double rg = h.rho * h.gravity;
  KELP_CHECK(std::isfinite(rg * h.waterplane_area) &&
                 std::isfinite(rg * h.displaced_volume * h.gm_transverse) &&
                 std::isfinite(rg * h.displaced_volume * h.gm_longitudinal),
             "SurfaceHydrostatics: a stiffness rho g A_wp or rho g V GM overflows");
}

/// \brief Surface-relative attitude of the free surface under a vessel: the roll φ_s and pitch
/// θ_s [rad] a hull lying flat on the local surface would have, from the surface slope
/// (∂ζ/∂x, ∂ζ/∂y) (NED, per metre north/east) and the heading ψ:
/// θ_s = atan(s_fwd), φ_s = −atan(s_stbd), with s_fwd, s_stbd the slopes along body x and y.
/// (A surface rising ahead lifts the bow: θ > 0; rising to starboard lifts starboard: φ < 0.)
/// \param slope_north ∂ζ/∂x [-] \param slope_east ∂ζ/∂y [-] \param psi heading ψ [rad]
/// \return (φ_s, θ_s) [rad]; no check, no throw.
template <typename Scalar>
Eigen::Matrix<Scalar, 2, 1> surface_attitude(const Scalar& slope_north, const Scalar& slope_east,
                                             const Scalar& psi) {
  using std::atan;
  using std::cos;
  using std::sin;
  const Scalar c = cos(psi), s = sin(psi);
  const Scalar s_fwd = slope_north * c + slope_east * s;
  const Scalar s_stbd = -slope_north * s + slope_east * c;
  return Eigen::Matrix<Scalar, 2, 1>(-atan(s_stbd), atan(s_fwd));
}

/// \brief Linear restoring that follows the local free surface, body frame [N, N·m]:
/// \f$ \boldsymbol\tau = -\mathbf G (\boldsymbol\eta - \boldsymbol\eta_s) \f$ with
/// G = diag(0, 0, ρgA_wp, ρg∇GM_T, ρg∇GM_L, 0) (Fossen 2021 §4.2, linear restoring of a
/// surface vessel) and the surface state η_s = (·, ·, −ζ, φ_s, θ_s, ·).
///
/// Assumptions: small motions about the calm-water equilibrium (heave z measured from it,
/// positive down), waves long compared with the hull (the surface under it is a plane at the
/// local elevation ζ and slope, evaluated at the hull's reference point), and small angles (body
/// and NED vertical treated alike).
/// \param[in] h hydrostatics \param[in] heave z of the vessel from its calm equilibrium, NED [m]
/// \param[in] phi roll [rad] \param[in] theta pitch [rad] \param[in] psi heading [rad]
/// \param[in] zeta local elevation ζ [m] (up) \param[in] slope_north ∂ζ/∂x [-]
/// \param[in] slope_east ∂ζ/∂y [-]
/// \throws kelp::invalid_argument when `h` is invalid (see `validate(const
/// SurfaceHydrostatics&)`); non-finite motions give non-finite loads (they come from a state the
/// integrators check).
/// \return τ [N, N·m], body frame.
template <typename Scalar>
Vector6<Scalar> surface_following_restoring(const SurfaceHydrostatics& h, const Scalar& heave,
                                            const Scalar& phi, const Scalar& theta,
                                            const Scalar& psi, const Scalar& zeta,
                                            const Scalar& slope_north, const Scalar& slope_east) {
  validate(h);
  const Eigen::Matrix<Scalar, 2, 1> att = surface_attitude(slope_north, slope_east, psi);
  const double rg = h.rho * h.gravity;
  Vector6<Scalar> tau = Vector6<Scalar>::Zero();
  tau(2) = -Scalar(rg * h.waterplane_area) * (heave + zeta);
  tau(3) = -Scalar(rg * h.displaced_volume * h.gm_transverse) * (phi - att(0));
  tau(4) = -Scalar(rg * h.displaced_volume * h.gm_longitudinal) * (theta - att(1));
  return tau;
}

/// \brief The wave part of `surface_following_restoring`: its value minus the calm-water
/// restoring −Gη, i.e. G η_s = (0, 0, −ρgA_wp ζ, ρg∇GM_T φ_s, ρg∇GM_L θ_s, 0) [N, N·m]. Add it
/// to a vehicle model that already has its own (calm-water) restoring g(η). Zero in a calm sea.
/// \throws kelp::invalid_argument when `h` is invalid (see `validate(const
/// SurfaceHydrostatics&)`).
/// \param h hydrostatics \param psi heading [rad] \param zeta local elevation ζ [m] (up)
/// \param slope_north ∂ζ/∂x [-] \param slope_east ∂ζ/∂y [-]
/// \return G η_s [N, N·m], body frame.
template <typename Scalar>
Vector6<Scalar> wave_restoring(const SurfaceHydrostatics& h, const Scalar& psi, const Scalar& zeta,
                               const Scalar& slope_north, const Scalar& slope_east) {
  validate(h);
  const Eigen::Matrix<Scalar, 2, 1> att = surface_attitude(slope_north, slope_east, psi);
  const double rg = h.rho * h.gravity;
  Vector6<Scalar> tau = Vector6<Scalar>::Zero();
  tau(2) = -Scalar(rg * h.waterplane_area) * zeta;
  tau(3) = Scalar(rg * h.displaced_volume * h.gm_transverse) * att(0);
  tau(4) = Scalar(rg * h.displaced_volume * h.gm_longitudinal) * att(1);
  return tau;
}

/// \brief Checks a surface vessel's hydrostatics (`rho`, `gravity`) against the environment.
/// \param h the hydrostatics. \param env the environment the vessel is in.
/// \throws kelp::invalid_argument naming both values when they differ.
template <typename Scalar>
void check_same_water(const SurfaceHydrostatics& h, const Environment<Scalar>& env) {
  check_same_water(h.rho, h.gravity, env, "SurfaceHydrostatics");
}

/// \brief Checks the paper's wave-load parameters (`rho`, `gravity`) against the environment.
/// \param w the wave and hull. \param env the environment the vessel is in.
/// \throws kelp::invalid_argument naming both values when they differ.
template <typename Scalar>
void check_same_water(const PaperWave& w, const Environment<Scalar>& env) {
  check_same_water(w.rho, w.gravity, env, "PaperWave");
}

}  // namespace environment
}  // namespace kelp
