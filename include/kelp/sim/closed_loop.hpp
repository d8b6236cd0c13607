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
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "kelp/control/controllers.hpp"
#include "kelp/control/tether_management.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/kernel_path.hpp"
#include "kelp/nav/pair.hpp"
#include "kelp/sim/entanglement.hpp"
#include "kelp/sim/run_log.hpp"
#include "kelp/sim/scenario.hpp"
#include "kelp/sim/solver_report.hpp"
#include "kelp/sim/turn_counter.hpp"
#include "kelp/sim/world.hpp"
#include "kelp/system/presets.hpp"
#include "kelp/system/solver_stats.hpp"
#include "kelp/system/system.hpp"
#include "kelp/vehicle/presets.hpp"
#include "kelp/vehicle/thrusters.hpp"

namespace kelp {
namespace sim {

namespace detail {
/// Distance from p to the segment a–b.
inline double distance_to_segment(const kelp::Vector3<double>& p, const kelp::Vector3<double>& a,
                                  const kelp::Vector3<double>& b) {
  const kelp::Vector3<double> ab = b - a;
  const double l2 = ab.squaredNorm();
  const double s = l2 > 0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (a + s * ab - p).norm();
}
}  // namespace detail

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
  double count() const { return std::max<double>(1, static_cast<double>(samples)); }
  /// \brief RMS of the AUV's path error [m].
  double auv_rms_error() const { return std::sqrt(auv_squared_error_sum / count()); }
  /// \brief RMS of the ASV's horizontal distance to the AUV [m].
  double asv_rms_distance() const { return std::sqrt(asv_squared_distance_sum / count()); }
  /// \brief Mean end force at the AUV [N].
  double auv_mean_tension() const { return auv_tension_sum / count(); }
  /// \brief Fraction of the samples with a slack tether at the AUV (under 0.1 N).
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
class ClosedLoop {
 public:
  /// The step [s].
  static constexpr double dt = 0.01;

  /// \brief The loop of a scenario, its world built by world_setup().
  /// \throws scenario_error, kelp::invalid_argument (see world_setup()).
  explicit ClosedLoop(const Scenario& sc, const ClosedLoopOptions& options = {})
      : ClosedLoop(sc, world_setup(sc, options.scenario_file), options) {}

  /// \brief The loop of a scenario over an already built world (e.g. one a program has adjusted).
  /// \throws kelp::invalid_argument for a world the library refuses.
  ClosedLoop(const Scenario& sc, const WorldSetup& world, const ClosedLoopOptions& options = {})
      : scenario_(sc),
        options_(options),
        model_(world.parameters, world.environment),
        workspace_(model_),
        state_(start_state(model_, workspace_, world, sc)),
        rov_thrusters_(rov_allocation()),
        boat_thrusters_(boat_allocation()),
        auv_(model_.auv(), rov_thrusters_, auv_settings(sc)),
        asv_(model_.asv(), boat_thrusters_, asv_settings(sc)),
        start_(state_.auv.position),
        steps_(std::lround(sc.duration / dt)),
        log_every_(std::max(1L, std::lround(1.0 / (sc.log_rate * dt)))),
        node_every_(std::max(1L, std::lround(1.0 / (sc.node_rate * dt)))),
        entanglement_(entanglement_axes(model_), sc.entanglement,
                      0.5 * model_.tether().parameters().diameter) {
    waypoints_ = sc.waypoints;
    if (waypoints_.empty()) {
      const kelp::Vector3<double> s0(start_.x(), start_.y(), sc.depth);
      const double a = sc.square_side;
      waypoints_ = {s0 + kelp::Vector3<double>(a, 0, 0), s0 + kelp::Vector3<double>(a, a, 0),
                    s0 + kelp::Vector3<double>(0, a, 0), s0};
    }
    auv_.follow(waypoints_);
    if (sc.asv_station) {
      const kelp::Matrix3<double> r = state_.asv.attitude.toRotationMatrix();
      asv_.station(state_.asv.position, std::atan2(r(1, 0), r(0, 0)));
    } else {
      asv_.follow_auv();
    }
    // At most one parting per segment: no allocation in a step when the line parts.
    failures_.reserve(std::size_t(model_.tether().segments()));
    if (sc.winch.enabled) {
      kelp::control::TetherManagementSettings& w = winch_settings_;
      w.strategy = kelp::control::winch_strategy_from_name(sc.winch_strategy);
      w.tension_low = sc.winch.tension_low;
      w.tension_high = sc.winch.tension_high;
      w.tension_gain = sc.winch.tension_gain;
      w.slack = sc.winch.slack;
      w.extra_length = sc.winch.extra_length;
      w.length_per_depth = sc.winch.length_per_depth;
      w.length_per_offset = sc.winch.length_per_offset;
      w.length_gain = sc.winch.length_gain;
      kelp::control::validate(w);
    }
    line_mass_start_ = kelp::tether::line_mass(model_.tether_of(state_), state_.tether);
    length_start_ = kelp::tether::unstretched_length(model_.tether_of(state_), state_.tether);
    if (sc.navigation.mode == "sensors")
      navigation_ = std::make_unique<kelp::nav::PairNavigation>(sc.navigation.sensors,
                                                                sc.navigation.seed, model_, state_);
    observe();
  }

