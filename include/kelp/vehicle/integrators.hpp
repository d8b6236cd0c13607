/// \file
/// \brief Fixed-step integrators for a VehicleState: classical RK4 (`step_rk4`, `step_rk4_with`)
/// and semi-implicit (symplectic) Euler (`step_symplectic_euler`); kelp names every integrator
/// step `step_<scheme>`, as the tether's (one name per scheme). Both are allocation-free,
/// renormalise the attitude quaternion and leave the state unchanged (throwing
/// kelp::numerical_error) when a step produces a non-finite value or an attitude it cannot
/// renormalise (the zero quaternion).
///
/// Calling convention (kelp's, for every layer): `step_x(model, ws, [env,] state, inputs, dt,
/// [options])`: the constant description first (the model, then the environment, which a vehicle
/// model does not own), then what the step writes (workspace, state), what the caller gives this
/// step (VehicleInputs: τ and τ_ext), the step length and last the options (here the uniform
/// current of the environment-free variants). The clock is the state's (`VehicleState::time`):
/// a step samples the environment at it and advances it by dt on success.
///
/// `dt` is a non-deduced parameter (`kelp::identity_t<Scalar>`): Scalar comes from the model and
/// state, so `step_rk4(model, ws, x, inputs, 0.01)` compiles for a float model too.
/// After a step the workspace holds the terms of the step's last evaluation, not of the committed
/// state (see `VehicleWorkspace`).
///
/// The external wrench is either held constant over the step (zero-order hold: the usual coupling
/// with a controller or a tether solved once per step) or given as a callable evaluated at every
/// RK4 stage.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <utility>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/vehicle/kinematics.hpp"
#include "kelp/vehicle/model.hpp"
#include "kelp/vehicle/state.hpp"
#include "kelp/vehicle/surroundings.hpp"

