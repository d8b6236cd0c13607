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

/// \brief How step() advances a tether: the scheme and its Newton settings.
/// Built from its fields in order (`{Integrator::rk4}`, `{Integrator::bdf2, newton}`), each
/// defaulted (a constructor rather than an aggregate, so that giving the leading fields only does
/// not trip -Wmissing-field-initializers in users' builds).
/// \tparam Scalar double or float.
template <typename Scalar>
struct StepOptions {
  /// Time-stepping scheme.
  Integrator integrator = Integrator::bdf2;
  /// Newton settings of the implicit schemes (ignored by the explicit ones).
  ImplicitOptions<Scalar> implicit;

  /// \brief The options of the fields, in order.
  /// \param integrator_ the scheme (default BDF2).
  /// \param implicit_ the implicit schemes' Newton settings (default ImplicitOptions{}).
  StepOptions(Integrator integrator_ = Integrator::bdf2,  // NOLINT(google-explicit-constructor)
              const ImplicitOptions<Scalar>& implicit_ = {})
      : integrator(integrator_), implicit(implicit_) {}
};

/// \brief How advance() advances a tether: the longest sub-step, the scheme and its Newton
/// settings. Built from its fields in order (`{0.01, Integrator::rk4}`), each defaulted.
/// \tparam Scalar double or float.
template <typename Scalar>
struct AdvanceOptions {
  /// Longest sub-step [s], > 0: advance() takes ⌈duration / max_dt⌉ equal sub-steps.
  double max_dt = 0.01;
  /// Time-stepping scheme.
  Integrator integrator = Integrator::bdf2;
  /// Newton settings of the implicit schemes (ignored by the explicit ones).
  ImplicitOptions<Scalar> implicit;

  /// \brief The options of the fields, in order.
  /// \param max_dt_ the longest sub-step [s] (default 0.01; checked > 0 by advance()).
  /// \param integrator_ the scheme (default BDF2).
  /// \param implicit_ the implicit schemes' Newton settings (default ImplicitOptions{}).
  AdvanceOptions(double max_dt_ = 0.01,  // NOLINT(google-explicit-constructor)
                 Integrator integrator_ = Integrator::bdf2,
                 const ImplicitOptions<Scalar>& implicit_ = {})
      : max_dt(max_dt_), integrator(integrator_), implicit(implicit_) {}
};

/// \brief One step of length `dt` [s] with the scheme of `options` (dispatch to
/// step_symplectic_euler, step_rk2, step_rk4, step_implicit_euler or step_bdf2, which take the
/// same arguments): `step(model, ws, env, state, boundary, dt, options)`, kelp's calling
/// convention (model, workspace, environment, state, inputs, dt, options). After the step, a line
/// with a breaking strength parts where a segment's axial force exceeds it
/// (part_if_overloaded, kelp/tether/failure.hpp): StepReport::partings and
/// StepReport::failure say so.
/// \throws as the individual steps; kelp::invalid_argument for an Integrator value outside the
/// enumeration.
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
/// \param[in] options the scheme and its Newton settings.
/// \return the step's report (with partings = 1 and the failure when the line parted).
template <typename Scalar, typename Env>
StepReport<Scalar> step(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                        const Env& env, TetherState<Scalar>& state,
                        const TetherBoundary<Scalar>& boundary, double dt,
                        const StepOptions<Scalar>& options = {}) {
  const auto dispatch = [&]() -> StepReport<Scalar> {
    switch (options.integrator) {
      case Integrator::symplectic_euler:
        return step_symplectic_euler(model, ws, env, state, boundary, dt);
      case Integrator::rk2:
        return step_rk2(model, ws, env, state, boundary, dt);
      case Integrator::rk4:
        return step_rk4(model, ws, env, state, boundary, dt);
      case Integrator::implicit_euler:
        return step_implicit_euler(model, ws, env, state, boundary, dt, options.implicit);
      case Integrator::bdf2:
        return step_bdf2(model, ws, env, state, boundary, dt, options.implicit);
    }
    ::kelp::detail::throw_invalid_argument("integrator is not a kelp::tether::Integrator value");
  };
  StepReport<Scalar> report = dispatch();
  if (part_if_overloaded(model, state, report.failure)) {
    report.partings = 1;
    ws.end_evaluated = false;  // evaluated on the unparted line
  }
  return report;
}

