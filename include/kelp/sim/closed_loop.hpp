/// \file
/// \brief The closed loop of the tethered pair: the system of a scenario flown by kelp's
/// controllers (the ROV's survey, the boat following it), sampled at the scenario's log rate, with
/// its error and tension statistics.
///
/// ClosedLoop is the steppable object (one call advances one step of 10 ms; the state, the
/// commands and the latest sample can be read between calls); simulate() runs a whole scenario
/// with an optional CSV log (RunLog) and returns the summary kelp-tethered-pair writes.
/// kelp-tethered-pair runs it once with the log; kelp-sweep runs it many times without. Part of the
/// optional `kelp::sim` component (`find_package(kelp CONFIG COMPONENTS sim)`, target kelp::sim).
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "kelp/control/controllers.hpp"
#include "kelp/control/tether_management.hpp"
#include "kelp/sim/entanglement.hpp"
#include "kelp/sim/export.hpp"
#include "kelp/sim/navigation.hpp"
#include "kelp/sim/run_log.hpp"
#include "kelp/sim/scenario.hpp"
#include "kelp/sim/summary.hpp"
#include "kelp/sim/turn_counter.hpp"
#include "kelp/sim/world.hpp"
#include "kelp/system/solver_stats.hpp"
#include "kelp/system/system.hpp"
#include "kelp/vehicle/thrusters.hpp"

namespace kelp {
namespace sim {

/// \brief What an observer of the run sees after every step (ClosedLoopOptions::on_step).
struct StepView {
  long step;                                  ///< steps taken so far (1 after the first)
  const kelp::system::SystemModeld& model;    ///< the system being run
  const kelp::system::SystemStated& state;    ///< its state after the step
  const kelp::system::SystemReportd& report;  ///< what the step did
};

/// \brief The error and tension statistics of a run, accumulated at every sample after t = 0.
///
/// The AUV's error is its distance from the survey leg it flies, the ASV's its horizontal distance
/// from the AUV; "late" values are over the second half of the run (after settling).
struct RunMetrics {
  long samples = 0;                     ///< samples accumulated
  long slack_samples = 0;               ///< samples with under 0.1 N at the AUV's end
  double auv_squared_error_sum = 0;     ///< Σ AUV error² [m²]
  double auv_max_error = 0;             ///< largest AUV error [m]
  double asv_squared_distance_sum = 0;  ///< Σ ASV distance² [m²]
  double asv_max_distance = 0;          ///< largest ASV distance [m]
  double max_tension = 0;               ///< largest end force, either end [N]
  double auv_tension_sum = 0;           ///< Σ end force at the AUV [N]
  double late_depth_error = 0;          ///< second half: largest |AUV depth − target depth| [m]
  double late_auv_error = 0;            ///< second half: largest AUV error [m]
  double late_asv_distance = 0;         ///< second half: largest ASV distance [m]