namespace kelp::vehicle {

/// \brief Time derivative of a VehicleState.
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
struct StateDerivative {
  /// ṗ [m/s] NED and q̇ (Eigen coefficient order x, y, z, w).
  PoseRate<Scalar> pose;
  /// ν̇ [m/s², rad/s²], body axes.
  Vector6<Scalar> nu_dot = Vector6<Scalar>::Zero();
};

namespace detail {

/// state_derivative() with the unchecked forward dynamics: the stage derivative of the steps.
template <typename Scalar, typename DT>
StateDerivative<Scalar> state_derivative_unchecked(const VehicleModel<Scalar>& model,
                                                   VehicleWorkspace<Scalar>& ws,
                                                   const VehicleState<Scalar>& state,
                                                   const Eigen::MatrixBase<DT>& tau_total,
                                                   const Surroundings<Scalar>& s) {
  StateDerivative<Scalar> d;
  d.pose = pose_rate(state.attitude, state.nu);
  d.nu_dot = forward_dynamics_unchecked(model, ws, state, tau_total, Vector6<Scalar>::Zero(), s);
  return d;
}

}  // namespace detail

/// \brief Full state derivative: kinematics (pose_rate()) and kinetics (forward_dynamics()).
/// \param[in] model vehicle. \param[in,out] ws buffers. \param[in] state current state.
/// \param[in] tau_total τ + τ_ext [N, N m], body axes. \param[in] current_ned v_c^n [m/s], NED.
/// \tparam Scalar double, float or ceres::Jet.
/// \tparam DT, DC Eigen vector expressions (6 and 3 entries).
/// \return ṗ (NED), q̇ and ν̇ (body) at `state`.
/// \throws as forward_dynamics(): kelp::invalid_argument for a wrench or current of the wrong
/// size or a non-finite value in them or in the state.
template <typename Scalar, typename DT, typename DC>
StateDerivative<Scalar> state_derivative(const VehicleModel<Scalar>& model,
                                         VehicleWorkspace<Scalar>& ws,
                                         const VehicleState<Scalar>& state,
                                         const Eigen::MatrixBase<DT>& tau_total,
                                         const Eigen::MatrixBase<DC>& current_ned) {
  const Surroundings<Scalar> s = detail::current_surroundings<Scalar>(current_ned);
  detail::check_dynamics_input(state, tau_total, Vector6<Scalar>::Zero(), s);
  return detail::state_derivative_unchecked(model, ws, state, tau_total, s);
}

namespace detail {

template <typename Scalar>
VehicleState<Scalar> advance(const VehicleState<Scalar>& x, const StateDerivative<Scalar>& d,
                             const Scalar& h) {
  VehicleState<Scalar> y;
  y.time = x.time + double(value_of(h));  // the stage's time
  y.position = x.position + h * d.pose.position_dot;
  y.attitude.coeffs() = x.attitude.coeffs() + h * d.pose.attitude_dot;
  renormalize(y.attitude);
  y.nu = x.nu + h * d.nu_dot;
  return y;
}

/// Commits `next` if it is finite with a unit attitude (renormalize() keeps a finite non-zero
/// quaternion unit; a zero one, e.g. from a stage that cancelled it, is no rotation), else throws
/// numerical_error naming `who`, state unchanged.
template <typename Scalar>
void commit_if_finite(VehicleState<Scalar>& state, const VehicleState<Scalar>& next,
                      const char* who) {
  if (!(all_finite(next.position) && all_finite(next.attitude.coeffs()) && all_finite(next.nu)))
    ::kelp::detail::throw_numerical_error(std::string(who) +
                                          ": step produced a non-finite state; state unchanged");
  using std::abs;
  if (!(abs(value_of(next.attitude.squaredNorm()) - 1.0) < 1e-3))
    ::kelp::detail::throw_numerical_error(
        std::string(who) + ": step produced a non-unit attitude quaternion; state unchanged");
  state = next;
}

/// Classical RK4 over dt from `state`: `deriv(x, c)` returns the StateDerivative at the stage state
/// x (whose `time` is the stage's), c ∈ {0, ½, ½, 1} being the stage's fraction of the step.
/// Commits a finite result at `state.time + dt` (else throws numerical_error naming `who`, state
/// unchanged) and returns the last stage's derivative. The one RK4 of the vehicle steps and of the
/// coupled system.
template <typename Scalar, typename Deriv>
StateDerivative<Scalar> rk4(VehicleState<Scalar>& state, const Scalar& dt, Deriv&& deriv,
                            const char* who) {
  const Scalar half = Scalar(0.5) * dt;
  const StateDerivative<Scalar> k1 = deriv(state, 0.0);
  const StateDerivative<Scalar> k2 = deriv(advance(state, k1, half), 0.5);
  const StateDerivative<Scalar> k3 = deriv(advance(state, k2, half), 0.5);
  const StateDerivative<Scalar> k4 = deriv(advance(state, k3, dt), 1.0);
  StateDerivative<Scalar> k;
  const Scalar two(2);
  k.pose.position_dot = k1.pose.position_dot + two * k2.pose.position_dot +
                        two * k3.pose.position_dot + k4.pose.position_dot;
  k.pose.attitude_dot = k1.pose.attitude_dot + two * k2.pose.attitude_dot +
                        two * k3.pose.attitude_dot + k4.pose.attitude_dot;
  k.nu_dot = k1.nu_dot + two * k2.nu_dot + two * k3.nu_dot + k4.nu_dot;
  VehicleState<Scalar> next = advance(state, k, dt / Scalar(6));
  next.time = state.time + double(value_of(dt));
  commit_if_finite(state, next, who);
  return k4;
}

/// Checks a vehicle state: finite clock, position, velocity and attitude, and a unit attitude (a
/// zero or badly scaled quaternion would otherwise be silently read as some rotation by Eigen).
template <typename Scalar>
void check_state(const VehicleState<Scalar>& state) {
  check_finite(state.time, "state.time");
  check_all_finite(state.position, "state.position");
  check_all_finite(state.nu, "state.nu");
  check_all_finite(state.attitude.coeffs(), "state.attitude");
  using std::abs;
  KELP_CHECK(abs(value_of(state.attitude.squaredNorm()) - 1.0) < 1e-3,
             "state.attitude must be a unit quaternion");
}

/// Checks what a step takes from the caller: dt > 0 and a valid state (check_state).
template <typename Scalar>
void check_step_input(const VehicleState<Scalar>& state, identity_t<Scalar> dt) {
  check_positive(dt, "dt");
  check_state(state);
}

/// Checks a current velocity: 3 finite NED entries.
template <typename Derived>
void check_current(const Eigen::MatrixBase<Derived>& v) {
  KELP_CHECK(v.size() == 3, "current_ned must have 3 entries");
  check_all_finite(v, "current_ned");
}

/// The semi-implicit (symplectic) Euler update from ν̇ at the start of the step (see
/// step_symplectic_euler()); commits a finite result at `state.time + dt`.
template <typename Scalar>
void symplectic_euler(VehicleState<Scalar>& state, const Vector6<Scalar>& nu_dot, const Scalar& dt,
                      const char* who) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  VehicleState<Scalar> next;
  next.time = state.time + double(value_of(dt));
  next.nu = state.nu + dt * nu_dot;
  next.position =
      state.position + dt * (state.attitude * Vector3<Scalar>(next.nu.template head<3>()));
  const Vector3<Scalar> rot = dt * next.nu.template tail<3>();
  const Scalar angle2 = rot.squaredNorm();
  Quaternion<Scalar> dq;
  if (value_of(angle2) > 1e-24) {
    const Scalar angle = sqrt(angle2);
    const Scalar s = sin(Scalar(0.5) * angle) / angle;
    dq = Quaternion<Scalar>(cos(Scalar(0.5) * angle), s * rot(0), s * rot(1), s * rot(2));
  } else {
    const Scalar h(0.5);
    dq = Quaternion<Scalar>(Scalar(1), h * rot(0), h * rot(1), h * rot(2));
  }
  next.attitude = state.attitude * dq;
  renormalize(next.attitude);
  commit_if_finite(state, next, who);
}

}  // namespace detail