/// \brief Sub-stepping driver: advances `state` by `duration` [s] in n = ⌈duration/max_dt⌉ equal
/// steps of the chosen integrator (`options`); the kinematic ends follow `boundary` (given at the
/// current time) through the interval. `ws.end_forces` holds the forces at the end of the last
/// sub-step, `ws.end_impulse` the impulse on the ends summed over all of them. An explicit scheme's
/// sub-step takes its predecessor's evaluation at the end state as its first stage (each sub-step's
/// boundary is its predecessor's moved on by one sub-step, so that they meet exactly). If any
/// sub-step fails (after its own retries, for the implicit schemes) or throws for any other reason
/// the state is restored to its value at entry, history included, and the error rethrown. No heap
/// allocation. \returns the sum of the sub-steps' reports (committed steps, Newton iterations,
/// worst residual, retries).
/// \tparam Scalar double or float (deduced from the model).
/// \tparam Env the environment type: kelp::environment::Environment or any type with its duck-typed
/// interface (kelp/tether/lumped_mass.hpp).
/// \param[in] model the tether.
/// \param[in,out] ws the workspace built for `model`; end_forces at the end, end_impulse summed.
/// \param[in] env the water.
/// \param[in,out] state advanced by `duration` on success, restored (history included) on failure.
/// \param[in] boundary the kinematic ends' motion from the state's time, NED (extrapolated over
/// the whole interval: constant acceleration).
/// \param[in] duration the interval [s], > 0.
/// \param[in] options the longest sub-step, the scheme and its Newton settings.
/// \throws kelp::invalid_argument for a duration or max_dt not finite and > 0, more than
/// INT_MAX sub-steps, or bad input to a step; kelp::numerical_error when a sub-step fails (the
/// state is restored first).
template <typename Scalar, typename Env>
StepReport<Scalar> advance(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                           const Env& env, TetherState<Scalar>& state,
                           const TetherBoundary<Scalar>& boundary, double duration,
                           const AdvanceOptions<Scalar>& options = {}) {
  const double max_dt = options.max_dt;
  check_positive(duration, "duration");
  check_positive(max_dt, "max_dt");
  const double ratio = std::ceil(duration / max_dt);
  KELP_CHECK(ratio <= double(std::numeric_limits<int>::max()),
             "max_dt too small for duration: more than INT_MAX sub-steps");
  const int n = std::max(1, static_cast<int>(ratio));
  const double h = duration / n;
  const StepOptions<Scalar> step_options(options.integrator, options.implicit);
  ws.entry_backup.save(state);
  StepReport<Scalar> report;
  EndForces<Scalar> impulse;
  const bool chained = !is_implicit(options.integrator);
  TetherBoundary<Scalar> sub = boundary.after(Scalar(0));
  try {
    for (int k = 0; k < n; ++k) {
      if (k > 0) sub = chained ? sub.after(Scalar(h)) : boundary.after(Scalar(k * h));
      report += step(model, ws, env, state, sub, h, step_options);
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

using StepOptionsd = StepOptions<double>;        ///< StepOptions<double>
using StepOptionsf = StepOptions<float>;         ///< StepOptions<float>
using AdvanceOptionsd = AdvanceOptions<double>;  ///< AdvanceOptions<double>
using AdvanceOptionsf = AdvanceOptions<float>;   ///< AdvanceOptions<float>

}  // namespace kelp::tether

/// \brief The double-precision tether step and sub-stepping driver in kelp's Environment, for a
/// compiled layer that instantiates them once: `KELP_TETHER_INSTANCES(template)` in one unit,
/// `KELP_TETHER_INSTANCES(extern template)` wherever they are called (kelp::sim does:
/// kelp/sim/instantiation.hpp; the expansion needs kelp/environment/environment.hpp). `prefix`
/// may carry attributes after `template`.
#define KELP_TETHER_INSTANCES(prefix)                                                    \
  prefix kelp::tether::StepReport<double>                                                \
  kelp::tether::step<double, kelp::environment::Environment<double>>(                    \
      const kelp::tether::TetherModel<double>&, kelp::tether::TetherWorkspace<double>&,  \
      const kelp::environment::Environment<double>&, kelp::tether::TetherState<double>&, \
      const kelp::tether::TetherBoundary<double>&, double,                               \
      const kelp::tether::StepOptions<double>&);                                         \
  prefix kelp::tether::StepReport<double>                                                \
  kelp::tether::advance<double, kelp::environment::Environment<double>>(                 \
      const kelp::tether::TetherModel<double>&, kelp::tether::TetherWorkspace<double>&,  \
      const kelp::environment::Environment<double>&, kelp::tether::TetherState<double>&, \
      const kelp::tether::TetherBoundary<double>&, double,                               \
      const kelp::tether::AdvanceOptions<double>&);