  ClosedLoop(const ClosedLoop&) = delete;
  ClosedLoop& operator=(const ClosedLoop&) = delete;

  /// \brief Advances one step: applies the current commands, steps the system, calls `on_step`,
  /// then samples the new state (and logs it when due).
  /// \returns the system's report of the step.
  /// \throws kelp::error when the run is over (done()); kelp::invalid_argument,
  /// kelp::numerical_error from `system::step` (the state is then as it was).
  const kelp::system::SystemReportd& step() {
    if (done())
      throw kelp::error("ClosedLoop::step: the run is over (" + std::to_string(steps_) +
                        " steps of the scenario's duration)");
    // With propulsion, the controllers' per-thruster commands drive the thrusters (lag, battery);
    // without, their wrench is applied directly.
    // The controllers' chains have the ESC's 1100–1900 µs mapping (their commands are the ESC's);
    // the propulsion takes the vehicle's PWM mapping's (e.g. the BlueBoat's 1000–2000 µs).
    const auto to_vehicle = [](const kelp::vehicle::PropulsionModeld& pm, const auto& esc,
                               kelp::vehicle::ThrusterVector<double>& u) {
      const auto& pp = pm.parameters();
      u.resize(esc.size());
      for (Eigen::Index i = 0; i < esc.size(); ++i)
        u(i) = esc(i) > 0.0 ? esc(i) / pp.esc_scale_forward : esc(i) / pp.esc_scale_reverse;
    };
    const kelp::control::AuvCommand& auv = auv_override_ ? *auv_override_ : *auv_command_;
    if (const auto* pm = model_.auv_propulsion())
      to_vehicle(*pm, auv.command, inputs_.auv_commands);
    else
      inputs_.auv.tau = auv.wrench;
    const kelp::control::AsvCommand& asv = asv_override_ ? *asv_override_ : *asv_command_;
    if (const auto* pm = model_.asv_propulsion())
      to_vehicle(*pm, asv.command, inputs_.asv_commands);
    else
      inputs_.asv.tau = asv.wrench;
    if (winch_override_ && model_.winch()) inputs_.winch_payout_rate = *winch_override_;
    report_ = kelp::system::step(model_, workspace_, state_, inputs_, dt);
    solver_stats_ += report_;
    if (report_.tether.partings > 0) {
      // The line parted in this step (kelp/tether/failure.hpp): kept for the summary and logged.
      failures_.push_back(report_.tether.failure);
      if (options_.log) options_.log->line_parted(report_.tether.failure);
    }
    remesh_ += report_.remesh;
    ++k_;
    if (options_.on_step) options_.on_step(StepView{k_, model_, state_, report_});
    observe();
    return report_;
  }

  /// \brief Steps until the run is over.
  void run() {
    while (!done()) step();
  }

  /// \brief Steps for `seconds` of simulated time (rounded to whole steps), or until the run is
  /// over. \returns the steps taken.
  long run_for(double seconds) {
    KELP_CHECK(std::isfinite(seconds) && seconds >= 0,
               "ClosedLoop::run_for: seconds must be finite and non-negative");
    const long n = std::min(std::lround(seconds / dt), steps_ - k_);
    for (long i = 0; i < n; ++i) step();
    return n;
  }

  /// \brief True once the scenario's duration has been simulated.
  bool done() const { return k_ >= steps_; }
  /// \brief Steps taken so far.
  long steps_taken() const { return k_; }
  /// \brief Steps of the whole run, `lround(duration / dt)`.
  long total_steps() const { return steps_; }
  /// \brief Simulation time [s].
  double time() const { return state_.time; }