/// \brief One classical fourth-order Runge–Kutta step of length `dt` with a wrench evaluated at
/// every stage: `wrench(stage_state, stage_time_offset)` must return τ + τ_ext (Vector6, body axes,
/// [N, N m]); stage offsets are 0, dt/2, dt/2, dt (the stage state's `time` is the stage's time).
/// The quaternion is renormalised at every stage and at the end.
/// \param[in] model vehicle. \param[in,out] ws buffers.
/// \param[in,out] state advanced by dt (its clock too) on success, unchanged on failure.
/// \param[in] wrench callable as above (the step's inputs). \param[in] dt step [s], > 0.
/// \param[in] current_ned v_c^n [m/s], NED, constant over the step.
/// \throws kelp::invalid_argument naming `dt`, a non-finite state field (its time included), a
/// non-unit attitude or a `current_ned` that is not 3 finite entries; kelp::numerical_error on a
/// non-finite result (including a non-finite wrench returned by the callable).
template <typename Scalar, typename WrenchFn, typename DC>
void step_rk4_with(const VehicleModel<Scalar>& model, VehicleWorkspace<Scalar>& ws,
                   VehicleState<Scalar>& state, WrenchFn&& wrench, identity_t<Scalar> dt,
                   const Eigen::MatrixBase<DC>& current_ned) {
  detail::check_step_input(state, dt);
  detail::check_current(current_ned);
  const Surroundings<Scalar> s = detail::current_surroundings<Scalar>(current_ned);
  // Stages unchecked: a NaN wrench or stage state ends the step as numerical_error (rk4).
  detail::rk4(
      state, dt,
      [&](const VehicleState<Scalar>& x, double c) {
        return detail::state_derivative_unchecked(model, ws, x, wrench(x, Scalar(c) * dt), s);
      },
      "step_rk4");
}

