/// \file
/// \brief A fleet scenario's world and run (`"fleet"` in a scenario file: any vehicles, point
/// masses, anchors and tethers in the scenario's sea; kelp/system/fleet.hpp is the physics).
///
/// fleet_world() builds the fleet's parameters, environment and start from a scenario (vehicles
/// from presets, vehicle files or Gazebo models: kelp/sim/vehicle_file.hpp); run_fleet() runs it
/// closed loop (each vehicle's controller on its true state: an underwater vehicle with the AUV
/// controller, a surface vehicle with two thrusters with the ASV controller; winches at their
/// commanded payout rates) and writes the run's outputs:
/// - `timeseries.csv`: at the scenario's `output.log_rate`, the time and, per vehicle
///   `<name>.x .y .z .roll .pitch .yaw .u .v .w` (NED [m], [rad], body [m/s]), per point mass
///   `<name>.x .y .z`, per tether `<name>.tension_start .tension_end` (the force its ends
///   delivered over the step [N]) and `<name>.length` (unstretched [m]);
/// - `nodes.csv`: at `output.node_rate`, `t,tether,node,x,y,z` for every node of every tether;
/// - `summary.json`: per vehicle, point mass and tether, the solver, the run's speed (it also
///   echoes the scenario as run and each vehicle's hull, for the replay);
/// - `run.mcap` (the scenario's `output.mcap`, the default): the run as a ROS 2 bag with topics
///   per vehicle and per tether (kelp/sim/ros2/fleet.hpp), every logged sample, the markers at
///   the node rate.
/// kelp-tethered-pair then writes the replay page of every vehicle and tether from these files
/// (kelp/sim/replay.hpp). The plots are the pair's only (yet).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "kelp/environment/environment.hpp"
#include "kelp/sim/export.hpp"
#include "kelp/sim/instantiation.hpp"
#include "kelp/sim/scenario.hpp"
#include "kelp/sim/vehicle_file.hpp"
#include "kelp/system/fleet.hpp"

namespace kelp {
namespace sim {

/// \brief A fleet scenario's parts, ready to build a kelp::system::FleetModel.
struct FleetWorld {
  kelp::system::FleetParametersd parameters;            ///< vehicles, point masses, tethers
  kelp::environment::Environmentd environment;          ///< the scenario's sea
  std::vector<VehicleDescription> vehicles;             ///< each vehicle as loaded (file or preset)
  std::vector<kelp::vehicle::VehicleStated> start;      ///< each vehicle's start state
  std::vector<kelp::Vector3<double>> point_mass_start;  ///< each point mass's start [m]
  /// What the world changed in what it loaded, one sentence each naming the JSON path (a
  /// Gazebo model's water replaced by the scenario's sea: a model file's water is its world's).
  std::vector<std::string> notes;
};

/// \brief The fleet of `sc` (which must have one), `file` naming the scenario in errors and
/// locating its vehicle files. \throws scenario_error naming the file and the JSON path (an
/// unknown preset, a vehicle file's own errors, a vehicle whose water differs from the sea's,
/// a tether shorter than the distance between its ends).
/// \param sc the scenario (with `fleet` set) \param file the scenario file's path
/// \return the fleet's parameters, environment, vehicles and start (NED [m])
KELP_SIM_API FleetWorld fleet_world(const Scenario& sc, const std::string& file);

/// \brief The state a fleet run starts from: every tether at its static shape between its ends
/// (kelp::system::initial_state from the world's start poses), and, when the scenario says so
/// (`start_with_water`, the default), every body and node moving with the water at t = 0.
/// `model` is built from `w` (its parameters and environment); `file` names the scenario.
/// \param model the fleet's model, built from `w`
/// \param ws its workspace (used to evaluate the start; its contents are overwritten)
/// \param w the fleet's world (fleet_world()) \param sc the scenario \param file its path
/// \return the start state at t = 0 (NED, body velocities)
/// \throws scenario_error naming `/fleet/tethers` when a tether's static shape cannot be found.
KELP_SIM_API kelp::system::FleetStated fleet_start_state(const kelp::system::FleetModeld& model,
                                                         kelp::system::FleetWorkspaced& ws,
                                                         const FleetWorld& w, const Scenario& sc,
                                                         const std::string& file);

/// \brief What a fleet run did (also in summary.json).
struct FleetRunSummary {
  bool completed = true;        ///< the whole duration ran (false: stopped, kelp/sim/stop.hpp)
  double simulated_s = 0;       ///< simulated time [s] (reached, when stopped)
  double wall_s = 0;            ///< wall time of the loop [s]
  long steps = 0;               ///< system steps of 10 ms
  double newton_mean = 0;       ///< tether Newton iterations per step, all tethers
  int newton_max = 0;           ///< most in one step
  long retried_steps = 0;       ///< tether steps retried in sub-steps
  long explicit_fallbacks = 0;  ///< tether steps redone by RK4
  /// Per tether: largest end force [N], and the fraction of steps its far end was slack
  /// (< 0.5 N).
  std::vector<double> max_tension,
      slack_fraction;  ///< per tether: the fraction of steps its far end was slack (< 0.5 N)
  /// Per vehicle (NaN without a controller): the RMS distance to the point its controller
  /// steers to (its hold point, or the waypoint ahead during a survey) [m].
  std::vector<double> rms_position_error;
  std::vector<std::string> notes;  ///< FleetWorld::notes (also summary.json's `notes`)
};

/// \brief Runs the fleet scenario `sc` closed loop into the directory `out` (created), writing
/// timeseries.csv, nodes.csv, summary.json and (unless `sc.mcap` is false) run.mcap. `file`
/// names the scenario. Before every step it polls for a stop (stop_requested(),
/// kelp/sim/stop.hpp, and `should_stop` when given): a stopped run ends after the step it was
/// in, closes its files whole and writes summary.json with `"completed": false` and the
/// simulated time reached. The CSV files are written in whole lines at least once a simulated
/// second (LineFile), so a run killed mid-way leaves them ending on a whole line.
/// \throws scenario_error as fleet_world(); kelp::error when a step fails (the outputs so far
/// are closed whole).
/// \param sc the scenario (with `fleet` set) \param file the scenario file's path
/// \param out the output directory \param should_stop polled before every step (may be empty)
/// \return what the run did (as summary.json says it)
KELP_SIM_API FleetRunSummary run_fleet(const Scenario& sc, const std::string& file,
                                       const std::string& out,
                                       const std::function<bool()>& should_stop = {});

}  // namespace sim
}  // namespace kelp
