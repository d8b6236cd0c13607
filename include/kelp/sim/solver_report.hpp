/// \file
/// \brief The `tether_solver` object of the programs' summaries (kelp-tethered-pair's
/// summary.json, kelp-sweep's per-run results, kelp-sitl's summary.json): a run's
/// system::SolverStats as JSON. Part of the optional `kelp::sim` component.
#pragma once

#include <cmath>
#include <nlohmann/json.hpp>

#include "kelp/system/solver_stats.hpp"
#include "kelp/system/system.hpp"
#include "kelp/tether/stepping.hpp"

namespace kelp {
namespace sim {

/// \brief How hard the tether's solver worked over a run, as JSON (the fields are documented in
/// examples/tethered_pair/README.md):
/// `integrator`, `newton_budget` (ImplicitOptions::max_iterations), `explicit_fallback` (whether
/// the safety net was on), `steps`, `tether_steps`, `newton_iterations`,
/// `newton_iterations_per_step_mean`, `newton_iterations_per_step_max`,
/// `newton_iterations_per_tether_step_mean`, `retried_steps`, `explicit_fallbacks`,
/// `force_evaluations`, `worst_residual_m_s`, `worst_rejected_residual_m_s` (null when an
/// attempt diverged to a non-finite state), `residual_tolerance_m_s` (the tolerance of a full
/// tether sub-step, ImplicitOptions::acceleration_tolerance × max_tether_dt).
/// \param[in] stats the run's statistics \param[in] p the parameters of the system that ran
inline nlohmann::json solver_summary(const kelp::system::SolverStatsd& stats,
                                     const kelp::system::SystemParametersd& p) {
  const auto finite_or_null = [](double x) {
    return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
  };
  nlohmann::json j;
  j["integrator"] = kelp::tether::integrator_name(p.tether_integrator);
  j["newton_budget"] = p.tether_options.max_iterations;
  j["explicit_fallback"] = p.explicit_fallback;
  j["steps"] = stats.steps;
  j["tether_steps"] = stats.tether_steps;
  j["newton_iterations"] = stats.newton_iterations;
  j["newton_iterations_per_step_mean"] = stats.mean_step_newton_iterations();
  j["newton_iterations_per_step_max"] = stats.max_step_newton_iterations;
  j["newton_iterations_per_tether_step_mean"] = stats.mean_tether_step_newton_iterations();
  j["retried_steps"] = stats.retried_steps;
  j["explicit_fallbacks"] = stats.explicit_fallbacks;
  j["force_evaluations"] = stats.force_evaluations;
  j["worst_residual_m_s"] = finite_or_null(stats.worst_residual);
  j["worst_rejected_residual_m_s"] = finite_or_null(stats.worst_rejected_residual);
  j["residual_tolerance_m_s"] = p.tether_options.acceleration_tolerance * p.max_tether_dt;
  return j;
}

}  // namespace sim
}  // namespace kelp