  /// \brief The scenario being run.
  const Scenario& scenario() const { return scenario_; }
  /// \brief The system being run.
  const kelp::system::SystemModeld& model() const { return model_; }
  /// \brief Its workspace (loads and reports of the last step).
  const kelp::system::SystemWorkspaced& workspace() const { return workspace_; }
  /// \brief Its state.
  const kelp::system::SystemStated& state() const { return state_; }
  /// \brief The report of the last step (zero before the first).
  const kelp::system::SystemReportd& last_report() const { return report_; }
  /// \brief The AUV's waypoints (NED [m]).
  const std::vector<kelp::Vector3<double>>& waypoints() const { return waypoints_; }
  /// \brief The AUV's controller.
  const kelp::control::AuvController& auv_controller() const { return auv_; }
  /// \brief The ASV's controller.
  const kelp::control::AsvController& asv_controller() const { return asv_; }
  /// \brief The AUV's controller's command for the next step (applied unless overridden).
  const kelp::control::AuvCommand& auv_command() const { return *auv_command_; }
  /// \brief Flies the AUV by `command` instead of its controller from the next step on (e.g. a
  /// learning agent's action, kelp::sim::PairEnv): its per-thruster commands (the ESC's, as the
  /// controller's) drive the propulsion, or without propulsion its wrench is applied. The
  /// controller keeps running (its waypoint and leg bookkeeping still defines the path error of
  /// the metrics) but its commands are not applied. Not owned: it must outlive its use; it is
  /// read at every step, so it may be changed between steps. Null: the controller flies again.
  void set_auv_override(const kelp::control::AuvCommand* command) { auv_override_ = command; }
  /// \brief The command overriding the AUV's controller, or null.
  const kelp::control::AuvCommand* auv_override() const { return auv_override_; }
  /// \brief Flies the ASV by `command` instead of its controller from the next step on; see
  /// set_auv_override(). Null: the controller flies again.
  void set_asv_override(const kelp::control::AsvCommand* command) { asv_override_ = command; }
  /// \brief The command overriding the ASV's controller, or null.
  const kelp::control::AsvCommand* asv_override() const { return asv_override_; }
  /// \brief Commands the winch's payout rate [m/s] by `*rate` instead of its strategy from the
  /// next step on (e.g. a ROS 2 node's /tether/cmd_payout); the winch still limits it
  /// (tether::limited_payout_rate). Ignored without a winch. Not owned, read at every step.
  /// Null: the strategy commands it again.
  void set_winch_override(const double* rate) { winch_override_ = rate; }
  /// \brief The ASV's command for the next step.
  const kelp::control::AsvCommand& asv_command() const { return *asv_command_; }
  /// \brief The sample of the current state (what a log row holds; its vehicle states point into
  /// this loop), updated after every step.
  const LogRow& sample() const { return sample_; }
  /// \brief The statistics so far.
  const RunMetrics& metrics() const { return metrics_; }
  /// \brief How hard the tether's solver has worked so far (every step's report summed).
  const kelp::system::SolverStatsd& solver_stats() const { return solver_stats_; }
  /// \brief The AUV's turns about the tether at its attachment (updated at every step).
  const TurnCounter& turn_counter() const { return turns_; }
  /// \brief The tether's winding about each cylinder of the environment and its entanglement
  /// events (updated at every step; kelp/sim/entanglement.hpp).
  const EntanglementMonitor& entanglement() const { return entanglement_; }
  /// \brief The tether's partings so far (at most one per step; kelp/tether/failure.hpp).
  const std::vector<kelp::tether::LineFailured>& line_failures() const { return failures_; }
  /// \brief The sensors and filters when the scenario's navigation mode is "sensors", else null.
  const kelp::nav::PairNavigation* navigation() const { return navigation_.get(); }

