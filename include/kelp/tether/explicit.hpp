/// \file
/// \brief The explicit tether steps: semi-implicit (symplectic) Euler, explicit midpoint (RK2)
/// and classical RK4. Each ends with one more force evaluation at the state it returns, for the
/// end forces (TetherWorkspace::end_forces), which the next explicit step takes as its first
/// stage when it starts from that state. See kelp/tether/stable_dt.hpp for the largest stable
/// step.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"

#include "kelp/core/simd.hpp"
#include "kelp/tether/forces.hpp"
#include "kelp/tether/model.hpp"
#include "kelp/tether/state.hpp"
#include "kelp/tether/stepping.hpp"

namespace kelp::tether {

namespace detail {

/// kelp's Environment and any environment with `std::uint64_t instance_id() const`: the id of
/// that object's value (0 for others).
template <typename Env, typename = void>
struct has_instance_id : std::false_type {};
template <typename Env>
struct has_instance_id<
    Env, std::void_t<decltype(std::uint64_t(std::declval<const Env&>().instance_id()))>>
    : std::true_type {};
template <typename Env>
std::uint64_t instance_id_of(const Env& env) {
  if constexpr (has_instance_id<Env>::value)
    return env.instance_id();
  else
    return 0;
}

/// The first stage of an explicit step: the forces and M⁻¹F at (state.time, x0, v0) into the
/// workspace (`acceleration`, the kinematic ends' rows the boundary's), unless the previous
/// explicit step evaluated exactly that at its end (TetherWorkspace::end_evaluated: the same
/// time, bitwise the same x0 and v0, the same model, environment and winch length). \returns
/// whether it evaluated the forces.
template <typename Scalar, typename Env>
bool first_stage(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws, const Env& env,
                 const TetherState<Scalar>& state, const TetherBoundary<Scalar>& boundary) {
  const auto same = [](const Matrix3X<Scalar>& a, const Matrix3X<Scalar>& b) {
    return a.size() == b.size() &&
           std::memcmp(a.data(), b.data(), sizeof(Scalar) * std::size_t(a.size())) == 0;
  };
  const bool reuse = ws.end_evaluated && ws.end_evaluation_time == state.time &&
                     ws.end_model == static_cast<const void*>(&model) &&
                     ws.end_environment == static_cast<const void*>(&env) &&
                     ws.end_environment_id == instance_id_of(env) &&
                     ws.end_winch_length == state.winch_length && same(ws.x0, ws.end_position) &&
                     same(ws.v0, ws.end_velocity);
  ws.end_evaluated = false;
  if (!reuse) {
    derivative(model, ws, env, state.time, boundary, ws.x0, ws.v0, ws.acceleration);
    return true;
  }
  const int n = model.segments();
  if (model.first_free_node() == 1) ws.acceleration.col(0) = boundary.start.acceleration;
  if (model.last_free_node() == n - 1) ws.acceleration.col(n) = boundary.end.acceleration;
  return false;
}

/// The end of an explicit step, after it committed its result to `state`: the forces at that
/// state and time into TetherWorkspace::end_forces and end_node_forces (the ends moving as
/// `boundary` has them h later), kept for the next explicit step (first_stage).
template <typename Scalar, typename Env>
void end_evaluation(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws, const Env& env,
                    const TetherState<Scalar>& state, const TetherBoundary<Scalar>& boundary,
                    Scalar h) {
  const TetherBoundary<Scalar> end = boundary.after(h);
  derivative(model, ws, env, state.time, end, state.position, state.velocity, ws.acceleration);
  ws.end_forces = end_forces_from_workspace(model, ws, end);
  set_end_node_forces(model, ws, end);
  ws.end_evaluated = true;
  ws.end_evaluation_time = state.time;
  ws.end_model = &model;
  ws.end_environment = &env;
  ws.end_environment_id = instance_id_of(env);
  ws.end_winch_length = state.winch_length;
  ws.end_position = state.position;
  ws.end_velocity = state.velocity;
}

}  // namespace detail

/// \brief One semi-implicit (symplectic) Euler step of length `dt` [s]:
/// v_{n+1} = v_n + h M⁻¹F(x_n, v_n), x_{n+1} = x_n + h v_{n+1}. Stable for h ω_max < 2.
/// End forces (`ws.end_forces`) are those at the end of the step (TetherWorkspace::end_forces).
/// \throws kelp::invalid_argument for bad input; kelp::numerical_error (state unchanged) when
/// the result is not finite.
/// \tparam Scalar double or float (deduced from the model).
/// \tparam Env the environment type: kelp::environment::Environment or any type with its duck-typed
/// interface (kelp/tether/lumped_mass.hpp).
/// \param[in] model the tether.
/// \param[in,out] ws the workspace built for `model` (TetherWorkspace(model)); end_forces,
/// end_node_forces and end_impulse are set.
/// \param[in] env the water (density, gravity, kinematics, seabed), queried at the step's times.
/// \param[in,out] state advanced by dt (its clock too) on success, unchanged on failure.
/// \param[in] boundary the kinematic ends' motion over the step, NED, from the state's time.
/// \param[in] dt the step [s], > 0 (estimate_stable_dt gives a stable one).
/// \return the work done (1 sub-step; 1 force evaluation, 2 when the previous step's end
/// evaluation could not be reused).
template <typename Scalar, typename Env>
StepReport<Scalar> step_symplectic_euler(const TetherModel<Scalar>& model,
                                         TetherWorkspace<Scalar>& ws, const Env& env,
                                         TetherState<Scalar>& state,
                                         const TetherBoundary<Scalar>& boundary, double dt) {
  detail::begin_explicit_step(model, ws, state, boundary, dt);
  const Scalar h = Scalar(dt);
  const bool evaluated = detail::first_stage(model, ws, env, state, boundary);
  const EndForces<Scalar> f0 = end_forces_from_workspace(model, ws, boundary);
  ws.end_impulse = {h * f0.on_start, h * f0.on_end};
  ws.v1.noalias() = ws.v0 + h * ws.acceleration;
  ws.x1.noalias() = ws.x0 + h * ws.v1;
  detail::apply_boundary(model, boundary, h, ws.x1, ws.v1);
  detail::commit(state, ws.x1, ws.v1, dt, "step_symplectic_euler");
  detail::end_evaluation(model, ws, env, state, boundary, h);
  StepReport<Scalar> r;
  r.substeps = 1;
  r.force_evaluations = 1 + int(evaluated);
  return r;
}

/// \brief One explicit-midpoint (RK2) step of length `dt` [s]. End forces are those at the end of
/// the step. \throws as step_symplectic_euler.
/// \tparam Scalar double or float (deduced from the model).
/// \tparam Env the environment type: kelp::environment::Environment or any type with its duck-typed
/// interface (kelp/tether/lumped_mass.hpp).
/// \param[in] model the tether.
/// \param[in,out] ws the workspace built for `model` (TetherWorkspace(model)); end_forces,
/// end_node_forces and end_impulse are set.
/// \param[in] env the water (density, gravity, kinematics, seabed), queried at the step's times.
/// \param[in,out] state advanced by dt (its clock too) on success, unchanged on failure.
/// \param[in] boundary the kinematic ends' motion over the step, NED, from the state's time.
/// \param[in] dt the step [s], > 0.
/// \return the work done (1 sub-step; 2 or 3 force evaluations, see step_symplectic_euler).
template <typename Scalar, typename Env>
StepReport<Scalar> step_rk2(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                            const Env& env, TetherState<Scalar>& state,
                            const TetherBoundary<Scalar>& boundary, double dt) {
  detail::begin_explicit_step(model, ws, state, boundary, dt);
  const double t = state.time;
  const Scalar h = Scalar(dt), h2 = Scalar(0.5) * h;
  const bool evaluated = detail::first_stage(model, ws, env, state, boundary);
  ws.xs.noalias() = ws.x0 + h2 * ws.v0;
  ws.vs.noalias() = ws.v0 + h2 * ws.acceleration;
  detail::apply_boundary(model, boundary, h2, ws.xs, ws.vs);
  detail::derivative(model, ws, env, t + 0.5 * dt, boundary, ws.xs, ws.vs, ws.acceleration);
  detail::add_end_impulse(model, ws, boundary, h);
  ws.x1.noalias() = ws.x0 + h * ws.vs;
  ws.v1.noalias() = ws.v0 + h * ws.acceleration;
  detail::apply_boundary(model, boundary, h, ws.x1, ws.v1);
  detail::commit(state, ws.x1, ws.v1, dt, "step_rk2");
  detail::end_evaluation(model, ws, env, state, boundary, h);
  StepReport<Scalar> r;
  r.substeps = 1;
  r.force_evaluations = 2 + int(evaluated);
  return r;
}

namespace detail {

/// One RK4 stage's state update in one vectorised pass over the flat 3 × (N+1) arrays: with the
/// stage accelerations ws.acceleration at the stage point (·, vs), accumulates x1 += w vs,
/// v1 += w a (the first stage starts them from x0, v0) and, unless this is the last stage, moves
/// the stage point to xs = x0 + ch vs, vs = v0 + ch a. `vs` is ws.v0 (first stage) or ws.vs
/// (updated in place). The kinematic end columns are overwritten by apply_boundary afterwards.
template <typename Scalar>
void rk4_stage_update(TetherWorkspace<Scalar>& ws, const Matrix3X<Scalar>& vs, Scalar w, Scalar ch,
                      bool first, bool last) {
  const Scalar *x0 = ws.x0.data(), *v0 = ws.v0.data(), *a = ws.acceleration.data();
  const Scalar* vin = vs.data();
  Scalar *x1 = ws.x1.data(), *v1 = ws.v1.data(), *xs = ws.xs.data(), *vo = ws.vs.data();
  const auto update = [&](auto lanes, Eigen::Index j) {
    using P = decltype(lanes);
    const P wp = P::all(w), vj = P::load(vin + j), aj = P::load(a + j);
    if (first) {
      (P::load(x0 + j) + wp * vj).store(x1 + j);
      (P::load(v0 + j) + wp * aj).store(v1 + j);
    } else {
      (P::load(x1 + j) + wp * vj).store(x1 + j);
      (P::load(v1 + j) + wp * aj).store(v1 + j);
    }
    if (!last) {
      const P cp = P::all(ch);
      (P::load(x0 + j) + cp * vj).store(xs + j);
      (P::load(v0 + j) + cp * aj).store(vo + j);
    }
  };
  simd::for_each_pack<Scalar>(0, ws.x1.size(), update);
}

}  // namespace detail

/// \brief One classical RK4 step of length `dt` [s]. End forces are those at the end of the step.
/// Four force evaluations (each also giving the accelerations M⁻¹F in its last pass), each
/// followed by one vectorised pass for the stage's state update, and the end state's (which the
/// next step takes as its first). \throws as step_symplectic_euler.
/// \tparam Scalar double or float (deduced from the model).
/// \tparam Env the environment type: kelp::environment::Environment or any type with its duck-typed
/// interface (kelp/tether/lumped_mass.hpp).
/// \param[in] model the tether.
/// \param[in,out] ws the workspace built for `model` (TetherWorkspace(model)); end_forces,
/// end_node_forces and end_impulse are set.
/// \param[in] env the water (density, gravity, kinematics, seabed), queried at the step's times.
/// \param[in,out] state advanced by dt (its clock too) on success, unchanged on failure.
/// \param[in] boundary the kinematic ends' motion over the step, NED, from the state's time.
/// \param[in] dt the step [s], > 0.
/// \return the work done (1 sub-step and its force evaluations).
template <typename Scalar, typename Env>
StepReport<Scalar> step_rk4(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                            const Env& env, TetherState<Scalar>& state,
                            const TetherBoundary<Scalar>& boundary, double dt) {
  detail::begin_explicit_step(model, ws, state, boundary, dt);
  const double t = state.time;
  const Scalar h = Scalar(dt);
  const Scalar c[4] = {Scalar(0), Scalar(0.5), Scalar(0.5), Scalar(1)};
  const Scalar w[4] = {h / Scalar(6), h / Scalar(3), h / Scalar(3), h / Scalar(6)};
  const double tc[4] = {t, t + 0.5 * dt, t + 0.5 * dt, t + dt};
  bool evaluated = false;
  for (int k = 0; k < 4; ++k) {
    const Matrix3X<Scalar>& xk = k == 0 ? ws.x0 : ws.xs;
    const Matrix3X<Scalar>& vk = k == 0 ? ws.v0 : ws.vs;
    if (k == 0)
      evaluated = detail::first_stage(model, ws, env, state, boundary);
    else
      detail::evaluate_forces<false>(model, ws, env, tc[k], xk, vk, ws.acceleration.data());
    detail::add_end_impulse(model, ws, boundary, w[k]);
    const bool last = k == 3;
    detail::rk4_stage_update(ws, vk, w[k], last ? Scalar(0) : c[k + 1] * h, k == 0, last);
    if (!last) detail::apply_boundary(model, boundary, c[k + 1] * h, ws.xs, ws.vs);
  }
  detail::apply_boundary(model, boundary, h, ws.x1, ws.v1);
  detail::commit(state, ws.x1, ws.v1, dt, "step_rk4");
  detail::end_evaluation(model, ws, env, state, boundary, h);
  StepReport<Scalar> r;
  r.substeps = 1;
  r.force_evaluations = 4 + int(evaluated);
  return r;
}

}  // namespace kelp::tether
