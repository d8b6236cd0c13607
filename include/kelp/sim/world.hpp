/// \file
/// \brief The tethered pair a scenario describes: the system's parameters, its sea and the
/// vehicles' start poses.
///
/// Shared by every program on kelp::sim (kelp-tethered-pair, kelp-sweep, kelp-sitl), so that a
/// run flown by kelp's controllers and one flown by ArduPilot SITL are the same world. Part of the
/// optional `kelp::sim` component.
#pragma once

#include <string>

#include "kelp/environment/environment.hpp"
#include "kelp/sim/export.hpp"
#include "kelp/sim/instantiation.hpp"
#include "kelp/sim/scenario.hpp"
#include "kelp/system/presets.hpp"
#include "kelp/system/system.hpp"

namespace kelp {
namespace sim {

/// \brief What a scenario builds: the system's parameters, its sea and the vehicles' start.
/// `system::SystemModeld(parameters, environment)` is the system to step.
struct WorldSetup {
  kelp::system::SystemParametersd parameters;       ///< vehicles, tether, attachment points
  kelp::environment::Environmentd environment;      ///< the sea (waves, wind, current)
  kelp::system::presets::StartPoses<double> start;  ///< the vehicles' initial states
};

/// \brief The sea of a scenario: its waves, wind and current (a preset or custom sea, seeded,
/// with its start-up ramp and wave kernel), seabed and obstacles; `file` names the scenario in
/// errors. What world_setup() and the fleet's world (kelp/sim/fleet_run.hpp) run in.
/// \throws scenario_error naming the file and the JSON path.
/// \param sc the scenario \param file the scenario file's path (named in errors)
/// \return the environment (NED; time 0 at the run's start)
KELP_SIM_API kelp::environment::Environmentd scenario_environment(const Scenario& sc,
                                                                  const std::string& file);

/// \brief The system, the sea and the start poses of a scenario.
/// \param[in] sc the scenario \param[in] file names the scenario in errors
/// \return the system's parameters, its sea and the vehicles' start poses (NED)
/// \throws scenario_error when the tether cannot span the start poses or the scenario's kernel
/// path is one this CPU lacks; kelp::invalid_argument from the library for parameters it refuses
/// and for a bad `KELP_KERNEL` environment variable.
KELP_SIM_API WorldSetup world_setup(const Scenario& sc, const std::string& file);

/// \brief The state a run of the scenario starts from: `system::initial_state` (the vehicles at
/// their start poses, the tether's static shape between them) at t = 0 and, with the scenario's
/// `start_with_water`, the vehicles and the tether's nodes moving with the water there
/// (vehicle body velocity = the water's current + wave orbital velocity at the CO in body axes, no
/// rotation; tether::move_with_water). While the start ramp holds the sea at rest (t = 0 with a
/// ramp) that velocity is zero. Every program on kelp::sim starts here (kelp-tethered-pair,
/// kelp-sweep, kelp-sitl), so a run flown by kelp's controllers and one flown by SITL start alike.
/// \throws kelp::numerical_error when the tether's static shape does not converge.
/// \param model the system, built from `world` \param ws its workspace (overwritten)
/// \param world the world (world_setup()) \param sc the scenario (its `start_with_water`)
/// \return the state at t = 0
KELP_SIM_API kelp::system::SystemStated start_state(const kelp::system::SystemModeld& model,
                                                    kelp::system::SystemWorkspaced& ws,
                                                    const WorldSetup& world, const Scenario& sc);

}  // namespace sim
}  // namespace kelp