  /// \brief The summary's `navigation` object: the mode, and with sensors the seed, the RMS
  /// errors of each vehicle's estimate over every step after t = 0 (position, 3-D and horizontal
  /// [m], heading [deg], body velocity [m/s]), the USBL's pings, losses and fixes used and the
  /// DVL's pings by mode.
  nlohmann::json navigation_summary() const {
    nlohmann::json n = {{"mode", scenario_.navigation.mode}};
    if (!navigation_) return n;
    const kelp::nav::PairNavigation& v = *navigation_;
    const double deg = 180.0 / kelp::pi;
    n["seed"] = scenario_.navigation.seed;
    n["auv_rms_position_error_m"] = v.auv_errors().rms_position();
    n["auv_rms_horizontal_error_m"] = v.auv_errors().rms_horizontal();
    n["auv_max_position_error_m"] = v.auv_errors().max_position;
    n["auv_rms_heading_error_deg"] = v.auv_errors().rms_heading() * deg;
    n["auv_rms_velocity_error_m_s"] = v.auv_errors().rms_velocity();
    n["asv_rms_position_error_m"] = v.asv_errors().rms_position();
    n["asv_rms_horizontal_error_m"] = v.asv_errors().rms_horizontal();
    n["asv_max_position_error_m"] = v.asv_errors().max_position;
    n["asv_rms_heading_error_deg"] = v.asv_errors().rms_heading() * deg;
    n["asv_rms_velocity_error_m_s"] = v.asv_errors().rms_velocity();
    n["usbl"] = {
        {"pings", v.usbl_pings()}, {"dropouts", v.usbl_dropouts()}, {"fixes_used", v.usbl_fixes()}};
    n["dvl_pings"] = {{"bottom", v.dvl_pings(kelp::nav::DvlMode::bottom)},
                      {"water", v.dvl_pings(kelp::nav::DvlMode::water)},
                      {"none", v.dvl_pings(kelp::nav::DvlMode::none)}};
    return n;
  }

  /// \brief The summary's `entanglement` object: the thresholds, every cylinder's winding
  /// (`obstacles`: name, index, `max_abs_winding_rad`, `final_winding_rad`, the times of its
  /// first `entangled` and `pinned` events or null, its events) and all events in time order
  /// (`events`: event, time_s, obstacle, position_m, winding_rad or tension_difference_n).
  nlohmann::json entanglement_summary() const {
    const EntanglementMonitor& m = entanglement_;
    const EntanglementSettings& x = m.settings();
    nlohmann::json e;
    e["settings"] = {{"wrap_threshold_rad", x.wrap_threshold},
                     {"wrap_hysteresis_rad", x.wrap_hysteresis},
                     {"contact_margin_m", x.contact_margin},
                     {"pin_slip_speed_m_s", x.pin_slip_speed},
                     {"pin_tension_difference_n", x.pin_tension_difference},
                     {"pin_hold_time_s", x.pin_hold_time}};
    const auto time_or_null = [](double t) {
      return std::isnan(t) ? nlohmann::json() : nlohmann::json(t);
    };
    const auto event_json = [&](const EntanglementEvent& v) {
      nlohmann::json j = {{"event", event_name(v.kind)},
                          {"time_s", v.time},
                          {"obstacle", m.axes()[std::size_t(v.obstacle)].name},
                          {"position_m", {v.position.x(), v.position.y(), v.position.z()}}};
      if (v.kind == EntanglementEvent::Kind::entangled)
        j["winding_rad"] = v.value;
      else
        j["tension_difference_n"] = v.value;
      return j;
    };
    nlohmann::json obstacles = nlohmann::json::array();
    for (std::size_t k = 0; k < m.axes().size(); ++k) {
      const ObstacleWinding& w = m.obstacle(k);
      nlohmann::json events = nlohmann::json::array();
      for (const EntanglementEvent& v : m.events())
        if (std::size_t(v.obstacle) == k) events.push_back(event_json(v));
      obstacles.push_back({{"name", m.axes()[k].name},
                           {"index", m.axes()[k].index},
                           {"max_abs_winding_rad", w.max_abs_winding},
                           {"final_winding_rad", w.winding},
                           {"entangled_s", time_or_null(w.first_entangled)},
                           {"pinned_s", time_or_null(w.first_pinned)},
                           {"events", events}});
    }
    e["obstacles"] = obstacles;
    nlohmann::json all = nlohmann::json::array();
    for (const EntanglementEvent& v : m.events()) all.push_back(event_json(v));
    e["events"] = all;
    e["dropped_events"] = m.dropped_events();
    return e;
  }

