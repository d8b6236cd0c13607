/// \file
/// \brief Fossen 6-DOF vehicle model: parameters, the model built from them once (mass matrix and
/// its LDLT factorisation) and the allocation-free forward dynamics.
///
/// Equation of motion with an irrotational ocean current (Fossen 2021, Handbook of Marine
/// Craft Hydrodynamics and Motion Control, 2nd ed., §10.3):
/// \f[ M_{RB}\dot\nu + C_{RB}(\nu)\nu + M_A\dot\nu_r + C_A(\nu_r)\nu_r + D(\nu_r)\nu_r + g(\eta)
///     = \tau + \tau_{env}, \f]
/// with ν_r = ν − ν_c, ν_c = (Rᵀ v_c^n, 0) and, for a current constant in NED,
/// ν̇_c = (ν_{c,1} × ν₂, 0) (the body-frame rate of a fixed NED vector). Hence
/// \f[ \dot\nu = M^{-1}\big(\tau + \tau_{env} - C_{RB}(\nu)\nu - C_A(\nu_r)\nu_r - D(\nu_r)\nu_r
///     - g(\eta) + M_A \dot\nu_c\big), \quad M = M_{RB} + M_A, \f]
/// where the last term is the irrotational-current correction. M is factored once (LDLT) when the
/// model is built and M⁻¹ is taken from that factorisation at the same time; a step then costs one
/// 6×6 matrix-vector product, with no factorisation, no inverse and no allocation per step.
/// Exception: a `submerged_free_surface` vehicle breaking the surface (submerged fraction φ < 1)
/// has M = M_RB + φ M_A, factored per evaluation (fixed size, no allocation); see
/// forward_dynamics().
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/environment/limits.hpp"
#include "kelp/environment/wave_loads.hpp"
#include "kelp/environment/wind.hpp"
#include "kelp/vehicle/added_mass.hpp"
#include "kelp/vehicle/coriolis.hpp"
#include "kelp/vehicle/damping.hpp"
#include "kelp/vehicle/restoring.hpp"
#include "kelp/vehicle/rigid_body.hpp"
#include "kelp/vehicle/state.hpp"
#include "kelp/vehicle/surroundings.hpp"

namespace kelp::vehicle {

/// \brief Which hydrostatic model gives g(η).
enum class Hydrostatics {
  /// Always fully submerged: constant weight and buoyancy, restoring_force() (rotation-matrix
  /// form), whatever the depth (no free surface).
  submerged,
  /// Floating at the surface: heave stiffness and metacentric heights relative to the local wave
  /// surface, bounded when the hull emerges or submerges (restoring_force_surface_following(),
  /// with `hull_height` the hull depth D; D = 0 leaves the heave force unbounded), plus wind loads
  /// from `wind_areas` and `wind_coefficients`.
  surface,
  /// Submerged vehicle that can reach the free surface: buoyancy B φ with φ the submerged
  /// fraction of a box hull of height `hull_height` about the CB
  /// (restoring_force_free_surface()); identical to `submerged` when fully under water.
  submerged_free_surface
};

/// \brief Constant parameters of a rigid marine vehicle (Fossen 2021 notation, SI units, body axes
/// x fwd / y stbd / z down about the body origin CO). Added mass and damping are positive
/// magnitudes; the equations carry the signs.
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
struct VehicleParameters {
  /// m [kg], > 0.
  Scalar mass = Scalar(0);
  /// I_g [kg m²]: inertia tensor about the CG in body axes, symmetric positive definite.
  Matrix3<Scalar> inertia = Matrix3<Scalar>::Zero();
  /// r_g [m]: centre of gravity relative to the CO, body axes.
  Vector3<Scalar> r_g = Vector3<Scalar>::Zero();
  /// r_b [m]: centre of buoyancy relative to the CO, body axes (submerged model).
  Vector3<Scalar> r_b = Vector3<Scalar>::Zero();
  /// ∇ [m³]: displaced volume; B = ρ g ∇ (submerged) or the floating volume (surface).
  Scalar displaced_volume = Scalar(0);
  /// ρ [kg/m³]: water density, in (0, 1e5] (`environment::limits::max_fluid_density`).
  Scalar density = Scalar(seawater_density);
  /// g [m/s²]: gravitational acceleration, in (0, 1000] (`environment::limits::max_gravity`).
  Scalar gravity = Scalar(standard_gravity);
  /// M_A [kg, kg m, kg m²]: added mass, symmetric positive semi-definite (−X_u̇ … magnitudes).
  Matrix6<Scalar> added_mass = Matrix6<Scalar>::Zero();
  /// Linear and quadratic damping magnitudes.
  DampingParameters<Scalar> damping;
  /// Restoring model.
  Hydrostatics hydrostatics = Hydrostatics::submerged;
  /// A_wp [m²]: waterplane area (surface model only).
  Scalar waterplane_area = Scalar(0);
  /// GM_T [m]: transverse metacentric height (surface model only).
  Scalar gm_transverse = Scalar(0);
  /// GM_L [m]: longitudinal metacentric height (surface model only).
  Scalar gm_longitudinal = Scalar(0);
  /// Hull height [m]: for `submerged_free_surface` the vertical extent h of the box hull about the
  /// CB (> 0); for `surface` the hull depth D from keel to deck (0: heave force unbounded; else
  /// > the draft ∇/A_wp). Unused by `submerged`.
  Scalar hull_height = Scalar(0);
  /// Projected areas above water for the wind loads (surface model only; zero areas: no wind load).
  environment::WindAreas wind_areas;
  /// Wind-load coefficients c_x, c_y, c_n (surface model only), Fossen 2021 §10.1.1.
  environment::ConstantWindCoefficients wind_coefficients;