  /// \brief The count the means divide by (at least 1, so that an empty run gives zeros).
  /// \return max(1, samples)
  double count() const { return std::max<double>(1, static_cast<double>(samples)); }
  /// \brief RMS of the AUV's path error. \return the RMS [m] (0 without samples)
  double auv_rms_error() const { return std::sqrt(auv_squared_error_sum / count()); }
  /// \brief RMS of the ASV's horizontal distance to the AUV. \return the RMS [m]
  double asv_rms_distance() const { return std::sqrt(asv_squared_distance_sum / count()); }
  /// \brief Mean end force at the AUV. \return the mean [N]
  double auv_mean_tension() const { return auv_tension_sum / count(); }
  /// \brief Fraction of the samples with a slack tether at the AUV (under 0.1 N).
  /// \return the fraction, in [0, 1]
  double slack_fraction() const { return static_cast<double>(slack_samples) / count(); }
};

/// \brief Options of a ClosedLoop.
struct ClosedLoopOptions {
  /// Named in errors and in the summary.
  std::string scenario_file = "(embedded default)";
  /// Where samples (at the scenario's log rate) and tether snapshots (at its node rate) are
  /// written, the first ones (t = 0) when the loop is built; not owned, must outlive the loop;
  /// null: no log.
  RunLog* log = nullptr;
  /// Called after every step, before the new state is sampled (e.g. the soak test's checks);
  /// empty: nothing is called.
  std::function<void(const StepView&)> on_step;
  /// Called with every sample taken at the log rate (the rows of the log, t = 0 included), with
  /// or without a log; empty: nothing is called.
  std::function<void(const LogRow&)> on_sample;
};

/// \brief The tethered pair of a scenario flown by kelp's controllers, one step at a time.
///
/// Built from a scenario: the world (world_setup()), the system at its start state (start_state():
/// the sea ramped in, the vehicles and tether moving with the water), the AUV's
/// controller following the scenario's waypoints (by default a square at the mission depth from
/// the start) and the ASV's controller following the AUV. Every step (dt = 10 ms): the controllers'
/// commands (computed from the current state) drive the system through `system::step`; then the
/// new state is sampled (errors, thrusts, end forces), and at the scenario's log rate the sample
/// is accumulated into the metrics and written to the log. A run of `duration` is
/// `lround(duration / dt)` steps. No heap allocation in a step (without a log).
///
/// The loop holds references into itself (the controllers keep the models and allocations): it
/// can be neither copied nor moved; hold it by value or through a pointer.
class KELP_SIM_API ClosedLoop {
 public:
  /// The step [s].
  static constexpr double dt = 0.01;

  /// \brief The loop of a scenario, its world built by world_setup().
  /// \param sc the scenario (copied) \param options the log and observers (ClosedLoopOptions)
  /// \throws scenario_error, kelp::invalid_argument (see world_setup()).
  explicit ClosedLoop(const Scenario& sc, const ClosedLoopOptions& options = {})
      : ClosedLoop(sc, world_setup(sc, options.scenario_file), options) {}

  /// \brief The loop of a scenario over an already built world (e.g. one a program has adjusted).
  /// \param sc the scenario (copied; its controllers, rates, duration and mission are used)
  /// \param world the world to run (copied), e.g. world_setup(sc) adjusted
  /// \param options the log and observers (ClosedLoopOptions)
  /// \throws kelp::invalid_argument for a world the library refuses.
  ClosedLoop(const Scenario& sc, const WorldSetup& world, const ClosedLoopOptions& options = {});

  ClosedLoop(const ClosedLoop&) = delete;
  ClosedLoop& operator=(const ClosedLoop&) = delete;

  /// \brief Advances one step: applies the current commands, steps the system, calls `on_step`,
  /// then samples the new state (and logs it when due).
  /// \returns the system's report of the step.
  /// \throws kelp::error when the run is over (done()); kelp::invalid_argument,
  /// kelp::numerical_error from `system::step` (the state is then as it was).
  const kelp::system::SystemReportd& step();

  /// \brief Steps until the run is over.
  void run() {
    while (!done()) step();
  }

  /// \brief Steps for `seconds` of simulated time (rounded to whole steps), or until the run is
  /// over. \param seconds simulated time to run [s], finite and ≥ 0
  /// \returns the steps taken (fewer when the run ends first).
  /// \throws kelp::invalid_argument for a negative or non-finite `seconds`; what step() throws.
  long run_for(double seconds);

  /// \brief Whether the scenario's duration has been simulated.
  /// \return true once steps_taken() reaches total_steps()
  bool done() const { return k_ >= steps_; }
  /// \brief Steps taken so far. \return the count (0 before the first step)
  long steps_taken() const { return k_; }
  /// \brief Steps of the whole run. \return `lround(duration / dt)`
  long total_steps() const { return steps_; }
  /// \brief Simulation time. \return the state's time [s]
  double time() const { return state_.time; }