/// \brief step_rk4_with() in still water.
/// \param[in] model vehicle. \param[in,out] ws buffers.
/// \param[in,out] state advanced by dt (its clock too) on success, unchanged on failure.
/// \param[in] wrench callable `(stage_state, stage_time_offset)` → τ + τ_ext [N, N m], body.
/// \param[in] dt step [s], > 0.
/// \throws as the overload with a current.
template <typename Scalar, typename WrenchFn>
void step_rk4_with(const VehicleModel<Scalar>& model, VehicleWorkspace<Scalar>& ws,
                   VehicleState<Scalar>& state, WrenchFn&& wrench, identity_t<Scalar> dt) {
  step_rk4_with(model, ws, state, std::forward<WrenchFn>(wrench), dt, Vector3<Scalar>::Zero());
}

/// \brief One RK4 step in a uniform current, flat calm surface, no wind, with τ and τ_ext held
/// over the step (zero-order hold).
/// \param[in] model vehicle. \param[in,out] ws buffers.
/// \param[in,out] state advanced by dt (its clock too) on success, unchanged on failure.
/// \param[in] inputs τ and τ_ext [N, N m], body. \param[in] dt step [s], > 0.
/// \param[in] current_ned v_c^n [m/s], NED.
/// \throws kelp::invalid_argument naming `dt`, a non-finite state field (its time included), a
/// non-unit attitude or `current_ned` (not 3 finite entries); kelp::numerical_error on a
/// non-finite result (a NaN or Inf in the inputs included).
template <typename Scalar, typename DC>
void step_rk4(const VehicleModel<Scalar>& model, VehicleWorkspace<Scalar>& ws,
              VehicleState<Scalar>& state, const VehicleInputs<Scalar>& inputs,
              identity_t<Scalar> dt, const Eigen::MatrixBase<DC>& current_ned) {
  const Vector6<Scalar> total = inputs.tau + inputs.tau_ext;
  step_rk4_with(
      model, ws, state,
      [&total](const VehicleState<Scalar>&, const Scalar&) -> const Vector6<Scalar>& {
        return total;
      },
      dt, current_ned);
}

/// \brief One RK4 step in still water (no current).
/// \param[in] model vehicle. \param[in,out] ws buffers.
/// \param[in,out] state advanced by dt (its clock too) on success, unchanged on failure.
/// \param[in] inputs τ and τ_ext [N, N m], body. \param[in] dt step [s], > 0.
/// \throws as the overload with a current.
template <typename Scalar>
void step_rk4(const VehicleModel<Scalar>& model, VehicleWorkspace<Scalar>& ws,
              VehicleState<Scalar>& state, const VehicleInputs<Scalar>& inputs,
              identity_t<Scalar> dt) {
  step_rk4(model, ws, state, inputs, dt, Vector3<Scalar>::Zero());
}

