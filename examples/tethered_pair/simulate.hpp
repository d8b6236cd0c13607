// One closed-loop run of the tethered pair: the system of a scenario flown by kelp's
// controllers (the ROV's survey, the boat following it), with its error and tension statistics.
// kelp-tethered-pair runs it once with the CSV log; kelp-sweep runs it many times without.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "kelp/control/controllers.hpp"
#include "kelp/system/presets.hpp"
#include "scenario.hpp"
#include "world.hpp"

namespace tethered_pair {

namespace detail {
// Distance from p to the segment a–b.
inline double distance_to_segment(const kelp::Vector3<double>& p, const kelp::Vector3<double>& a,
                                  const kelp::Vector3<double>& b) {
  const kelp::Vector3<double> ab = b - a;
  const double l2 = ab.squaredNorm();
  const double s = l2 > 0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (a + s * ab - p).norm();
}
}  // namespace detail

/// What an observer of the run sees after every step (SimulateOptions::on_step).
struct StepView {
  long step;                                  ///< steps taken so far (1 after the first)
  const kelp::system::SystemModeld& model;    ///< the system being run
  const kelp::system::SystemStated& state;    ///< its state after the step
  const kelp::system::SystemReportd& report;  ///< what the step did
};

struct SimulateOptions {
  /// Where to write timeseries.csv and nodes.csv (at the scenario's rates), created once the
  /// scenario is known to be valid; empty: no CSV.
  std::string log_dir;
  bool progress = false;                             ///< a progress bar on stderr
  std::string scenario_file = "(embedded default)";  ///< named in errors and in the summary
  /// Called after every step (e.g. the soak test's checks); empty: nothing is called.
  std::function<void(const StepView&)> on_step;
};

/// Runs `sc` and returns its summary (the JSON kelp-tethered-pair writes as summary.json, without
/// the program's version): errors, tensions, slack fraction, energy, wall time.
/// \throws scenario_error, kelp::invalid_argument, kelp::numerical_error.
inline nlohmann::json simulate(const Scenario& sc, const SimulateOptions& o = {}) {
  namespace kc = kelp::control;
  namespace ks = kelp::system;
  namespace kv = kelp::vehicle;
  using kelp::Vector3;
  const WorldSetup setup = world_setup(sc, o.scenario_file);
  std::unique_ptr<RunLog> log;
  if (!o.log_dir.empty()) log = std::make_unique<RunLog>(o.log_dir);
  const ks::SystemModeld model(setup.parameters, setup.environment);
  ks::SystemWorkspaced ws(model);
  struct World {
    const ks::SystemModeld& model;
    ks::SystemWorkspaced& workspace;
    ks::SystemStated state;
  } w{model, ws, ks::initial_state(model, ws, setup.start.asv, setup.start.auv)};
  const auto rov = kv::bluerov2_heavy<double>();
  const auto boat = kv::blueboat<double>();
  const kv::ThrusterAllocationd rov_thrusters(rov.thruster_positions, rov.thruster_directions);
  const kv::ThrusterAllocationd boat_thrusters(boat.thruster_positions, boat.thruster_directions);
  kc::AuvControllerSettings auv_settings;
  auv_settings.compensate = sc.compensation;
  auv_settings.period = 1.0 / sc.auv_rate;
  const auto gain = [](kc::PidGains& g, const Gains& x) {
    g.kp = x.kp;
    g.ki = x.ki;
    g.kd = x.kd;
  };
  gain(auv_settings.surge, sc.auv_surge);
  gain(auv_settings.sway, sc.auv_sway);
  gain(auv_settings.heave, sc.auv_heave);
  gain(auv_settings.yaw, sc.auv_yaw);
  kc::AsvControllerSettings asv_settings;
  asv_settings.compensate = sc.compensation;
  asv_settings.period = 1.0 / sc.asv_rate;
  asv_settings.thrust_clip = sc.asv_thrust_clip;
  const auto set = [&](kc::PidGains& g, const Gains& x) {
    gain(g, x);
    g.output_limit = sc.asv_thrust_clip;
  };
  set(asv_settings.linear, sc.asv_linear);
  set(asv_settings.angular, sc.asv_angular);
  set(asv_settings.yaw, sc.asv_yaw);
  kc::AuvController auv(w.model.auv(), rov_thrusters, auv_settings);
  kc::AsvController asv(w.model.asv(), boat_thrusters, asv_settings);
  const Vector3<double> start = w.state.auv.position;
  const Vector3<double> s0(start.x(), start.y(), sc.depth);
  std::vector<Vector3<double>> square = sc.waypoints;
  if (square.empty()) {
    const double a = sc.square_side;
    square = {s0 + Vector3<double>(a, 0, 0), s0 + Vector3<double>(a, a, 0),
              s0 + Vector3<double>(0, a, 0), s0};
  }
  auv.follow(square);
  asv.follow_auv();

  const double dt = 0.01;
  const double duration = sc.duration;
  const long steps = std::lround(duration / dt);
  const long log_every = std::max(1L, std::lround(1.0 / (sc.log_rate * dt)));
  const long node_every = std::max(1L, std::lround(1.0 / (sc.node_rate * dt)));
  double auv_se = 0, auv_max = 0, asv_se = 0, asv_max = 0, t_max = 0, t_sum = 0;
  long samples = 0, slack = 0;
  // Over the second half of the run (after settling).
  double late_depth = 0, late_auv = 0, late_asv = 0;
  const bool bar = o.progress;
  const auto wall0 = std::chrono::steady_clock::now();
  ks::SystemInputsd in;
  ks::SystemReportd rep;
  for (long k = 0; k <= steps; ++k) {
    const double t = w.state.time();
    const kc::AuvCommand& ac = auv.update(kc::navigation_of(w.state.auv), t);
    const kc::AsvCommand& bc = asv.update(kc::navigation_of(w.state.asv), w.state.auv.position, t);
    if (k % log_every == 0) {
      // The AUV's error: distance from the survey path (the leg it is on); the boat's: its
      // horizontal distance from the AUV.
      const std::size_t leg = std::min(auv.next_waypoint(), square.size() - 1);
      const Vector3<double> from = leg == 0 ? start : square[leg - 1];
      const double e_auv = detail::distance_to_segment(w.state.auv.position, from, square[leg]);
      const double e_asv = (w.state.asv.position - w.state.auv.position).head<2>().norm();
      const double ta = rep.force_on_asv.norm(), tb = rep.force_on_auv.norm();
      if (k > 0) {
        auv_se += e_auv * e_auv;
        asv_se += e_asv * e_asv;
        auv_max = std::max(auv_max, e_auv);
        asv_max = std::max(asv_max, e_asv);
        t_max = std::max(t_max, std::max(ta, tb));
        t_sum += tb;
        slack += tb < 0.1;
        ++samples;
        if (t >= 0.5 * duration) {
          late_depth = std::max(late_depth, std::abs(w.state.auv.position.z() - auv.target().z()));
          late_auv = std::max(late_auv, e_auv);
          late_asv = std::max(late_asv, e_asv);
        }
      }
      LogRow row;
      row.t = t;
      row.asv = &w.state.asv;
      row.auv = &w.state.auv;
      row.auv_target = auv.target();
      row.auv_error = e_auv;
      row.asv_error = e_asv;
      row.asv_thrust << bc.left, bc.right;
      row.auv_thrust = ac.thrust;
      row.asv_command = bc.command;
      row.auv_command = ac.command;
      row.tension_asv = ta;
      row.tension_auv = tb;
      if (log) log->row(row);
    }
    if (log && k % node_every == 0) log->nodes(t, w.state.tether);
    if (k == steps) break;
    in.auv.control = ac.wrench;
    in.asv.control = bc.wrench;
    rep = ks::step(w.model, w.workspace, w.state, in, dt);
    if (o.on_step) o.on_step(StepView{k + 1, w.model, w.state, rep});
    if (bar && k % 500 == 0)
      std::fprintf(stderr, "\r[%-40s] %5.1f / %.0f s",
                   std::string(static_cast<std::size_t>(40.0 * k / steps), '#').c_str(), t,
                   duration);
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  if (bar) std::fprintf(stderr, "\n");
  if (log) log->close();

  nlohmann::json summary;
  const double n = std::max<double>(1, samples);
  summary["simulated_s"] = duration;
  summary["wall_s"] = wall;
  summary["realtime_factor"] = duration / wall;
  summary["auv"] = {{"rms_path_error_m", std::sqrt(auv_se / n)},
                    {"max_path_error_m", auv_max},
                    {"waypoints_reached", auv.next_waypoint()},
                    {"second_half_max_depth_error_m", late_depth},
                    {"second_half_max_path_error_m", late_auv}};
  summary["asv"] = {{"rms_distance_to_auv_m", std::sqrt(asv_se / n)},
                    {"max_distance_to_auv_m", asv_max},
                    {"second_half_max_distance_to_auv_m", late_asv}};
  summary["tether"] = {
      {"max_tension_n", t_max}, {"mean_tension_auv_n", t_sum / n}, {"slack_fraction", slack / n}};
  summary["energy_j"] = ks::energy(w.model, w.state).total();
  summary["scenario_file"] = o.scenario_file;
  summary["scenario"] = to_json(sc);
  return summary;
}

}  // namespace tethered_pair