  /// \brief The scenario being run. \return the loop's copy
  const Scenario& scenario() const { return scenario_; }
  /// \brief The system being run. \return its model (parameters, environment)
  const kelp::system::SystemModeld& model() const { return model_; }
  /// \brief Its workspace. \return the loads and reports of the last step
  const kelp::system::SystemWorkspaced& workspace() const { return workspace_; }
  /// \brief Its state. \return the current state (vehicles NED/body, tether nodes NED [m])
  const kelp::system::SystemStated& state() const { return state_; }
  /// \brief The report of the last step. \return the report (zero before the first step)
  const kelp::system::SystemReportd& last_report() const { return report_; }
  /// \brief The AUV's waypoints. \return the waypoints, NED [m]
  const std::vector<kelp::Vector3<double>>& waypoints() const { return waypoints_; }
  /// \brief The AUV's controller. \return it (its settings, leg and integrators)
  const kelp::control::AuvController& auv_controller() const { return auv_; }
  /// \brief The ASV's controller. \return it (its settings and integrators)
  const kelp::control::AsvController& asv_controller() const { return asv_; }
  /// \brief The AUV's controller's command for the next step (applied unless overridden).
  /// \return the command (body wrench and per-thruster commands)
  const kelp::control::AuvCommand& auv_command() const { return *auv_command_; }
  /// \brief Flies the AUV by `command` instead of its controller from the next step on (e.g. a
  /// learning agent's action, kelp::sim::PairEnv): its per-thruster commands (the ESC's, as the
  /// controller's) drive the propulsion, or without propulsion its wrench is applied. The
  /// controller keeps running (its waypoint and leg bookkeeping still defines the path error of
  /// the metrics) but its commands are not applied. Not owned: it must outlive its use; it is
  /// read at every step, so it may be changed between steps. Null: the controller flies again.
  /// \param command the command to fly by, or nullptr
  void set_auv_override(const kelp::control::AuvCommand* command) { auv_override_ = command; }
  /// \brief The command overriding the AUV's controller. \return it, or nullptr
  const kelp::control::AuvCommand* auv_override() const { return auv_override_; }
  /// \brief Flies the ASV by `command` instead of its controller from the next step on; see
  /// set_auv_override(). Null: the controller flies again.
  /// \param command the command to fly by (not owned), or nullptr
  void set_asv_override(const kelp::control::AsvCommand* command) { asv_override_ = command; }
  /// \brief The command overriding the ASV's controller. \return it, or nullptr
  const kelp::control::AsvCommand* asv_override() const { return asv_override_; }
  /// \brief Commands the winch's payout rate [m/s] by `*rate` instead of its strategy from the
  /// next step on (e.g. a ROS 2 node's /tether/cmd_payout); the winch still limits it
  /// (tether::limited_payout_rate). Ignored without a winch. Not owned, read at every step.
  /// Null: the strategy commands it again.
  /// \param rate the commanded payout rate [m/s] (positive: paying out; not owned), or nullptr
  void set_winch_override(const double* rate) { winch_override_ = rate; }
  /// \brief The ASV's command for the next step. \return the command (applied unless overridden)
  const kelp::control::AsvCommand& asv_command() const { return *asv_command_; }
  /// \brief The sample of the current state (what a log row holds; its vehicle states point into
  /// this loop), updated after every step. \return the sample
  const LogRow& sample() const { return sample_; }
  /// \brief The statistics so far. \return the metrics (samples at the log rate)
  const RunMetrics& metrics() const { return metrics_; }
  /// \brief How hard the tether's solver has worked so far (every step's report summed).
  /// \return the statistics
  const kelp::system::SolverStatsd& solver_stats() const { return solver_stats_; }
  /// \brief The AUV's turns about the tether at its attachment (updated at every step).
  /// \return the counter
  const TurnCounter& turn_counter() const { return turns_; }
  /// \brief The tether's winding about each cylinder of the environment and its entanglement
  /// events (updated at every step; kelp/sim/entanglement.hpp). \return the monitor
  const EntanglementMonitor& entanglement() const { return entanglement_; }
  /// \brief The tether's partings so far (at most one per step; kelp/tether/failure.hpp).
  /// \return the partings in time order (empty while the line holds)
  const std::vector<kelp::tether::LineFailured>& line_failures() const { return failures_; }
  /// \brief The sensors and filters when the scenario's navigation mode is "sensors".
  /// \return them, or nullptr in "perfect" mode
  const PairNavigation* navigation() const { return navigation_.get(); }

