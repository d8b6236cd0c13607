/// \file
/// \brief The scenario reference (docs/scenario-reference.md), generated from the parser's table.
/// Private to kelp::sim and its documentation tools (tests/docs/scenario_reference.cpp).
#pragma once

#include <string>
#include <vector>

#include "kelp/sim/export.hpp"

namespace kelp {
namespace sim {
namespace detail {

/// \brief docs/scenario-reference.md's text: every key of a scenario file (the table
/// `scenario_fields` of src/scenario.cpp, walked with the Reference visitor over the default
/// scenario) with its type, unit, default and allowed values, then the examples of
/// scenario_reference_examples().
KELP_SIM_API std::string scenario_reference_markdown();

/// \brief The reference's example scenarios (JSON texts), each of which parse_scenario reads.
KELP_SIM_API std::vector<std::string> scenario_reference_examples();

}  // namespace detail
}  // namespace sim
}  // namespace kelp
