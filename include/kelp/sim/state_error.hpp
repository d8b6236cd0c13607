/// \file
/// \brief kelp::sim::state_error, what the state files' reader and writer throw
/// (kelp/sim/state_io.hpp), in a header of its own so that code reading kelp's archives need not
/// include the physics. Part of the compiled `kelp::sim` component.
#pragma once

#include "kelp/core/error.hpp"
#include "kelp/sim/export.hpp"

namespace kelp {
namespace sim {

/// \brief A state that cannot be saved or loaded: the message names the input (a path or
/// `state`) and what is wrong (e.g. `run.state: section 'TETH' #0: nodes: 12 where 11 are
/// expected`).
///
/// It is bad input, so it derives from kelp::invalid_argument (and so from kelp::error).
class KELP_SIM_API state_error : public invalid_argument {
 public:
  using invalid_argument::invalid_argument;
};

}  // namespace sim
}  // namespace kelp