  /// \brief The summary's `navigation` object: the mode, and with sensors the seed, the RMS
  /// errors of each vehicle's estimate over every step after t = 0 (position, 3-D and horizontal
  /// [m], heading [deg], body velocity [m/s]), the USBL's pings, losses and fixes used and the
  /// DVL's pings by mode. \return the object (the mode alone in "perfect" mode)
  NavigationSummary navigation_summary() const;

  /// \brief The summary's `entanglement` object: the thresholds, every cylinder's winding
  /// (`obstacles`: name, index, `max_abs_winding_rad`, `final_winding_rad`, the times of its
  /// first `entangled` and `pinned` events or null, its events) and all events in time order
  /// (`events`: event, time_s, obstacle, position_m, winding_rad or tension_difference_n).
  /// \return the object
  EntanglementSummary entanglement_summary() const;

  /// \brief The run's summary as kelp-tethered-pair writes it in summary.json, without the wall
  /// time (simulate() adds it) and the program's version: errors, tensions, slack fraction, the
  /// tether solver's work (`tether_solver`, see solver_summary()), final energy, the wave
  /// kernel's instruction path (`kernel`: "portable", "avx2" or "avx512") and the fingerprint of
  /// the C library's math (`math_library`), the scenario file and the scenario with every field
  /// as used. `tether` also holds the AUV's turns about the tether (`net_turns`,
  /// `max_abs_turns`: TurnCounter) and the line's partings (`line_failures`: time, segment,
  /// position, tension; empty while it holds). Before the end (done()), `completed` is false and
  /// `simulated_s` the time reached. \return the summary (wall time and version unset)
  RunSummary summary() const;

 private:
  friend struct CheckpointAccess;  // a run's checkpoint (kelp/sim/checkpoint.hpp)
  // The environment's cylinders as the entanglement monitor's axes.
  static std::vector<EntanglementAxis> entanglement_axes(const kelp::system::SystemModeld& model);
  static kelp::vehicle::ThrusterAllocationd auv_allocation();
  static kelp::vehicle::ThrusterAllocationd asv_allocation();
  static void set_gains(kelp::control::PidGains& g, const Gains& x);
  static kelp::control::AuvControllerSettings auv_settings(const Scenario& sc);
  static kelp::control::AsvControllerSettings asv_settings(const Scenario& sc);

  // The controllers' commands at the current state, its sample, and at the log and node rates
  // the metrics and the log.
  void observe();

