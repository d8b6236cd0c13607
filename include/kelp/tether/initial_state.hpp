/// \file
/// \brief Initial lumped-mass tether states from the analytic catenary, optionally refined to
/// the lumped-mass static equilibrium.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <utility>

#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/tether/catenary.hpp"
#include "kelp/tether/integrators.hpp"
#include "kelp/tether/lumped_mass.hpp"

namespace kelp::tether {

/// \brief Nodes placed on the analytic catenary between two NED end points, at rest.
///
/// Node i sits at unstretched arc length s_i = i·L/N on `catenary_between(start, end, L, w)`,
/// with w = (μ − ρA) g the submerged weight per length from the environment's water density and
/// gravity (a buoyant line, w < 0, gives the inverted catenary). A taut geometry gives the straight
/// line; if the catenary solve fails (`invalid_input`, `max_iterations`) the straight line is used
/// as well. When the environment has a finite seabed (`seabed_depth()`) and both ends are at or
/// above it, the catenary is solved with that seabed (CatenaryOptions::seabed_depth), so a line
/// long enough to touch down starts with its grounded part lying on the bed rather than below
/// it. Likewise a buoyant line (w < 0) whose inverted catenary would rise above the still-water
/// surface starts with those nodes on the surface (z = 0). The status is reported through `status`
/// when non-null.
/// \param[in] model the tether \param[in] env environment (water_density(), gravity(),
/// seabed_depth())
/// \param[in] start_ned node 0, NED [m] \param[in] end_ned node N, NED [m]
/// \param[out] status catenary status (optional)
/// \throws kelp::invalid_argument naming `start_ned` / `end_ned` when not finite.
/// \return a state at the model's time 0, at rest, without history; the end nodes exactly at
/// `start_ned` and `end_ned`.
/// \tparam Scalar double or float (deduced from the model).
/// \tparam Env the environment type (kelp/tether/lumped_mass.hpp).
template <typename Scalar, typename Env>
TetherState<Scalar> catenary_initial_state(const TetherModel<Scalar>& model, const Env& env,
                                           const Vector3<Scalar>& start_ned,
                                           const Vector3<Scalar>& end_ned,
                                           CatenaryStatus* status = nullptr) {
  check_all_finite(start_ned, "start_ned");
  check_all_finite(end_ned, "end_ned");
  const Scalar w =
      model.submerged_weight_per_length(Scalar(env.water_density()), Scalar(env.gravity()));
  const Scalar L = model.parameters().length;
  CatenaryOptions<Scalar> options;
  const double bed = double(value_of(Scalar(env.seabed_depth())));
  if (std::isfinite(bed) && value_of(start_ned.z()) <= bed && value_of(end_ned.z()) <= bed)
    options.seabed_depth = bed;
  const CatenaryShape<Scalar> shape = catenary_between(start_ned, end_ned, L, w, options);
  const CatenaryStatus st = shape.status();
  if (status) *status = st;
  if (!(shape.result().ok() || st == CatenaryStatus::taut))
    return straight_line_state(model, start_ned, end_ned);
  TetherState<Scalar> s(model);
  const int n = model.segments();
  for (int i = 0; i <= n; ++i) s.position.col(i) = shape.point_at(L * Scalar(i) / Scalar(n));
  // A buoyant line's inverted catenary may rise out of the water, where the line would not float:
  // such nodes start on the still-water surface instead.
  if (w < Scalar(0) && value_of(start_ned.z()) >= 0 && value_of(end_ned.z()) >= 0)
    for (int i = 0; i <= n; ++i) s.position(2, i) = std::max(s.position(2, i), Scalar(0));
  s.position.col(0) = start_ned;
  s.position.col(n) = end_ned;
  if (!all_finite(s.position)) return straight_line_state(model, start_ned, end_ned);
  return s;
}

/// \brief Sets every node's velocity to the water's (current + wave orbital velocity, as
/// `env.sample_water` gives it at the node's position and the state's time), so that a line laid
/// in moving water starts drifting with it instead of at rest: no drag impulse in its first step.
/// Positions, time and integrator history are left as they are. \param[in] model the tether
/// \param[in] env environment (`sample_water(points, t, velocity, acceleration)`)
/// \param[in,out] state the tether's state
/// \throws kelp::invalid_argument when the state's size does not match the model.
/// \tparam Scalar double or float (deduced from the model).
/// \tparam Env the environment type (kelp/tether/lumped_mass.hpp).
template <typename Scalar, typename Env>
void move_with_water(const TetherModel<Scalar>& model, const Env& env, TetherState<Scalar>& state) {
  KELP_CHECK(state.position.cols() == model.segments() + 1 &&
                 state.velocity.cols() == state.position.cols(),
             "move_with_water: the state does not match the model");
  Matrix3X<Scalar> acceleration(3, state.position.cols());
  env.sample_water(state.position, state.time, state.velocity, acceleration);
}

/// \brief Catenary initial state refined by `solve_static_equilibrium` with both ends fixed at
/// `start_ned`, `end_ned` (free ends of the model stay free). Returns the solve's result (check
/// `converged`); the state is written to `state` when the solve returns.
/// \throws as catenary_initial_state and solve_static_equilibrium, with `state` unchanged.
/// \tparam Scalar double or float (deduced from the model).
/// \tparam Env the environment type (kelp/tether/lumped_mass.hpp).
/// \param[in] model the tether.
/// \param[in,out] ws the workspace built for `model` (scratch of the solve).
/// \param[in] env the water (weight, buoyancy, seabed; currents load the line as in a step).
/// \param[in] start_ned node 0, NED [m].
/// \param[in] end_ned node N, NED [m].
/// \param[out] state the equilibrium (or the solve's last iterate when it did not converge).
/// \param[in] options the static solve's settings.
/// \return the solve's result (StaticResult: check `converged`).
template <typename Scalar, typename Env>
[[nodiscard]] StaticResult<Scalar> static_initial_state(const TetherModel<Scalar>& model,
                                                        TetherWorkspace<Scalar>& ws, const Env& env,
                                                        const Vector3<Scalar>& start_ned,
                                                        const Vector3<Scalar>& end_ned,
                                                        TetherState<Scalar>& state,
                                                        const StaticOptions<Scalar>& options = {}) {
  // Solved on a copy: `state` changes only when the solve returns.
  TetherState<Scalar> s = catenary_initial_state(model, env, start_ned, end_ned);
  const StaticResult<Scalar> result = solve_static_equilibrium(
      model, ws, env, s, TetherBoundary<Scalar>::fixed(start_ned, end_ned), options);
  state = std::move(s);
  return result;
}

}  // namespace kelp::tether

