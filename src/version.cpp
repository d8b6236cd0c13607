#include "kelp/sim/version.hpp"

#include "kelp/version.hpp"

namespace kelp {
namespace sim {

const char* version() noexcept { return KELP_VERSION_STRING; }

}  // namespace sim
}  // namespace kelp