  Scenario scenario_;
  ClosedLoopOptions options_;
  kelp::system::SystemModeld model_;
  kelp::system::SystemWorkspaced workspace_;
  kelp::system::SystemStated state_;
  kelp::vehicle::ThrusterAllocationd auv_thrusters_, asv_thrusters_;
  kelp::control::AuvController auv_;
  kelp::control::AsvController asv_;
  kelp::Vector3<double> start_;  // the AUV's start: where its first leg begins
  std::vector<kelp::Vector3<double>> waypoints_;
  long steps_, log_every_, node_every_, k_ = 0;
  kelp::system::SystemInputsd inputs_;
  kelp::system::SystemReportd report_;
  const kelp::control::AuvCommand* auv_command_ = nullptr;
  const kelp::control::AsvCommand* asv_command_ = nullptr;
  const kelp::control::AuvCommand* auv_override_ = nullptr;  // set_auv_override()
  const kelp::control::AsvCommand* asv_override_ = nullptr;  // set_asv_override()
  const double* winch_override_ = nullptr;                   // set_winch_override()
  LogRow sample_;
  RunMetrics metrics_;
  kelp::system::SolverStatsd solver_stats_;
  TurnCounter turns_;
  std::vector<kelp::tether::LineFailured> failures_;
  // Navigation from sensors ("sensors" mode); null: the controllers see the true state.
  std::unique_ptr<PairNavigation> navigation_;
  // The winch's strategy, its re-meshes so far, the line's mass and length at the start and
  // the range of its length.
  kelp::control::TetherManagementSettings winch_settings_;
  kelp::tether::RemeshReport<double> remesh_;
  double line_mass_start_ = 0, length_start_ = 0;
  double min_length_ = std::numeric_limits<double>::infinity(), max_length_ = 0;
  // The tether's winding about the environment's cylinders, and its entanglement events.
  EntanglementMonitor entanglement_;
};

/// \brief The summary of a run's tether solver (the summary's `tether_solver`): the integrator,
/// the Newton budget, whether the explicit safety net was on, the counts of `stats` and the
/// tolerance of a full tether sub-step (ImplicitOptions::acceleration_tolerance × max_tether_dt).
/// \param[in] stats the run's statistics \param[in] p the parameters of the system that ran
/// \return the summary (non-finite statistics as NaN)
KELP_SIM_API SolverSummary solver_summary(const kelp::system::SolverStatsd& stats,
                                          const kelp::system::SystemParametersd& p);

/// \brief Options of simulate().
struct SimulateOptions {
  /// Where to write timeseries.csv and nodes.csv (at the scenario's rates), created once the
  /// scenario is known to be valid; empty: no CSV.
  std::string log_dir;
  /// Called after every step with the steps taken, the run's steps and the simulation time
  /// (e.g. a program's progress bar); empty: nothing is called.
  std::function<void(long steps_taken, long total_steps, double time)> on_progress;
  std::string scenario_file = "(embedded default)";  ///< named in errors and in the summary
  /// Called after every step (e.g. the soak test's checks); empty: nothing is called.
  std::function<void(const StepView&)> on_step;
  /// Called with every sample at the log rate (ClosedLoopOptions::on_sample); empty: none.
  std::function<void(const LogRow&)> on_sample;
  /// Polled before every step, with stop_requested() (kelp/sim/stop.hpp): true stops the run
  /// there (e.g. Python's check for Ctrl-C); empty: stop_requested() alone.
  std::function<bool()> should_stop;
  /// With `log_dir` or `mcap_file`: also the run as a ROS 2 bag (RunBag, kelp/sim/run.hpp:
  /// every sample, the markers at the scenario's node rate), which checkpoints include.
  bool mcap = false;
  /// Where the bag goes; empty: `log_dir`/run.mcap.
  std::string mcap_file;
  /// Writes the run's checkpoint (kelp/sim/checkpoint.hpp) every this many simulated seconds
  /// (rounded to whole steps) and when the run is stopped; 0: none. Writing one allocates and
  /// flushes the files to disk (between two steps; the steps themselves still allocate nothing).
  /// [s]
  double checkpoint_every = 0;
  /// Where the checkpoint is written and read; empty: `log_dir`/checkpoint.bin.
  std::string checkpoint_file;
  /// Continues the run from its checkpoint instead of starting it: the scenario must be the
  /// one the run started with; its files in `log_dir` are truncated to the lengths the
  /// checkpoint records, and the run goes on from there, as if it had never stopped.
  bool resume = false;
};

/// \brief Runs a scenario to its end in a ClosedLoop and returns its summary (what
/// kelp-tethered-pair writes as summary.json, without the program's version): ClosedLoop::summary()
/// with the wall time [s] and the real-time factor.
///
/// Before every step it polls for a stop (stop_requested(), kelp/sim/stop.hpp, and
/// `o.should_stop`): a stopped run ends after the step it was in, closes its log whole and
/// returns the summary with `completed` false and the simulated time reached. With
/// `o.checkpoint_every`, it writes a checkpoint at that interval and at a stop; with `o.resume`
/// it continues from the checkpoint (kelp/sim/checkpoint.hpp).
/// \throws scenario_error, kelp::invalid_argument, kelp::numerical_error; kelp::error when the
/// log cannot be written; state_error for a checkpoint that cannot be resumed (nothing in
/// `log_dir` is then changed).
/// \param sc the scenario to run \param o the log, bag, checkpoint and observer options
/// \return the summary, `completed` false when stopped
KELP_SIM_API RunSummary simulate(const Scenario& sc, const SimulateOptions& o = {});

}  // namespace sim
}  // namespace kelp
