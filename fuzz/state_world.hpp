// The systems of fuzz_state_reader and of its seeds (make_state_seeds.cpp): the scenario's pair
// on a coarse 10 m tether with a winch (6-20 m) and both vehicles' thrusters and batteries, in a
// calm sea of 4 wave components, and the same pair as a fleet (kelp::system::fleet_of).
#pragma once

#include "kelp/sim/world.hpp"
#include "kelp/system/fleet.hpp"

namespace kelp_fuzz {

struct StateWorld {
  kelp::sim::Scenario scenario;
  kelp::sim::WorldSetup world;
  kelp::system::SystemModeld pair;
  kelp::system::SystemWorkspaced pair_ws;
  kelp::system::FleetModeld fleet;
  kelp::system::FleetWorkspaced fleet_ws;

  StateWorld()
      : scenario(make_scenario()),
        world(kelp::sim::world_setup(scenario, "fuzz_state_reader")),
        pair(world.parameters, world.environment),
        pair_ws(pair),
        fleet(kelp::system::fleet_of(world.parameters), world.environment),
        fleet_ws(fleet) {}

  static kelp::sim::Scenario make_scenario() {
    kelp::sim::Scenario sc;
    sc.sea = kelp::sim::Sea::calm;
    sc.wave_components = 4;
    sc.segment_length = 2.0;
    sc.winch.enabled = true;
    sc.winch.min_length = 6;
    sc.winch.max_length = 20;
    return sc;
  }
};

/// The first byte of fuzz_state_reader's inputs (the state file follows it).
enum StateInputFlags : std::uint8_t {
  fleet_file = 1,  ///< the fleet's reader (else the pair's)
  seal = 2,        ///< payload length and CRC-32 rewritten to fit the rest (reach the sections)
  with_model = 4,  ///< load_state(bytes, model) (else the model-free reader)
  step_once = 8,   ///< a state accepted with the model is stepped once
};

}  // namespace kelp_fuzz