  /// \brief W = m g [N].
  /// \return m g [N].
  Scalar weight() const { return mass * gravity; }
  /// \brief B = ρ g ∇ [N].
  /// \return ρ g ∇ [N].
  Scalar buoyancy() const { return density * gravity * displaced_volume; }

  /// \brief The same parameters in another scalar type (e.g. double → ceres::Jet).
  /// \tparam T the new scalar. \return the converted parameters.
  template <typename T>
  VehicleParameters<T> cast() const {
    VehicleParameters<T> o;
    o.mass = T(mass);
    o.inertia = inertia.template cast<T>();
    o.r_g = r_g.template cast<T>();
    o.r_b = r_b.template cast<T>();
    o.displaced_volume = T(displaced_volume);
    o.density = T(density);
    o.gravity = T(gravity);
    o.added_mass = added_mass.template cast<T>();
    o.damping = damping.template cast<T>();
    o.hydrostatics = hydrostatics;
    o.waterplane_area = T(waterplane_area);
    o.gm_transverse = T(gm_transverse);
    o.gm_longitudinal = T(gm_longitudinal);
    o.hull_height = T(hull_height);
    o.wind_areas = wind_areas;
    o.wind_coefficients = wind_coefficients;
    return o;
  }
};

namespace detail {
/// Throws `kelp::invalid_argument` naming `density` or `gravity` and the value unless
/// 0 < ρ ≤ 1e5 kg/m³ and 0 < g ≤ 1000 m/s² (`environment::limits`: far beyond any water or
/// planet; beyond them buoyancy and accelerations overflow a step).
template <typename Scalar>
void check_water(const Scalar& density, const Scalar& gravity) {
  environment::detail::check_positive_at_most(value_of(density),
                                              environment::limits::max_fluid_density, "density",
                                              "finite and in (0, 1e5] kg/m^3");
  environment::detail::check_positive_at_most(value_of(gravity), environment::limits::max_gravity,
                                              "gravity", "finite and in (0, 1000] m/s^2");
}
}  // namespace detail

/// \brief Throws kelp::invalid_argument naming the first offending field of `p` (`mass`,
/// `inertia`, `r_g`, `r_b`, `displaced_volume`, `density`, `gravity`, `added_mass`,
/// `linear_damping`, `quadratic_damping`, `waterplane_area`, `gm_transverse`, `gm_longitudinal`,
/// `hull_height`, `wind_areas`, `wind_coefficients`).
/// `VehicleModel`'s constructor calls it.
/// \throws kelp::invalid_argument as above; besides finiteness and signs, `density` must be at
/// most 1e5 kg/m³ and `gravity` at most 1000 m/s² (see `environment::limits`; the message gives
/// the value), and the weight m g and buoyancy ρ g ∇ must be finite.
/// \tparam Scalar double, float or ceres::Jet.
/// \param p The parameters to check.
template <typename Scalar>
void validate(const VehicleParameters<Scalar>& p) {
  check_positive(p.mass, "mass");
  check_symmetric_definite(p.inertia, "inertia", false);
  check_all_finite(p.r_g, "r_g");
  check_all_finite(p.r_b, "r_b");
  check_non_negative(p.displaced_volume, "displaced_volume");
  detail::check_water(p.density, p.gravity);
  check_finite(p.weight(), "weight m g");
  check_finite(p.buoyancy(), "buoyancy rho g displaced_volume");
  check_added_mass(p.added_mass);
  validate(p.damping);
  if (p.hydrostatics == Hydrostatics::surface) {
    check_positive(p.waterplane_area, "waterplane_area");
    check_positive(p.displaced_volume, "displaced_volume");
    check_finite(p.gm_transverse, "gm_transverse");
    check_finite(p.gm_longitudinal, "gm_longitudinal");
    check_non_negative(p.hull_height, "hull_height");
    KELP_CHECK(value_of(p.hull_height) == 0.0 ||
                   value_of(p.hull_height) > value_of(p.displaced_volume / p.waterplane_area),
               "hull_height must be 0 or greater than the draft displaced_volume/waterplane_area");
    check_non_negative(p.wind_areas.frontal_area, "wind_areas.frontal_area");
    check_non_negative(p.wind_areas.lateral_area, "wind_areas.lateral_area");
    check_non_negative(p.wind_areas.length_overall, "wind_areas.length_overall");
    check_finite(p.wind_coefficients.cx, "wind_coefficients.cx");
    check_finite(p.wind_coefficients.cy, "wind_coefficients.cy");
    check_finite(p.wind_coefficients.cn, "wind_coefficients.cn");
  }
  if (p.hydrostatics == Hydrostatics::submerged_free_surface)
    check_positive(p.hull_height, "hull_height");
}

/// \brief A vehicle model built once from VehicleParameters: validated parameters, M_RB, M_A
/// (symmetrised), M = M_RB + M_A and its LDLT factorisation. Immutable after construction, so one
/// model can be shared by many simulations (each with its own VehicleWorkspace).
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
class VehicleModel {
 public:
  /// \brief Validates `parameters` and factors the mass matrix.
  /// \param parameters The vehicle's parameters (copied).
  /// \throws kelp::invalid_argument naming the offending field, or when a derived quantity
  /// (M_RB, M, M⁻¹, the surface vessel's stiffnesses ρ g A_wp and ρ g ∇ GM) is not finite, e.g.
  /// for a mass or inertia near the largest double.
  explicit VehicleModel(const VehicleParameters<Scalar>& parameters);

