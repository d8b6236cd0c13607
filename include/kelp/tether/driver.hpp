/// \file
/// \brief Stepping a tether with a scheme chosen at run time: `step` (one step, dispatched on
/// `Integrator`) and `advance` (the sub-stepping driver, which restores the state on failure).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"

#include "kelp/tether/explicit.hpp"
#include "kelp/tether/implicit.hpp"
#include "kelp/tether/model.hpp"
#include "kelp/tether/state.hpp"
#include "kelp/tether/stepping.hpp"

namespace kelp::tether {

/// \brief One step of length `dt` [s] with the chosen integrator (dispatch).
/// \throws as the individual steps; kelp::invalid_argument for an Integrator value outside the
/// enumeration.
template <typename Scalar, typename Env>
StepReport<Scalar> step(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                        const Env& env, TetherState<Scalar>& state,
                        const TetherBoundary<Scalar>& boundary, double dt, Integrator integrator,
                        const ImplicitOptions<Scalar>& options = {}) {
  switch (integrator) {
    case Integrator::symplectic_euler:
      return step_symplectic_euler(model, ws, env, state, boundary, dt);
    case Integrator::rk2:
      return step_rk2(model, ws, env, state, boundary, dt);
    case Integrator::rk4:
      return step_rk4(model, ws, env, state, boundary, dt);
    case Integrator::implicit_euler:
      return step_implicit(model, ws, env, state, boundary, dt, false, options);
    case Integrator::bdf2:
      return step_implicit(model, ws, env, state, boundary, dt, true, options);
  }
  ::kelp::detail::throw_invalid_argument("integrator is not a kelp::tether::Integrator value");
}

/// \brief Sub-stepping driver: advances `state` by `duration` [s] in n = ⌈duration/max_dt⌉ equal
/// steps of the chosen integrator; the kinematic ends follow `boundary` (given at the current
/// time) through the interval. `ws.end_forces` holds the forces of the last sub-step,
/// `ws.end_impulse` the impulse on the ends summed over all of them. If any
/// sub-step fails (after its own retries, for the implicit schemes) or throws for any other reason
/// the state is restored to its value at entry, history included, and the error rethrown. No heap
/// allocation. \returns the sum of the sub-steps' reports (committed steps, Newton iterations,
/// worst residual, retries).
template <typename Scalar, typename Env>
StepReport<Scalar> advance(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                           const Env& env, TetherState<Scalar>& state,
                           const TetherBoundary<Scalar>& boundary, double duration, double max_dt,
                           Integrator integrator, const ImplicitOptions<Scalar>& options = {}) {
  check_positive(duration, "duration");
  check_positive(max_dt, "max_dt");
  const double ratio = std::ceil(duration / max_dt);
  KELP_CHECK(ratio <= double(std::numeric_limits<int>::max()),
             "max_dt too small for duration: more than INT_MAX sub-steps");
  const int n = std::max(1, static_cast<int>(ratio));
  const double h = duration / n;
  ws.entry_backup.save(state);
  StepReport<Scalar> report;
  EndForces<Scalar> impulse;
  try {
    for (int k = 0; k < n; ++k) {
      report += step(model, ws, env, state, boundary.after(Scalar(k * h)), h, integrator, options);
      impulse.on_start += ws.end_impulse.on_start;
      impulse.on_end += ws.end_impulse.on_end;
    }
  } catch (...) {
    ws.entry_backup.restore(state);
    throw;
  }
  ws.end_impulse = impulse;
  return report;
}

}  // namespace kelp::tether
