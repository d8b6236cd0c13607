/// \file
/// \brief How hard the tether's solver worked over a run: SolverStats, summed from the
/// SystemReport of every system step (`stats += system::step(...)`).
///
/// A run's output should say whether its numbers came from converged implicit steps, how many
/// Newton corrections they took, how many steps had to be split and how many were redone
/// explicitly (SystemParameters::explicit_fallback): the figures kelp-tethered-pair's
/// summary.json, kelp-sweep's results and kelp-sitl's summary report as `tether_solver`.
#pragma once

#include <algorithm>

#include "kelp/system/system.hpp"

namespace kelp::system {

/// \brief The tether solver's work summed over system steps. A fixed-size value: adding a
/// report allocates nothing.
///
/// "Step" is a system step (one `system::step` call). With the paper's settings (system steps
/// and `max_tether_dt` both 10 ms, no coupling corrections) a system step is one tether step
/// unless Newton's method failed and the step was split; in general it holds
/// ⌈dt / max_tether_dt⌉ tether sub-steps per coupling pass (`tether_steps` counts them).
/// \tparam Scalar double or float.
template <typename Scalar>
struct SolverStats {
  /// System steps added.
  long steps = 0;
  /// Tether steps committed (SystemReport::tether.substeps summed; the halves of a split step
  /// and the explicit sub-steps of a fallback count one each).
  long tether_steps = 0;
  /// Newton corrections, failed attempts included (0 for explicit tether schemes).
  long newton_iterations = 0;
  /// Most Newton corrections in one system step (its sub-steps and failed attempts included).
  int max_step_newton_iterations = 0;
  /// Implicit tether steps that did not converge at their first step length and were split
  /// (tether::StepReport::retries summed).
  long retried_steps = 0;
  /// Tether steps redone with RK4 after the implicit scheme failed even in its split steps
  /// (SystemReport::tether_fallbacks summed; 0 unless SystemParameters::explicit_fallback).
  long explicit_fallbacks = 0;
  /// Tether force evaluations, failed attempts included.
  long force_evaluations = 0;
  /// Worst final scaled Newton residual max_i |R_i|/a_i of a committed step [m/s]
  /// (tether::StepReport::residual; within ImplicitOptions::acceleration_tolerance × the
  /// sub-step when every step converged).
  Scalar worst_residual = Scalar(0);
  /// Worst final residual of the attempts that did not converge and were split [m/s]
  /// (tether::StepReport::rejected_residual; infinite when an attempt produced a non-finite
  /// state).
  Scalar worst_rejected_residual = Scalar(0);

  /// \brief Adds the work of one system step.
  /// \param r The report of one `system::step` call.
  /// \return *this.
  SolverStats& operator+=(const SystemReport<Scalar>& r) {
    ++steps;
    tether_steps += r.tether.substeps;
    newton_iterations += r.tether.newton_iterations;
    max_step_newton_iterations = std::max(max_step_newton_iterations, r.tether.newton_iterations);
    retried_steps += r.tether.retries;
    explicit_fallbacks += r.tether_fallbacks;
    force_evaluations += r.tether.force_evaluations;
    worst_residual = std::max(worst_residual, r.tether.residual);
    worst_rejected_residual = std::max(worst_rejected_residual, r.tether.rejected_residual);
    return *this;
  }

  /// \brief Adds another run's (or part of a run's) statistics: counts add up, maxima are the
  /// worst.
  /// \param o The statistics to add.
  /// \return *this.
  SolverStats& operator+=(const SolverStats& o) {
    steps += o.steps;
    tether_steps += o.tether_steps;
    newton_iterations += o.newton_iterations;
    max_step_newton_iterations = std::max(max_step_newton_iterations, o.max_step_newton_iterations);
    retried_steps += o.retried_steps;
    explicit_fallbacks += o.explicit_fallbacks;
    force_evaluations += o.force_evaluations;
    worst_residual = std::max(worst_residual, o.worst_residual);
    worst_rejected_residual = std::max(worst_rejected_residual, o.worst_rejected_residual);
    return *this;
  }

  /// \brief Mean Newton corrections per system step (0 before the first step).
  /// \return newton_iterations / steps.
  double mean_step_newton_iterations() const {
    return steps > 0 ? static_cast<double>(newton_iterations) / static_cast<double>(steps) : 0.0;
  }
  /// \brief Mean Newton corrections per committed tether step (0 before the first step).
  /// \return newton_iterations / tether_steps (failed attempts' corrections included).
  double mean_tether_step_newton_iterations() const {
    return tether_steps > 0
               ? static_cast<double>(newton_iterations) / static_cast<double>(tether_steps)
               : 0.0;
  }
};

using SolverStatsd = SolverStats<double>;  ///< SolverStats<double>
using SolverStatsf = SolverStats<float>;   ///< SolverStats<float>

}  // namespace kelp::system