  /// \brief The validated parameters.
  /// \return The parameters, as given.
  const VehicleParameters<Scalar>& parameters() const { return parameters_; }
  /// \brief M_RB about the CO [kg, kg m, kg m²].
  /// \return The 6×6 rigid-body mass matrix, body axes.
  const Matrix6<Scalar>& rigid_body_mass() const { return rigid_body_mass_; }
  /// \brief M_A (symmetric part of the given matrix).
  /// \return ½ (M_A + M_Aᵀ) [kg, kg m, kg m²], body axes.
  const Matrix6<Scalar>& added_mass() const { return added_mass_; }
  /// \brief M = M_RB + M_A (fully submerged; a `submerged_free_surface` vehicle at the surface has
  /// M_RB + φ M_A, see forward_dynamics()).
  /// \return M [kg, kg m, kg m²], symmetric positive definite.
  const Matrix6<Scalar>& mass_matrix() const { return mass_; }
  /// \brief LDLT factorisation of M, computed once.
  /// \return The factorisation of mass_matrix().
  const Eigen::LDLT<Matrix6<Scalar>>& mass_ldlt() const { return ldlt_; }
  /// \brief M⁻¹, obtained once from the LDLT factorisation at construction.
  /// \return M⁻¹.
  const Matrix6<Scalar>& mass_inverse() const { return mass_inverse_; }
  /// \brief W = m g [N].
  /// \return W [N].
  const Scalar& weight() const { return weight_; }
  /// \brief B = ρ g ∇ [N] (submerged model).
  /// \return B [N] (fully submerged; the free-surface models scale it).
  const Scalar& buoyancy() const { return buoyancy_; }

  /// \brief Restoring vector g(η) [N, N m], body axes, in calm water (flat surface at z = 0).
  /// \param[in] state vehicle state. \param[in] R its rotation matrix body → NED.
  /// \return g(η) [N, N m], body axes.
  template <typename DerivedR>
  Vector6<Scalar> restoring(const VehicleState<Scalar>& state,
                            const Eigen::MatrixBase<DerivedR>& R) const {
    return restoring(state, R, Scalar(0), Eigen::Matrix<Scalar, 2, 1>::Zero());
  }

  /// \brief Restoring vector g(η) [N, N m], body axes, relative to the local free surface, by the
  /// model's `Hydrostatics`: restoring_force() (`submerged`), restoring_force_free_surface()
  /// (`submerged_free_surface`) or restoring_force_surface_following() (`surface`).
  /// \param[in] state vehicle state \param[in] R its rotation body → NED
  /// \param[in] zeta surface elevation ζ at the CO's (x, y) [m], up
  /// \param[in] slope (∂ζ/∂x, ∂ζ/∂y) [-] (read by `surface` only)
  /// \param[out] fraction submerged fraction φ (`submerged_free_surface`; 1 otherwise), if not null
  /// \return g [N, N m], body axes.
  template <typename DerivedR, typename DerivedS>
  Vector6<Scalar> restoring(const VehicleState<Scalar>& state, const Eigen::MatrixBase<DerivedR>& R,
                            const Scalar& zeta, const Eigen::MatrixBase<DerivedS>& slope,
                            Scalar* fraction = nullptr) const {
    const VehicleParameters<Scalar>& p = parameters_;
    if (fraction != nullptr) *fraction = Scalar(1);
    switch (p.hydrostatics) {
      case Hydrostatics::surface:
        return restoring_force_surface_following(
            p.density, p.gravity, p.displaced_volume, p.waterplane_area, p.gm_transverse,
            p.gm_longitudinal, p.hull_height, state.position(2), zeta, slope, R);
      case Hydrostatics::submerged_free_surface:
        return restoring_force_free_surface(weight_, buoyancy_, p.r_g, p.r_b, p.hull_height,
                                            state.position(2), zeta, R, fraction);
      case Hydrostatics::submerged:
        break;
    }
    return restoring_force(weight_, buoyancy_, p.r_g, p.r_b, R);
  }

