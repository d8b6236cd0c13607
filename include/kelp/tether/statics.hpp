/// \file
/// \brief Static equilibrium of a tether by pseudo-transient continuation (repeated implicit
/// steps with the velocities reset, kelp/tether/implicit.hpp).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"

#include "kelp/tether/forces.hpp"
#include "kelp/tether/implicit.hpp"
#include "kelp/tether/model.hpp"
#include "kelp/tether/state.hpp"
#include "kelp/tether/stepping.hpp"

namespace kelp::tether {

/// \brief Settings of the static-equilibrium solve.
/// \tparam Scalar double or float.
template <typename Scalar>
struct StaticOptions {
  /// Converged when max_i |F_i| ≤ this [N]; ≤ 0 selects 1e-7 × the line's weight in air.
  Scalar force_tolerance = Scalar(0);
  /// Maximum pseudo steps (each one implicit step solved by Newton). A line that settles in a few
  /// dozen takes a few dozen; a buoyant line floating at the surface, whose nodes land there one
  /// by one, can take several hundred (a 15 m ROV tether: ~650).
  int max_iterations = 1000;
  /// First pseudo time step h [s] of the regularisation M/h² (grows as the residual falls).
  Scalar initial_pseudo_dt = Scalar(0.05);
};

/// \brief Outcome of the static-equilibrium solve.
/// \tparam Scalar double or float.
template <typename Scalar>
struct StaticResult {
  bool converged = false;  ///< residual below tolerance
  /// Pseudo steps attempted (each one implicit step solved by Newton; a step retried shorter
  /// counts again)
  int iterations = 0;
  Scalar residual = Scalar(0);  ///< final max_i |F_i| over free nodes [N]
};

/// \brief Static equilibrium F(x) = 0 of the free nodes (velocities zero, ends held at the
/// boundary positions) by pseudo-transient continuation: repeated backward-Euler steps (each
/// solved by Newton with the analytic block-tridiagonal Jacobian) with the velocities reset to
/// zero after every step, so that each step solves (M/h² + D_x + D_v/h) Δx = F(x + Δx) — the
/// mass term regularises slack and contact nonlinearities while h is small, and the iteration
/// becomes Newton's method on F(x) = 0 as h grows (doubling after every easy step, quartered and
/// retried after a step whose Newton solve did not converge). Drag from a current enters F.
/// Starts from `state` (e.g. the catenary); `state` ends at the last iterate with zero velocity
/// and unchanged time; `ws.end_forces` holds the static end forces.
/// \throws kelp::invalid_argument for bad input (a workspace not built for the model, a state or
/// boundary that does not fit or is not finite, StaticOptions with a NaN or infinite
/// force_tolerance, an initial_pseudo_dt not finite and > 0, max_iterations < 1), before the
/// state is touched; kelp::numerical_error if the iteration produces non-finite values (state
/// unchanged).
/// \tparam Scalar double or float (deduced from the model).
/// \tparam Env the environment type (kelp/tether/lumped_mass.hpp).
/// \param[in] model the tether.
/// \param[in,out] ws the workspace built for `model`; end_forces and end_node_forces hold the
/// static end forces, NED [N], on return.
/// \param[in] env the water, queried at the state's time.
/// \param[in,out] state the starting shape; on return the last iterate, at rest, its history
/// cleared, its time unchanged.
/// \param[in] boundary the end positions, NED [m] (velocities and accelerations ignored: the ends
/// are held still).
/// \param[in] options tolerance, pseudo-step limit, first pseudo step.
/// \return whether it converged, the pseudo steps taken and the final residual [N].
template <typename Scalar, typename Env>
[[nodiscard]] StaticResult<Scalar> solve_static_equilibrium(
    const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws, const Env& env,
    TetherState<Scalar>& state, const TetherBoundary<Scalar>& boundary,
    const StaticOptions<Scalar>& options = {}) {
  // Every check before the state is touched.
  detail::check_workspace(model, ws);
  check_state(model, state);
  check_boundary(boundary);
  check_finite(options.force_tolerance, "StaticOptions::force_tolerance");
  check_positive(options.initial_pseudo_dt, "StaticOptions::initial_pseudo_dt");
  KELP_CHECK(options.max_iterations >= 1, "StaticOptions::max_iterations must be >= 1");
  const int f0 = model.first_free_node(), f1 = model.last_free_node();
  Scalar tol = options.force_tolerance;
  if (!(tol > Scalar(0)))
    tol = Scalar(1e-7) * model.parameters().mass_per_length * model.parameters().length *
          Scalar(env.gravity());
  ImplicitOptions<Scalar> inner;
  inner.max_iterations = 6;
  const Scalar m_ref = model.node_mass(model.segments() / 2);
  // The inner residual is max_i h·|F_i|/a_i [m/s], a_i the node's isotropic mass (structural
  // plus added mass), not m_ref: this tolerance asks for |F_i| ≤ ½·tol·a_i/m_ref, half the
  // force tolerance for an interior node in air, looser where added mass or a point mass
  // makes a_i > m_ref (the outer loop checks |F_i| ≤ tol itself).
  // (acceleration_tolerance · h is the inner velocity tolerance.)
  inner.acceleration_tolerance = Scalar(0.5) * tol / m_ref;
  detail::check_implicit_options(inner);
  TetherBoundary<Scalar> b = boundary;
  b.start.velocity.setZero();
  b.end.velocity.setZero();
  b.start.acceleration.setZero();
  b.end.acceleration.setZero();
  detail::load_parted(state, ws);
  detail::load_clamps(model, boundary, ws);
  // Keep the entry state (no single step uses that backup) and iterate on `state` itself,
  // restoring it on error.
  ws.entry_backup.save(state);
  const double t_entry = state.time, carry_entry = state.time_carry;
  state.velocity.setZero();
  state.clear_history();
  detail::apply_boundary(model, b, Scalar(0), state.position, state.velocity);
  StaticResult<Scalar> result;
  Scalar h = options.initial_pseudo_dt;
  const Scalar h_max(1e6);
  try {
    for (int it = 0;; ++it) {
      compute_forces<false>(model, ws, env, t_entry, state.position, state.velocity);
      Scalar res(0);
      for (int i = f0; i <= f1; ++i) res = std::max(res, ws.force.col(i).cwiseAbs().maxCoeff());
      if (!(res == res))
        ::kelp::detail::throw_numerical_error("solve_static_equilibrium: non-finite force");
      result.residual = res;
      result.iterations = it;
      if (res <= tol) {
        result.converged = true;
        break;
      }
      if (it >= options.max_iterations) break;
      StepReport<Scalar> r;
      // A pseudo step that does not converge is not committed: retry it shorter.
      const bool taken =
          detail::try_implicit(model, ws, env, state, b, double(value_of(h)), false, inner, r);
      state.time = t_entry;
      state.time_carry = carry_entry;
      state.velocity.setZero();
      state.clear_history();
      if (!taken) {
        if (!(h > options.initial_pseudo_dt * Scalar(1e-6)))
          ::kelp::detail::throw_numerical_error(
              "solve_static_equilibrium: no pseudo step converges; the state is unchanged");
        h *= Scalar(0.25);
      } else if (r.newton_iterations <= 5) {  // an easy step: lengthen the next
        h = std::min(h_max, h * Scalar(2));
      }
    }
  } catch (...) {
    ws.entry_backup.restore(state);
    throw;
  }
  ws.end_forces = end_forces_from_workspace(model, ws, b);
  detail::set_end_node_forces(model, ws, b);
  return result;
}

using StaticOptionsd = StaticOptions<double>;  ///< StaticOptions<double>
using StaticOptionsf = StaticOptions<float>;   ///< StaticOptions<float>
using StaticResultd = StaticResult<double>;    ///< StaticResult<double>
using StaticResultf = StaticResult<float>;     ///< StaticResult<float>

}  // namespace kelp::tether