  /// \brief The run's summary as kelp-tethered-pair writes it in summary.json, without the wall
  /// time (simulate() adds it) and the program's version: errors, tensions, slack fraction, the
  /// tether solver's work (`tether_solver`, see solver_summary()), final energy, the wave
  /// kernel's instruction path (`kernel`: "portable", "avx2" or "avx512") and the fingerprint of
  /// the C library's math (`math_library`), the scenario file and the scenario with every field
  /// as used. `tether` also holds the AUV's turns about the tether (`net_turns`,
  /// `max_abs_turns`: TurnCounter) and the line's partings (`line_failures`: time, segment,
  /// position, tension; empty while it holds).
  nlohmann::json summary() const {
    const RunMetrics& m = metrics_;
    nlohmann::json s;
    s["simulated_s"] = scenario_.duration;
    s["auv"] = {{"rms_path_error_m", m.auv_rms_error()},
                {"max_path_error_m", m.auv_max_error},
                {"waypoints_reached", auv_.next_waypoint()},
                {"second_half_max_depth_error_m", m.late_depth_error},
                {"second_half_max_path_error_m", m.late_auv_error}};
    s["asv"] = {{"rms_distance_to_auv_m", m.asv_rms_distance()},
                {"max_distance_to_auv_m", m.asv_max_distance},
                {"second_half_max_distance_to_auv_m", m.late_asv_distance}};
    s["tether"] = {{"max_tension_n", m.max_tension},
                   {"mean_tension_auv_n", m.auv_mean_tension()},
                   {"slack_fraction", m.slack_fraction()},
                   {"net_turns", turns_.turns()},
                   {"max_abs_turns", turns_.max_abs_turns()}};
    // The line's partings: when, which segment, where, under what force.
    nlohmann::json parted = nlohmann::json::array();
    for (const auto& f : failures_)
      parted.push_back({{"time_s", f.time},
                        {"segment", f.segment},
                        {"position_m", {f.position.x(), f.position.y(), f.position.z()}},
                        {"tension_n", f.tension}});
    s["tether"]["line_failures"] = parted;
    // The line's structural mass and unstretched length at the start and the end (they differ
    // with a winch, which pays line out and reels it in).
    const auto& line = model_.tether_of(state_);
    s["tether"]["line_mass_start_kg"] = line_mass_start_;
    s["tether"]["line_mass_end_kg"] = kelp::tether::line_mass(line, state_.tether);
    s["tether"]["length_start_m"] = length_start_;
    s["tether"]["length_end_m"] = kelp::tether::unstretched_length(line, state_.tether);
    if (model_.winch())
      s["tether"]["winch"] = {
          {"strategy", kelp::control::winch_strategy_name(winch_settings_.strategy)},
          {"nodes_inserted", remesh_.inserted},
          {"nodes_removed", remesh_.removed},
          {"remesh_kinetic_energy_lost_j", remesh_.kinetic_energy_lost},
          {"min_length_m", min_length_},
          {"max_length_m", max_length_}};
    s["tether_solver"] = solver_summary(solver_stats_, model_.parameters());
    s["energy_j"] = kelp::system::energy(model_, state_).total();
    // Propulsion: the energy each vehicle's battery delivered [Wh] and its final state of charge.
    const auto battery = [&](const kelp::vehicle::PropulsionModeld* pm,
                             const kelp::vehicle::PropulsionStated& x, nlohmann::json& out) {
      if (pm == nullptr) return;
      out["energy_wh"] = x.battery.energy_drawn / 3600.0;
      out["final_soc"] = kelp::vehicle::state_of_charge(pm->parameters().battery, x.battery);
    };
    battery(model_.auv_propulsion(), state_.auv_propulsion, s["auv"]);
    battery(model_.asv_propulsion(), state_.asv_propulsion, s["asv"]);
    // What the numbers depend on beyond the scenario: the wave kernel's instruction path and the
    // C library's math (kelp/core/kernel_path.hpp); kelp-sweep merge compares them across runs.
    s["kernel"] = kelp::simd::kernel_name(model_.environment().waves().active_kernel());
    s["math_library"] = kelp::simd::math_library_fingerprint();
    s["navigation"] = navigation_summary();
    s["entanglement"] = entanglement_summary();
    s["scenario_file"] = options_.scenario_file;
    s["scenario"] = to_json(scenario_);
    return s;
  }