  /// \brief Submerged fraction φ ∈ [0, 1] of the state under a surface at elevation ζ [m]
  /// (`submerged_free_surface`: submerged_fraction() of the box hull about the CB; 1 for the other
  /// models). Every fluid term of a `submerged_free_surface` vehicle scales with it (see
  /// forward_dynamics()).
  /// \param state Vehicle state (its CO depth and attitude place the CB).
  /// \param zeta Surface elevation ζ at the vehicle [m], up.
  /// \return φ [-].
  Scalar submerged_fraction(const VehicleState<Scalar>& state, const Scalar& zeta) const {
    if (parameters_.hydrostatics != Hydrostatics::submerged_free_surface) return Scalar(1);
    const Scalar z_cb =
        state.position(2) + state.attitude.toRotationMatrix().row(2).dot(parameters_.r_b);
    return vehicle::submerged_fraction(z_cb, zeta, parameters_.hull_height);
  }

  /// \brief Hydrostatic potential energy U [J] of which restoring() is the gradient for a fixed
  /// surface (ζ, slope): see restoring_potential_free_surface() and
  /// restoring_potential_surface_following(); −W z_CG + B z_CB for `submerged`.
  /// \param state Vehicle state.
  /// \param zeta Surface elevation ζ at the CO's (x, y) [m], up.
  /// \param slope (∂ζ/∂x, ∂ζ/∂y) [-] (read by `surface` only).
  /// \return U [J].
  template <typename DerivedS>
  Scalar restoring_potential(const VehicleState<Scalar>& state, const Scalar& zeta,
                             const Eigen::MatrixBase<DerivedS>& slope) const {
    const VehicleParameters<Scalar>& p = parameters_;
    const Matrix3<Scalar> R = state.attitude.toRotationMatrix();
    switch (p.hydrostatics) {
      case Hydrostatics::surface:
        return restoring_potential_surface_following(
            p.density, p.gravity, p.displaced_volume, p.waterplane_area, p.gm_transverse,
            p.gm_longitudinal, p.hull_height, state.position(2), zeta, slope, R);
      case Hydrostatics::submerged_free_surface:
        return restoring_potential_free_surface(weight_, buoyancy_, p.r_g, p.r_b, p.hull_height,
                                                state.position(2), zeta, R);
      case Hydrostatics::submerged:
        break;
    }
    return -weight_ * (state.position(2) + R.row(2).dot(p.r_g)) +
           buoyancy_ * (state.position(2) + R.row(2).dot(p.r_b));
  }