/// \brief The double-precision static solves in kelp's Environment (solve_static_equilibrium and
/// static_initial_state), for a compiled layer that instantiates them once, as
/// KELP_TETHER_INSTANCES does the step (kelp/tether/driver.hpp): kelp::sim declares them extern in
/// kelp/sim/instantiation.hpp. The expansion needs kelp/environment/environment.hpp.
#define KELP_TETHER_STATICS_INSTANCES(prefix)                                                   \
  prefix kelp::tether::StaticResult<double>                                                     \
  kelp::tether::solve_static_equilibrium<double, kelp::environment::Environment<double>>(       \
      const kelp::tether::TetherModel<double>&, kelp::tether::TetherWorkspace<double>&,         \
      const kelp::environment::Environment<double>&, kelp::tether::TetherState<double>&,        \
      const kelp::tether::TetherBoundary<double>&, const kelp::tether::StaticOptions<double>&); \
  prefix kelp::tether::StaticResult<double>                                                     \
  kelp::tether::static_initial_state<double, kelp::environment::Environment<double>>(           \
      const kelp::tether::TetherModel<double>&, kelp::tether::TetherWorkspace<double>&,         \
      const kelp::environment::Environment<double>&, const kelp::Vector3<double>&,              \
      const kelp::Vector3<double>&, kelp::tether::TetherState<double>&,                         \
      const kelp::tether::StaticOptions<double>&);
