/// \file
/// \brief A run's summary as a JSON value, for the library's writers. Private to kelp::sim.
#pragma once

#include <nlohmann/json.hpp>

#include "kelp/sim/summary.hpp"

namespace kelp {
namespace sim {

/// \brief summary_json()'s value.
nlohmann::json summary_to_json(const RunSummary& s);
/// \brief solver_summary_json()'s value.
nlohmann::json solver_summary_to_json(const SolverSummary& s);

}  // namespace sim
}  // namespace kelp