 private:
  // The environment's cylinders as the entanglement monitor's axes.
  static std::vector<EntanglementAxis> entanglement_axes(const kelp::system::SystemModeld& model) {
    std::vector<EntanglementAxis> axes;
    if (const kelp::environment::ObstacleSet* o = model.environment().obstacles()) {
      for (std::size_t k = 0; k < o->cylinders().size(); ++k) {
        const kelp::environment::Cylinder& c = o->cylinders()[k];
        EntanglementAxis a;
        a.name = c.name.empty() ? "cylinder " + std::to_string(k) : c.name;
        a.index = int(k);
        a.from = c.from;
        a.to = c.to;
        a.radius = c.radius;
        axes.push_back(a);
      }
    }
    return axes;
  }
  static kelp::vehicle::ThrusterAllocationd rov_allocation() {
    const auto rov = kelp::vehicle::bluerov2_heavy<double>();
    return {rov.thruster_positions, rov.thruster_directions};
  }
  static kelp::vehicle::ThrusterAllocationd boat_allocation() {
    const auto boat = kelp::vehicle::blueboat<double>();
    return {boat.thruster_positions, boat.thruster_directions};
  }
  static void set_gains(kelp::control::PidGains& g, const Gains& x) {
    g.kp = x.kp;
    g.ki = x.ki;
    g.kd = x.kd;
  }
  static kelp::control::AuvControllerSettings auv_settings(const Scenario& sc) {
    kelp::control::AuvControllerSettings s;
    s.thruster_facing = kelp::vehicle::bluerov2_heavy<double>().thruster_facing;
    s.compensate = sc.compensation;
    s.period = 1.0 / sc.auv_rate;
    set_gains(s.surge, sc.auv_surge);
    set_gains(s.sway, sc.auv_sway);
    set_gains(s.heave, sc.auv_heave);
    set_gains(s.yaw, sc.auv_yaw);
    if (sc.control_preset == "kelp") {
      // Track the survey's legs (a reference moving at leg_speed, at most 1 m ahead), with the
      // horizontal and vertical thrust saturated apart.
      s.follow_legs = true;
      s.max_horizontal_error = 1.0;
      s.split_saturation = true;
    }
    return s;
  }
  static kelp::control::AsvControllerSettings asv_settings(const Scenario& sc) {
    kelp::control::AsvControllerSettings s;
    s.thruster_facing = kelp::vehicle::blueboat<double>().thruster_facing;
    s.compensate = sc.compensation;
    s.period = 1.0 / sc.asv_rate;
    s.thrust_clip = sc.asv_thrust_clip;
    if (sc.control_preset == "kelp") s.law = kelp::control::AsvLaw::track;
    const auto set = [&](kelp::control::PidGains& g, const Gains& x) {
      set_gains(g, x);
      g.output_limit = sc.asv_thrust_clip;
    };
    set(s.linear, sc.asv_linear);
    set(s.angular, sc.asv_angular);
    set(s.yaw, sc.asv_yaw);
    return s;
  }