/// \brief Surroundings a vehicle model needs at state `x` and time t: the surface slope only for
/// a surface vessel (a submerged one's restoring reads only the elevation), the wind only for a
/// model with wind areas (else zero; forward_dynamics does not read it then).
///
/// The water that moves a hull is the water around its submerged part, not at its CO, which for
/// a floating hull lies on the waterline and so above the local surface about half the time
/// (where the wave kinematics are zero). The water velocity and acceleration are therefore
/// taken no higher than the centroid of the submerged part: for a surface vessel half its
/// still-water draft ∇/A_wp below the local surface; for a submerged vehicle whose hull box
/// (`hull_height` about the CB, Hydrostatics::submerged_free_surface) pierces the surface,
/// halfway between the surface and the bottom of the box. One more environment sample when that
/// applies.
/// \tparam Env `kelp::environment::Environment` or a type with the same queries (see the
/// overload without a model).
/// \param[in] model vehicle (its hydrostatics, draft and wind areas decide what is sampled).
/// \param[in] env environment \param[in] x vehicle state \param[in] t time [s]
/// \return The surroundings: water velocity and material acceleration (NED), free surface and
/// wind.
template <typename Scalar, typename Env>
Surroundings<Scalar> surroundings(const VehicleModel<Scalar>& model, const Env& env,
                                  const VehicleState<Scalar>& x, double t) {
  const VehicleParameters<Scalar>& p = model.parameters();
  // The wind only for a hull with areas above water; the slope only for a surface vessel.
  const bool wind = p.wind_areas.frontal_area > 0.0 || p.wind_areas.lateral_area > 0.0;
  Surroundings<Scalar> s =
      detail::sample_surroundings(env, x, t, p.hydrostatics == Hydrostatics::surface, wind);
  const Scalar z = x.position(2), z_surface = -s.surface_elevation;
  Scalar z_wet = z;
  if (p.hydrostatics == Hydrostatics::surface && value_of(p.waterplane_area) > 0.0) {
    const Scalar centroid = z_surface + Scalar(0.5) * p.displaced_volume / p.waterplane_area;
    if (value_of(centroid) > value_of(z)) z_wet = centroid;
  } else if (p.hydrostatics == Hydrostatics::submerged_free_surface &&
             value_of(p.hull_height) > 0.0) {
    // The box is centred on the CB, as the submerged fraction's band (restoring.hpp).
    const Scalar z_cb = z + x.attitude.toRotationMatrix().row(2).dot(p.r_b);
    const Scalar half = Scalar(0.5) * p.hull_height;
    if (value_of(z_cb - half) < value_of(z_surface)) {  // the box pierces the surface
      const Scalar bottom = z_cb + half;
      z_wet =
          value_of(bottom) > value_of(z_surface) ? Scalar(0.5) * (z_surface + bottom) : z_surface;
    }
  }
  if (value_of(z_wet) > value_of(z)) resample_water(env, x, t, z_wet, s);
  return s;
}

/// \brief One classical RK4 step of length `dt` in an environment: the surroundings (water
/// velocity and acceleration, free surface, wind) are sampled at each stage's state and time
/// (t, t + dt/2, t + dt/2, t + dt, with t = state.time) and enter forward_dynamics(…,
/// Surroundings); τ and τ_ext are held over the step (zero-order hold). Allocation-free. The
/// caller checks once that the model's water is the environment's (check_same_water in
/// water.hpp).
/// \param[in] model vehicle.
/// \param[in] env environment (`kelp::environment::Environment` or any type with `sample(p, t)`
/// and `surface_slope(x, y, t)`). \param[in,out] ws buffers.
/// \param[in,out] state advanced by dt (its clock too) on success, unchanged (bit for bit) on
/// failure. \param[in] inputs τ (control) and τ_ext (e.g. the tether's) [N, N m], body.
/// \param[in] dt step [s], > 0.
/// \throws kelp::invalid_argument naming `dt` or a non-finite state field (`state.time`
/// included) or a non-unit attitude; kelp::numerical_error on a non-finite result (a NaN or Inf
/// in the inputs included).
template <typename Scalar, typename Env>
void step_rk4(const VehicleModel<Scalar>& model, VehicleWorkspace<Scalar>& ws, const Env& env,
              VehicleState<Scalar>& state, const VehicleInputs<Scalar>& inputs,
              identity_t<Scalar> dt) {
  detail::check_step_input(state, dt);
  const Vector6<Scalar> total = inputs.tau + inputs.tau_ext;
  const Vector6<Scalar> zero = Vector6<Scalar>::Zero();
  const double t = state.time, dt_d = value_of(dt);
  detail::rk4(
      state, dt,
      [&](const VehicleState<Scalar>& x, double c) {
        StateDerivative<Scalar> d;
        d.pose = pose_rate(x.attitude, x.nu);
        d.nu_dot = detail::forward_dynamics_unchecked(model, ws, x, total, zero,
                                                      surroundings(model, env, x, t + c * dt_d));
        return d;
      },
      "step_rk4");
}

