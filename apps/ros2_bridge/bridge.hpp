// kelp-tethered-pair --ros2: the tethered pair's run with live ROS 2 topics over DDS (Eclipse
// Cyclone DDS, the middleware of ROS 2 Humble's default rmw_cyclonedds_cpp), without ROS 2: the
// same messages as the run's MCAP bag (kelp/sim/ros2/messages.hpp), published with ROS 2's names,
// types and QoS, and subscriptions through which a ROS 2 node flies the pair (commands.hpp).
// The DDS side lives in bridge.cpp, so that no Cyclone header reaches the program.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "kelp/sim/run.hpp"
#include "kelp/sim/scenario.hpp"

namespace kelp_ros2 {

/// How the run meets ROS 2.
struct Ros2Options {
  /// false: the loop is paced to real time (times `speed`) and kelp publishes /clock.
  /// true (lockstep): kelp follows /clock: each rosgraph_msgs/Clock it receives is a target
  /// time, and kelp steps (10 ms each) until its time reaches it, publishes, and waits for the
  /// next; kelp does not publish /clock then (the clock's owner does).
  bool lockstep = false;
  /// Paced mode: simulated seconds per wall-clock second (1: real time).
  double speed = 1.0;
  /// Lockstep: the run ends (its summary written) after this long without a new /clock target
  /// [wall-clock s].
  double clock_timeout = 10.0;
  /// The DDS domain; negative: ROS_DOMAIN_ID from the environment, else 0 (as ROS 2 does).
  int domain = -1;
};

/// Runs a scenario as run_scenario() does (CSV log, summary.json in `run.out`) with the ROS 2
/// topics live; the summary has a `ros2` object (mode, domain, messages published per topic,
/// subscriptions' counters, publish cost) in summary.json. \returns the run's summary (as
/// run_scenario()'s). \throws as run_scenario(), and kelp::error when DDS cannot be set up.
kelp::sim::RunSummary run_with_ros2(const kelp::sim::Scenario& scenario,
                                    const kelp::sim::RunOptions& run, const Ros2Options& options);

}  // namespace kelp_ros2