 private:
  VehicleParameters<Scalar> parameters_;
  Matrix6<Scalar> rigid_body_mass_;
  Matrix6<Scalar> added_mass_;
  Matrix6<Scalar> mass_;
  Eigen::LDLT<Matrix6<Scalar>> ldlt_;
  Matrix6<Scalar> mass_inverse_;
  Scalar weight_;
  Scalar buoyancy_;
};

// Defined out of the class, so not inline: a program that links an explicit instantiation
// (KELP_VEHICLE_INSTANCES, kelp/vehicle/instances.hpp) and declares it extern does not compile
// the validation and the factorisation again.
template <typename Scalar>
VehicleModel<Scalar>::VehicleModel(const VehicleParameters<Scalar>& parameters)
    : parameters_((validate(parameters), parameters)) {
  const Scalar h(0.5);
  rigid_body_mass_ = rigid_body_mass_matrix(parameters_.mass, parameters_.inertia, parameters_.r_g);
  added_mass_ = h * (parameters_.added_mass + parameters_.added_mass.transpose());
  mass_ = rigid_body_mass_ + added_mass_;
  ldlt_.compute(mass_);
  // M_RB is positive definite and M_A positive semi-definite, so M is positive definite.
  KELP_CHECK(ldlt_.info() == Eigen::Success && ldlt_.isPositive(),
             "mass matrix M = M_RB + M_A must be positive definite");
  // M⁻¹ formed once here from the factorisation (never per step): for a 6×6 system one
  // matrix-vector product per evaluation is several times faster than two triangular solves.
  // Column by column: a vector right-hand side keeps Eigen's blocked matrix kernels (GEBP/TRSM),
  // heavy to compile, out of every translation unit that builds a model.
  for (int j = 0; j < 6; ++j) mass_inverse_.col(j) = ldlt_.solve(Vector6<Scalar>::Unit(j));
  check_all_finite(mass_, "mass matrix M = M_RB + M_A (mass, inertia, r_g, added_mass)");
  check_all_finite(mass_inverse_, "inverse mass matrix (mass, inertia, r_g, added_mass)");
  weight_ = parameters_.weight();
  buoyancy_ = parameters_.buoyancy();
  if (parameters_.hydrostatics == Hydrostatics::surface) {
    const Scalar rho_g = parameters_.density * parameters_.gravity;
    check_finite(rho_g * parameters_.waterplane_area, "heave stiffness rho g waterplane_area");
    check_finite(rho_g * parameters_.displaced_volume * parameters_.gm_transverse,
                 "roll stiffness rho g displaced_volume gm_transverse");
    check_finite(rho_g * parameters_.displaced_volume * parameters_.gm_longitudinal,
                 "pitch stiffness rho g displaced_volume gm_longitudinal");
  }
}

/// \brief Mutable per-simulation buffers of the forward dynamics. After each call they hold the
/// terms of the last evaluation (useful to log loads or to couple a tether in `system/`).
///
/// After a step they hold the terms of the step's LAST EVALUATION, not of the committed state:
/// - `step_rk4` / `step_rk4_with`: the fourth stage, evaluated at the predictor
///   x₄ = x_k + dt·k₃ (with the stage-4 wrench), which differs from x_{k+1} by O(dt²);
/// - `step_symplectic_euler`: the state at the START of the step, x_k.
///
/// The workspace is scratch and outputs only (nothing in it feeds the next step). To log the
/// terms of the committed state, call `forward_dynamics(model, ws, state, tau, tau_ext,
/// current)` after the step: one evaluation, paid only by callers who need it (recomputing them
/// inside every RK4 step would cost a fifth evaluation, +25 %, and for `step_rk4_with` a fifth
/// call of the user's wrench at a time that belongs to the next step).
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
struct VehicleWorkspace {
  /// R: rotation body → NED of the last evaluated state.
  Matrix3<Scalar> rotation = Matrix3<Scalar>::Identity();
  /// ν_c = (Rᵀ v_c^n, 0): current velocity in body axes [m/s].
  Vector6<Scalar> nu_c = Vector6<Scalar>::Zero();
  /// ν_r = ν − ν_c [m/s, rad/s].
  Vector6<Scalar> nu_r = Vector6<Scalar>::Zero();
  /// ν̇_c = (ν_{c,1} × ω, 0) [m/s²].
  Vector6<Scalar> nu_c_dot = Vector6<Scalar>::Zero();
  /// C_RB(ν) ν [N, N m].
  Vector6<Scalar> coriolis_rigid_body = Vector6<Scalar>::Zero();
  /// C_A(ν_r) ν_r [N, N m].
  Vector6<Scalar> coriolis_added_mass = Vector6<Scalar>::Zero();
  /// D(ν_r) ν_r [N, N m].
  Vector6<Scalar> damping = Vector6<Scalar>::Zero();
  /// g(η) [N, N m].
  Vector6<Scalar> restoring = Vector6<Scalar>::Zero();
  /// Froude–Krylov force of the accelerating water, (ρ ∇ φ Rᵀ a_w, 0) [N] (see forward_dynamics).
  Vector6<Scalar> froude_krylov = Vector6<Scalar>::Zero();
  /// Wind load (X, Y, 0, 0, 0, N) [N, N m] (surface vessels).
  Vector6<Scalar> wind = Vector6<Scalar>::Zero();
  /// Submerged fraction φ of the last evaluation (1 unless `submerged_free_surface`).
  Scalar submerged_fraction = Scalar(1);
  /// Force of the changing added mass of a vehicle crossing the surface,
  /// −φ̇ M_A ν_r + ½ (ν_rᵀ M_A ν_r) ∇φ [N, N m] (zero when φ is 0 or 1; see forward_dynamics).
  Vector6<Scalar> added_mass_change = Vector6<Scalar>::Zero();
  /// Right-hand side M ν̇ [N, N m].
  Vector6<Scalar> rhs = Vector6<Scalar>::Zero();
  /// ν̇ [m/s², rad/s²].
  Vector6<Scalar> nu_dot = Vector6<Scalar>::Zero();
};

namespace detail {

/// forward_dynamics() without the checks of the values, for the evaluations inside a step (every
/// stage of the vehicle steps and of the system's step): there a NaN wrench, state or water
/// velocity gives a NaN ν̇, which the step reports as numerical_error with the state unchanged
/// (its documented contract), instead of an invalid_argument from the middle of the step. The
/// step checks what it takes from its caller once, up front. Sizes are still checked (free for
/// fixed-size vectors).
template <typename Scalar, typename D1, typename D2>
Vector6<Scalar> forward_dynamics_unchecked(const VehicleModel<Scalar>& model,
                                           VehicleWorkspace<Scalar>& ws,
                                           const VehicleState<Scalar>& state,
                                           const Eigen::MatrixBase<D1>& tau,
                                           const Eigen::MatrixBase<D2>& tau_ext,
                                           const Surroundings<Scalar>& s) {
  KELP_CHECK(tau.size() == 6 && tau_ext.size() == 6,
             "forward_dynamics: tau and tau_ext must have 6 entries");
  const VehicleParameters<Scalar>& p = model.parameters();
  ws.rotation = state.attitude.toRotationMatrix();
  const Vector3<Scalar> vw = ws.rotation.transpose() * s.water_velocity;
  const Vector3<Scalar> aw = ws.rotation.transpose() * s.water_acceleration;
  ws.nu_c.template head<3>() = vw;
  ws.nu_c.template tail<3>().setZero();
  ws.nu_r = state.nu - ws.nu_c;
  ws.nu_c_dot.template head<3>() = vw.cross(Vector3<Scalar>(state.nu.template tail<3>())) + aw;
  ws.nu_c_dot.template tail<3>().setZero();
  ws.coriolis_rigid_body = coriolis_force(model.rigid_body_mass(), state.nu);
  ws.coriolis_added_mass = coriolis_force(model.added_mass(), ws.nu_r);
  ws.damping = damping_force(p.damping, ws.nu_r);
  ws.restoring = model.restoring(state, ws.rotation, s.surface_elevation, s.surface_slope,
                                 &ws.submerged_fraction);
  ws.froude_krylov.setZero();
  ws.wind.setZero();
  if (p.hydrostatics == Hydrostatics::surface) {
    const Vector3<Scalar> ah(s.water_acceleration(0), s.water_acceleration(1), Scalar(0));
    ws.froude_krylov.template head<3>() = environment::froude_krylov_force(
        p.density, p.displaced_volume, Vector3<Scalar>(ws.rotation.transpose() * ah));
    if (p.wind_areas.frontal_area > 0.0 || p.wind_areas.lateral_area > 0.0) {
      using std::atan2;
      const Scalar psi = atan2(ws.rotation(1, 0), ws.rotation(0, 0));
      const Vector3<Scalar> w =
          environment::detail::wind_load_unchecked(p.wind_coefficients, p.wind_areas, s.air_density,
                                                   s.wind_velocity, psi, state.nu(0), state.nu(1));
      ws.wind(0) = w(0);
      ws.wind(1) = w(1);
      ws.wind(5) = w(2);
    }
  } else {
    ws.froude_krylov.template head<3>() = environment::froude_krylov_force(
        p.density, Scalar(p.displaced_volume * ws.submerged_fraction), aw);
  }
  ws.added_mass_change.setZero();
  const Scalar& phi = ws.submerged_fraction;
  // Fast path: fully submerged (or not a submerged-fraction model): M is the factored M_RB + M_A.
  if (p.hydrostatics != Hydrostatics::submerged_free_surface || !(value_of(phi) < 1.0)) {
    ws.rhs = Vector6<Scalar>(tau) + Vector6<Scalar>(tau_ext) - ws.coriolis_rigid_body -
             ws.coriolis_added_mass - ws.damping - ws.restoring + model.added_mass() * ws.nu_c_dot +
             ws.froude_krylov + ws.wind;
    ws.nu_dot.noalias() = model.mass_inverse() * ws.rhs;
    return ws.nu_dot;
  }
  // Breaking the surface: every fluid term scales with φ (buoyancy and Froude–Krylov above; added
  // mass, its Coriolis and the flow's inertia force, and damping here), the mass matrix is
  // M_RB + φ M_A (factored here, a fixed-size LDLT: no allocation), and the added mass changing
  // with the position adds −φ̇ M_A ν_r + ½ (ν_rᵀ M_A ν_r) ∇φ, the terms of Lagrange's equations
  // for T = ½ νᵀ (M_RB + φ(η) M_A) ν (d/dt(M ν) = M ν̇ + φ̇ M_A ν, minus ∂T/∂η), so that T + U is
  // still conserved without damping (no energy from the changing mass). ∇φ in body axes is
  // (1/h)(d, r_b × d), d = Rᵀ e_z, inside the band and 0 outside; φ̇ = ∇φᵀ ν_r, which in waves
  // counts the surface's own motion through the orbital velocity.
  const Matrix6<Scalar>& ma = model.added_mass();
  ws.coriolis_added_mass *= phi;
  ws.damping *= phi;
  if (value_of(phi) > 0.0) {
    const Vector3<Scalar> d = ws.rotation.row(2).transpose();
    Vector6<Scalar> grad;
    grad.template head<3>() = d / p.hull_height;
    grad.template tail<3>() = Vector3<Scalar>(p.r_b).cross(d) / p.hull_height;
    const Vector6<Scalar> ma_nu_r = ma * ws.nu_r;
    ws.added_mass_change = -grad.dot(ws.nu_r) * ma_nu_r + Scalar(0.5) * ws.nu_r.dot(ma_nu_r) * grad;
  }
  ws.rhs = Vector6<Scalar>(tau) + Vector6<Scalar>(tau_ext) - ws.coriolis_rigid_body -
           ws.coriolis_added_mass - ws.damping - ws.restoring + phi * (ma * ws.nu_c_dot) +
           ws.froude_krylov + ws.wind + ws.added_mass_change;
  const Matrix6<Scalar> mass = model.rigid_body_mass() + phi * ma;
  const Eigen::LDLT<Matrix6<Scalar>> ldlt(mass);
  ws.nu_dot = ldlt.solve(ws.rhs);
  return ws.nu_dot;
}

/// The surroundings of a uniform current under a flat calm surface, no wind.
template <typename Scalar, typename DC>
Surroundings<Scalar> current_surroundings(const Eigen::MatrixBase<DC>& current_ned) {
  KELP_CHECK(current_ned.size() == 3, "forward_dynamics: current_ned must have 3 entries");
  Surroundings<Scalar> s;
  s.water_velocity = current_ned;
  return s;
}

/// Throws kelp::invalid_argument naming the first value forward_dynamics() reads that is not
/// finite (about 40 comparisons: nothing beside the 6×6 solve).
template <typename Scalar, typename D1, typename D2>
void check_dynamics_input(const VehicleState<Scalar>& state, const Eigen::MatrixBase<D1>& tau,
                          const Eigen::MatrixBase<D2>& tau_ext, const Surroundings<Scalar>& s) {
  KELP_CHECK(tau.size() == 6 && tau_ext.size() == 6,
             "forward_dynamics: tau and tau_ext must have 6 entries");
  check_all_finite(tau, "forward_dynamics: tau");
  check_all_finite(tau_ext, "forward_dynamics: tau_ext");
  check_all_finite(state.position, "forward_dynamics: state.position");
  check_all_finite(state.attitude.coeffs(), "forward_dynamics: state.attitude");
  check_all_finite(state.nu, "forward_dynamics: state.nu");
  check_all_finite(s.water_velocity, "forward_dynamics: surroundings water_velocity");
  check_all_finite(s.water_acceleration, "forward_dynamics: surroundings water_acceleration");
  check_finite(s.surface_elevation, "forward_dynamics: surroundings surface_elevation");
  check_all_finite(s.surface_slope, "forward_dynamics: surroundings surface_slope");
  check_all_finite(s.wind_velocity, "forward_dynamics: surroundings wind_velocity");
  check_finite(s.air_density, "forward_dynamics: surroundings air_density");
}

}  // namespace detail

/// \brief Forward dynamics of a vehicle in its surroundings (water velocity and acceleration, free
/// surface, wind), allocation-free:
/// \f[ \dot\nu = M^{-1}\big(\tau + \tau_{ext} - C_{RB}(\nu)\nu - C_A(\nu_r)\nu_r - D(\nu_r)\nu_r
///     - g(\eta, \zeta, \nabla\zeta) + M_A\dot\nu_w + \tau_{FK} + \tau_{wind}\big). \f]
/// Water motion (Fossen 2021, §10.3, extended to a non-uniform, unsteady flow as in Faltinsen
/// 1990, ch. 3, for a body small against the wavelength): ν_w = (Rᵀ v_w, 0) with v_w the water
/// velocity at the CO (current + wave orbital velocity), ν_r = ν − ν_w, and the body-frame rate
/// of the water velocity seen by the vehicle ν̇_w = (ν_{w,1} × ν₂ + Rᵀ a_w, 0), where a_w is the
/// water's material acceleration Dv/Dt = ∂v/∂t + (v·∇)v at the CO (Surroundings::
/// water_acceleration: the convective part from the wave velocity gradient; without it a
/// neutrally buoyant body sinks under waves, pushed by the mean (m + A₃₃) k a²ω² e^{−2kz}). The
/// difference (∇v_w)(ṗ − v_w) between the rate along the body's path and along the water's
/// (second order in the wave steepness times the relative velocity) and the slow time variation
/// of the current are neglected.
/// M_A ν̇_w is the added-mass (diffraction) force of the accelerating flow; τ_FK = (ρ ∇ φ Rᵀ a_w,
/// 0) is the Froude–Krylov force (the pressure gradient of the undisturbed flow on the displaced
/// volume, φ the submerged fraction), so the translational forcing is (ρ∇ I + M_A) Rᵀ a_w, the
/// inertia term of Morison's equation with C_M = 1 + C_A. For a surface vessel only the
/// horizontal part of a_w enters τ_FK: the vertical pressure of the wave is already in the
/// restoring that follows the local surface. The moments of τ_FK are neglected (small body).
/// Wind (surface vessels): environment::wind_load() with the model's `wind_areas` and
/// `wind_coefficients` and the surroundings' air density (the environment's: one air, as there
/// is one water), on the heading ψ and the body velocity over ground (Fossen 2021,
/// §10.1.1). With still water, no wind and a flat surface this is the irrotational-current
/// model of the file comment.
/// Free surface (`submerged_free_surface`, docs/equations.md "Free surface"): every fluid term
/// scales with the submerged fraction φ of the box hull about the CB: buoyancy, τ_FK, the added
/// mass (M = M_RB + φ M_A in the mass matrix, φ C_A, φ M_A ν̇_w) and the damping φ D; the
/// position-dependent added mass adds ws.added_mass_change = −φ̇ M_A ν_r + ½ (ν_rᵀ M_A ν_r) ∇φ
/// (Lagrange's equations for T = ½ νᵀ M(φ) ν), so that T + U is conserved without damping.
///
/// \param[in] model the vehicle. \param[in,out] ws buffers, filled with the terms.
/// \param[in] state pose (NED, unit quaternion) and ν (body).
/// \param[in] tau control wrench (thrusters) [N, N m], body axes about the CO.
/// \param[in] tau_ext other external wrench [N, N m], body axes about the CO (e.g. the tether's).
/// \param[in] s the surroundings at the vehicle's position (see surroundings()).
/// \return ν̇ [m/s², rad/s²], body axes.
/// \throws kelp::invalid_argument when tau or tau_ext has not 6 entries, or naming the first
/// value that is not finite (NaN or ±Inf) in tau, tau_ext, the state's position, attitude or ν,
/// or the surroundings; `ws` is then left as it was. The steps evaluate their stages without
/// these checks (detail::forward_dynamics_unchecked): they check their own input once, and a
/// non-finite value that appears inside a step ends it as numerical_error, state unchanged.
template <typename Scalar, typename D1, typename D2>
Vector6<Scalar> forward_dynamics(const VehicleModel<Scalar>& model, VehicleWorkspace<Scalar>& ws,
                                 const VehicleState<Scalar>& state,
                                 const Eigen::MatrixBase<D1>& tau,
                                 const Eigen::MatrixBase<D2>& tau_ext,
                                 const Surroundings<Scalar>& s) {
  detail::check_dynamics_input(state, tau, tau_ext, s);
  return detail::forward_dynamics_unchecked(model, ws, state, tau, tau_ext, s);
}

/// \brief Forward dynamics ν̇ = M⁻¹(τ + τ_ext − C_RB(ν)ν − C_A(ν_r)ν_r − D(ν_r)ν_r − g + M_A ν̇_c)
/// in a uniform current, flat calm surface at z = 0, no wind (see the file comment; Fossen 2021,
/// §10.3). Same as the Surroundings overload with water_velocity = current_ned. Allocation-free.
///
/// \param[in] model the vehicle. \param[in,out] ws buffers, filled with the terms.
/// \param[in] state pose (NED, unit quaternion) and ν (body).
/// \param[in] tau control wrench (thrusters) [N, N m], body axes about the CO.
/// \param[in] tau_ext other external wrench [N, N m], body axes about the CO (tether, wind,
///   waves... added by the caller each step).
/// \param[in] current_ned ocean current velocity v_c^n [m/s] in NED (irrotational, uniform).
/// \return ν̇ [m/s², rad/s²], body axes.
/// \throws kelp::invalid_argument when tau or tau_ext has not 6 entries or current_ned not 3, or
/// naming the first value that is not finite in tau, tau_ext, the state or current_ned (as the
/// Surroundings overload; `ws` is then left as it was).
template <typename Scalar, typename DT, typename DE, typename DC>
Vector6<Scalar> forward_dynamics(const VehicleModel<Scalar>& model, VehicleWorkspace<Scalar>& ws,
                                 const VehicleState<Scalar>& state,
                                 const Eigen::MatrixBase<DT>& tau,
                                 const Eigen::MatrixBase<DE>& tau_ext,
                                 const Eigen::MatrixBase<DC>& current_ned) {
  return forward_dynamics(model, ws, state, tau, tau_ext,
                          detail::current_surroundings<Scalar>(current_ned));
}

/// \brief Forward dynamics without current: ν̇ = M⁻¹(τ + τ_ext − C_RB ν − C_A ν − D ν − g).
/// \param[in] model the vehicle. \param[in,out] ws buffers, filled with the terms.
/// \param[in] state pose (NED, unit quaternion) and ν (body).
/// \param[in] tau control wrench [N, N m], body axes about the CO.
/// \param[in] tau_ext other external wrench [N, N m], body axes about the CO.
/// \return ν̇ [m/s², rad/s²], body axes.
/// \throws as the overload with a current.
template <typename Scalar, typename DT, typename DE>
Vector6<Scalar> forward_dynamics(const VehicleModel<Scalar>& model, VehicleWorkspace<Scalar>& ws,
                                 const VehicleState<Scalar>& state,
                                 const Eigen::MatrixBase<DT>& tau,
                                 const Eigen::MatrixBase<DE>& tau_ext) {
  return forward_dynamics(model, ws, state, tau, tau_ext, Vector3<Scalar>::Zero());
}

/// \brief Mechanical energy [J] of a vehicle: kinetic ½ νᵀ (M_RB + φ M_A) ν (φ the submerged
/// fraction, 1 unless `submerged_free_surface`) plus the hydrostatic
/// potential U of VehicleModel::restoring_potential() for the surface in `s` (elevation and slope
/// at the CO). U is the integral of the restoring force, so without damping, forcing, current or
/// waves (flat surface) the energy is conserved: e.g. for `submerged_free_surface`
/// U = −W z_CG + B h Φ(s) with Φ the integral of the submerged fraction (see
/// restoring_potential_free_surface()). The added-mass kinetic energy uses the velocity over
/// ground (the fluid at rest).
/// \param model The vehicle.
/// \param state Its state.
/// \param s Surroundings at the vehicle (only the surface elevation and slope are read; default:
/// flat calm surface at z = 0).
/// \return Kinetic + hydrostatic potential energy [J].
template <typename Scalar>
Scalar energy(const VehicleModel<Scalar>& model, const VehicleState<Scalar>& state,
              const Surroundings<Scalar>& s = Surroundings<Scalar>()) {
  const Scalar phi = model.submerged_fraction(state, s.surface_elevation);
  const Scalar kinetic = Scalar(0.5) * state.nu.dot(model.rigid_body_mass() * state.nu) +
                         Scalar(0.5) * phi * state.nu.dot(model.added_mass() * state.nu);
  return kinetic + model.restoring_potential(state, s.surface_elevation, s.surface_slope);
}

/// \brief Vehicle parameters in double precision.
using VehicleParametersd = VehicleParameters<double>;
/// \brief Vehicle parameters in single precision.
using VehicleParametersf = VehicleParameters<float>;
/// \brief Vehicle model in double precision.
using VehicleModeld = VehicleModel<double>;
/// \brief Vehicle model in single precision.
using VehicleModelf = VehicleModel<float>;
/// \brief Forward-dynamics workspace in double precision.
using VehicleWorkspaced = VehicleWorkspace<double>;
/// \brief Forward-dynamics workspace in single precision.
using VehicleWorkspacef = VehicleWorkspace<float>;

}  // namespace kelp::vehicle
