// kelp-sitl's embedded default world, shared by the program (main.cpp) and its tests, so that a
// test of the default world runs the world the program builds.
#pragma once

#include "kelp/sim/scenario.hpp"

namespace kelp_sitl {

/// The embedded default: kelp-tethered-pair's (the paper's moderate sea, a 10 m tether, the sea
/// ramped in over the scenario's `start.ramp`), but the ROV starts at the surface 4 m astern of
/// the boat, so that ArduSub has a dive to fly.
inline kelp::sim::Scenario default_scenario() {
  kelp::sim::Scenario s;
  s.auv_start = {-4.0, 0.0, 0.3};
  return s;
}

}  // namespace kelp_sitl