  // The controllers' commands at the current state, its sample, and at the log and node rates
  // the metrics and the log.
  void observe() {
    const double t = state_.time;
    // Propulsion: the controllers' inverse (command for a thrust) uses each battery's measured
    // voltage (the last step's; its open-circuit voltage before the first).
    const auto volts = [](const kelp::vehicle::PropulsionModeld& pm,
                          const kelp::vehicle::PropulsionStated& x) {
      return std::isfinite(x.battery.voltage)
                 ? x.battery.voltage
                 : kelp::vehicle::open_circuit_voltage(
                       pm.parameters().battery,
                       kelp::vehicle::state_of_charge(pm.parameters().battery, x.battery));
    };
    if (const auto* pm = model_.auv_propulsion())
      auv_.set_voltage(volts(*pm, state_.auv_propulsion));
    if (const auto* pm = model_.asv_propulsion())
      asv_.set_voltage(volts(*pm, state_.asv_propulsion));
    // What the controllers see: the true state, or the sensors' estimates (the boat takes the
    // ROV's position from the ROV's estimate, which it receives over the tether).
    if (navigation_) {
      navigation_->update(model_, state_);
      auv_command_ = &auv_.update(navigation_->auv(), t);
      asv_command_ = &asv_.update(navigation_->asv(), navigation_->auv().position, t);
    } else {
      auv_command_ = &auv_.update(kelp::control::navigation_of(state_.auv), t);
      asv_command_ = &asv_.update(kelp::control::navigation_of(state_.asv), state_.auv.position, t);
    }
    // The AUV's error: distance from the survey path (the leg it is on); the boat's: its
    // horizontal distance from the AUV.
    const std::size_t leg = std::min(auv_.next_waypoint(), waypoints_.size() - 1);
    const kelp::Vector3<double> from = leg == 0 ? start_ : waypoints_[leg - 1];
    const double e_auv = detail::distance_to_segment(state_.auv.position, from, waypoints_[leg]);
    const double e_asv = (state_.asv.position - state_.auv.position).head<2>().norm();
    const double ta = report_.force_on_asv.norm(), tb = report_.force_on_auv.norm();
    LogRow& row = sample_;
    row.t = t;
    row.asv = &state_.asv;
    row.auv = &state_.auv;
    row.auv_target = auv_.target();
    row.auv_error = e_auv;
    row.asv_error = e_asv;
    const kelp::control::AsvCommand& asv = asv_override_ ? *asv_override_ : *asv_command_;
    row.asv_thrust << asv.left, asv.right;
    row.auv_thrust = (auv_override_ ? auv_override_ : auv_command_)->thrust;
    row.asv_command = asv.command;
    row.auv_command = (auv_override_ ? auv_override_ : auv_command_)->command;
    row.tension_asv = ta;
    row.tension_auv = tb;
    row.force_on_asv = report_.force_on_asv;
    row.force_on_auv = report_.force_on_auv;
    row.auv_nu_dot = state_.auv_nu_dot;
    row.gravity = model_.environment().gravity();
    row.tether_model = &model_.tether_of(state_);
    row.tether = &state_.tether;
    // The AUV's turns about the tether (its attachment is the tether's last node).
    turns_.update(state_.auv, state_.tether, int(state_.tether.position.cols()) - 1);
    row.tether_turns = turns_.turns();
    row.parted_segments = state_.tether.parted_segments();
    // The tether's winding about each cylinder and its entanglement events (the segments' axial
    // forces of the last force evaluation, when the workspace holds this node count's).
    {
      const Eigen::Index segments = state_.tether.position.cols() - 1;
      const auto& tension = workspace_.tether.tension;
      const int raised = entanglement_.update(
          t, state_.tether.position, state_.tether.velocity,
          tension.head(tension.size() == segments ? segments : Eigen::Index(0)));
      if (options_.log)
        for (std::size_t k = entanglement_.events().size() - std::size_t(raised);
             k < entanglement_.events().size(); ++k) {
          const EntanglementEvent& e = entanglement_.events()[k];
          options_.log->entanglement(
              e.time, event_name(e.kind), e.position,
              e.kind == EntanglementEvent::Kind::pinned ? e.value : LogRow::none,
              entanglement_.axes()[std::size_t(e.obstacle)].name,
              entanglement_.obstacle(std::size_t(e.obstacle)).winding);
        }
      const int most = entanglement_.most_wound();
      row.tether_winding =
          most < 0 ? LogRow::none : entanglement_.obstacle(std::size_t(most)).winding;
      row.winding_obstacle =
          most < 0 ? LogRow::none : double(entanglement_.axes()[std::size_t(most)].index);
    }
    // The line out, and with a winch its payout rate, its pull and the next command.
    {
      const auto& line = model_.tether_of(state_);
      row.tether_length = kelp::tether::unstretched_length(line, state_.tether);
      min_length_ = std::min(min_length_, row.tether_length);
      max_length_ = std::max(max_length_, row.tether_length);
      if (model_.winch()) {
        row.payout_rate = state_.tether.payout_rate;
        row.winch_pull = kelp::tether::winch_pull(line, state_.tether);
        // What the winch's strategy sees: its load cell, its line counter, and the vehicles'
        // positions as the controllers see them.
        const kelp::Vector3<double> boat =
            navigation_ ? navigation_->asv().position : state_.asv.position;
        const kelp::Vector3<double> rov =
            navigation_ ? navigation_->auv().position : state_.auv.position;
        kelp::control::TetherManagementInput in;
        in.pull = row.winch_pull;
        in.length = row.tether_length;
        in.depth = rov.z() - boat.z();
        in.horizontal_offset = (rov - boat).head<2>().norm();
        inputs_.winch_payout_rate = kelp::control::winch_command(winch_settings_, in);
      }
    }
    // Propulsion: the thrust the thrusters deliver (lagged), their current, the batteries.
    if (const auto* pm = model_.asv_propulsion()) {
      const auto& x = state_.asv_propulsion;
      row.asv_thrust = x.thrust.head<2>();
      row.asv_current = x.current.head<2>();
      row.asv_voltage = x.battery.voltage;
      row.asv_soc = kelp::vehicle::state_of_charge(pm->parameters().battery, x.battery);
    }
    if (const auto* pm = model_.auv_propulsion()) {
      const auto& x = state_.auv_propulsion;
      row.auv_thrust = x.thrust.head<8>();
      row.auv_current = x.current.head<8>();
      row.auv_voltage = x.battery.voltage;
      row.auv_soc = kelp::vehicle::state_of_charge(pm->parameters().battery, x.battery);
    }
    if (k_ % log_every_ == 0) {
      if (k_ > 0) {
        RunMetrics& m = metrics_;
        m.auv_squared_error_sum += e_auv * e_auv;
        m.asv_squared_distance_sum += e_asv * e_asv;
        m.auv_max_error = std::max(m.auv_max_error, e_auv);
        m.asv_max_distance = std::max(m.asv_max_distance, e_asv);
        m.max_tension = std::max(m.max_tension, std::max(ta, tb));
        m.auv_tension_sum += tb;
        m.slack_samples += tb < 0.1;
        ++m.samples;
        if (t >= 0.5 * scenario_.duration) {
          m.late_depth_error =
              std::max(m.late_depth_error, std::abs(state_.auv.position.z() - auv_.target().z()));
          m.late_auv_error = std::max(m.late_auv_error, e_auv);
          m.late_asv_distance = std::max(m.late_asv_distance, e_asv);
        }
      }
      if (options_.log) options_.log->row(row);
      if (options_.on_sample) options_.on_sample(row);
    }
    if (options_.log && k_ % node_every_ == 0)
      options_.log->nodes(t, model_.tether_of(state_), state_.tether);
  }

