// kelp-sitl's embedded default world, shared by the program (main.cpp) and its tests, so that a
// test of the default world runs the world the program builds.
#pragma once

#include "kelp/sim/scenario.hpp"

namespace kelp_sitl {

/// The embedded default: kelp-tethered-pair's (the paper's moderate sea, Hs 3 m, a 10 m tether,
/// the sea ramped in over the scenario's `start.ramp`), the ROV 4 m astern of the boat and 8 m
/// down (scenarios/moderate.json is the same). Not at the surface: ArduSub moves its depth zero
/// up whenever its pressure sensor reads a height above z = 0 (ArduSub/sensors.cpp,
/// Sub::read_barometer), and a ROV floating in these waves rides every crest above it. Disarmed
/// and slightly buoyant, with no thrust, this ROV was still at least 3.1 m down 60 s after the
/// start (kelp-sitl with idle fake autopilots), time for kelp-mission to arm it and hold depth.
inline kelp::sim::Scenario default_scenario() {
  kelp::sim::Scenario s;
  s.auv_start = kelp::Vector3<double>(-4.0, 0.0, 8.0);
  return s;
}

}  // namespace kelp_sitl