/// \brief One semi-implicit (symplectic) Euler step in a uniform current, flat calm surface, no
/// wind: ν_{k+1} = ν_k + dt ν̇(x_k), then the pose is advanced with the *new* velocity:
/// p_{k+1} = p_k + dt R(q_k) ν₁_{k+1} and q_{k+1} = q_k ⊗ exp(½ dt ν₂_{k+1}) (exact rotation for a
/// constant rate, so the quaternion stays unit). First order; cheap and stable for stiff
/// restoring/damping at small dt. The tether's scheme of the same name (tether::Integrator::
/// symplectic_euler) is the same update.
/// \param[in] model vehicle. \param[in,out] ws buffers.
/// \param[in,out] state advanced by dt (its clock too) on success, unchanged on failure.
/// \param[in] inputs τ and τ_ext [N, N m], body. \param[in] dt step [s], > 0.
/// \param[in] current_ned v_c^n [m/s], NED.
/// \throws kelp::invalid_argument naming `dt`, a non-finite state field (its time included), a
/// non-unit attitude or `current_ned` (not 3 finite entries); kelp::numerical_error on a
/// non-finite result (a NaN or Inf in the inputs included).
template <typename Scalar, typename DC>
void step_symplectic_euler(const VehicleModel<Scalar>& model, VehicleWorkspace<Scalar>& ws,
                           VehicleState<Scalar>& state, const VehicleInputs<Scalar>& inputs,
                           identity_t<Scalar> dt, const Eigen::MatrixBase<DC>& current_ned) {
  detail::check_step_input(state, dt);
  detail::check_current(current_ned);
  const Vector6<Scalar> nu_dot =
      detail::forward_dynamics_unchecked(model, ws, state, inputs.tau, inputs.tau_ext,
                                         detail::current_surroundings<Scalar>(current_ned));
  detail::symplectic_euler(state, nu_dot, Scalar(dt), "step_symplectic_euler");
}

/// \brief One semi-implicit (symplectic) Euler step in still water (no current).
/// \param[in] model vehicle. \param[in,out] ws buffers.
/// \param[in,out] state advanced by dt (its clock too) on success, unchanged on failure.
/// \param[in] inputs τ and τ_ext [N, N m], body. \param[in] dt step [s], > 0.
/// \throws as the overload with a current.
template <typename Scalar>
void step_symplectic_euler(const VehicleModel<Scalar>& model, VehicleWorkspace<Scalar>& ws,
                           VehicleState<Scalar>& state, const VehicleInputs<Scalar>& inputs,
                           identity_t<Scalar> dt) {
  step_symplectic_euler(model, ws, state, inputs, dt, Vector3<Scalar>::Zero());
}

/// \brief One semi-implicit (symplectic) Euler step in an environment: ν̇ from the surroundings
/// sampled at the start of the step (at state.time), then the update of the current-only
/// overload. \throws as step_rk4() in an environment.
/// \param[in] model vehicle. \param[in,out] ws buffers.
/// \param[in] env environment (as for step_rk4() in an environment).
/// \param[in,out] state advanced by dt (its clock too) on success, unchanged on failure.
/// \param[in] inputs τ and τ_ext [N, N m], body. \param[in] dt step [s], > 0.
template <typename Scalar, typename Env>
void step_symplectic_euler(const VehicleModel<Scalar>& model, VehicleWorkspace<Scalar>& ws,
                           const Env& env, VehicleState<Scalar>& state,
                           const VehicleInputs<Scalar>& inputs, identity_t<Scalar> dt) {
  detail::check_step_input(state, dt);
  const Vector6<Scalar> nu_dot = detail::forward_dynamics_unchecked(
      model, ws, state, inputs.tau, inputs.tau_ext, surroundings(model, env, state, state.time));
  detail::symplectic_euler(state, nu_dot, Scalar(dt), "step_symplectic_euler");
}

}  // namespace kelp::vehicle