  Scenario scenario_;
  ClosedLoopOptions options_;
  kelp::system::SystemModeld model_;
  kelp::system::SystemWorkspaced workspace_;
  kelp::system::SystemStated state_;
  kelp::vehicle::ThrusterAllocationd rov_thrusters_, boat_thrusters_;
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
  std::unique_ptr<kelp::nav::PairNavigation> navigation_;
  // The winch's strategy, its re-meshes so far, the line's mass and length at the start and
  // the range of its length.
  kelp::control::TetherManagementSettings winch_settings_;
  kelp::tether::RemeshReport<double> remesh_;
  double line_mass_start_ = 0, length_start_ = 0;
  double min_length_ = std::numeric_limits<double>::infinity(), max_length_ = 0;
  // The tether's winding about the environment's cylinders, and its entanglement events.
  EntanglementMonitor entanglement_;
};

/// \brief Options of simulate().
struct SimulateOptions {
  /// Where to write timeseries.csv and nodes.csv (at the scenario's rates), created once the
  /// scenario is known to be valid; empty: no CSV.
  std::string log_dir;
  bool progress = false;                             ///< a progress bar on stderr
  std::string scenario_file = "(embedded default)";  ///< named in errors and in the summary
  /// Called after every step (e.g. the soak test's checks); empty: nothing is called.
  std::function<void(const StepView&)> on_step;
  /// Called with every sample at the log rate (ClosedLoopOptions::on_sample); empty: none.
  std::function<void(const LogRow&)> on_sample;
};

/// \brief Runs a scenario to its end in a ClosedLoop and returns its summary (the JSON
/// kelp-tethered-pair writes as summary.json, without the program's version): ClosedLoop::summary()
/// with the wall time [s] and the real-time factor.
/// \throws scenario_error, kelp::invalid_argument, kelp::numerical_error; kelp::error when the
/// log cannot be written.
inline nlohmann::json simulate(const Scenario& sc, const SimulateOptions& o = {}) {
  const WorldSetup setup = world_setup(sc, o.scenario_file);
  std::unique_ptr<RunLog> log;
  if (!o.log_dir.empty()) log = std::make_unique<RunLog>(o.log_dir);
  ClosedLoopOptions lo;
  lo.scenario_file = o.scenario_file;
  lo.log = log.get();
  lo.on_step = o.on_step;
  lo.on_sample = o.on_sample;
  ClosedLoop loop(sc, setup, lo);
  const long steps = loop.total_steps();
  const auto wall0 = std::chrono::steady_clock::now();
  while (!loop.done()) {
    const long k = loop.steps_taken();
    const double t = loop.time();
    loop.step();
    if (o.progress && k % 500 == 0)
      std::fprintf(stderr, "\r[%-40s] %5.1f / %.0f s",
                   std::string(static_cast<std::size_t>(40.0 * k / steps), '#').c_str(), t,
                   sc.duration);
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  if (o.progress) std::fprintf(stderr, "\n");
  if (log) log->close();
  nlohmann::json summary = loop.summary();
  summary["wall_s"] = wall;
  summary["realtime_factor"] = sc.duration / wall;
  return summary;
}

}  // namespace sim
}  // namespace kelp
