/// \file
/// \brief The scenario as a JSON value, for the library's writers (the summary embeds it).
/// Private to kelp::sim.
#pragma once

#include <nlohmann/json.hpp>

#include "kelp/sim/scenario.hpp"

namespace kelp {
namespace sim {

/// \brief The scenario as JSON (scenario_json()'s value).
nlohmann::json scenario_to_json(const Scenario& s);

}  // namespace sim
}  // namespace kelp
