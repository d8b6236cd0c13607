/// \file
/// \brief What readers of scenario files share: scenario_error (whose message names the file and
/// the JSON path), the PID gains of a scenario and the nesting-depth guard that parse_scenario
/// (kelp/sim/scenario.hpp) and the readers of files that embed scenarios (kelp-sweep's sweep
/// files) apply before parsing. Part of the compiled `kelp::sim` component.
#pragma once

#include <string>

#include "kelp/core/error.hpp"
#include "kelp/sim/export.hpp"

namespace kelp {
namespace sim {

/// \brief A scenario that cannot be used: the message names the file and the JSON path (e.g.
/// `scenario.json: /tether/length: expected a number in [0.5, 1000], got -3`).
///
/// It is bad user input, so it derives from kelp::invalid_argument (and so from kelp::error and
/// std::runtime_error): a program may catch it first to tell a bad file from a failed run.
class KELP_SIM_API scenario_error : public invalid_argument {
 public:
  using invalid_argument::invalid_argument;
};

/// \brief PID gains of one controller axis.
struct Gains {
  double kp;  ///< proportional gain
  double ki;  ///< integral gain
  double kd;  ///< derivative gain
};

/// \brief The deepest nesting of arrays and objects a scenario (or sweep) file may have; a scenario
/// needs 4. The library's JSON parser is iterative but copies, compares and dumps recursively, so
/// a file nested a hundred thousand levels deep would overflow the stack after parsing.
inline constexpr int max_json_depth = 64;

/// \brief Nesting depth of the arrays and objects in JSON text (brackets inside strings do not
/// count); the scan stops as soon as the depth exceeds `limit`. Exact for valid JSON. Readers of
/// files that embed scenarios (e.g. kelp-sweep's sweep files) check it before parsing.
/// \param text the JSON text (not validated) \param limit the depth at which to stop scanning
/// \return the deepest nesting found (0: no array or object), or limit + 1 once it exceeds
/// `limit`
KELP_SIM_API int json_depth(const std::string& text, int limit);

}  // namespace sim
}  // namespace kelp
