// The closed loop of the tethered pair (kelp/sim/closed_loop.hpp): its construction from a
// scenario, its step, its sampling and metrics, and its summary.
#include "kelp/sim/closed_loop.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "controller_io.hpp"
#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/kernel_path.hpp"
#include "kelp/system/presets.hpp"
#include "kelp/vehicle/presets.hpp"

namespace kelp {
namespace sim {

namespace {
/// Distance from p to the segment a–b.
double distance_to_segment(const kelp::Vector3<double>& p, const kelp::Vector3<double>& a,
                           const kelp::Vector3<double>& b) {
  const kelp::Vector3<double> ab = b - a;
  const double l2 = ab.squaredNorm();
  const double s = l2 > 0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (a + s * ab - p).norm();
}
}  // namespace

ClosedLoop::ClosedLoop(const Scenario& sc, const WorldSetup& world,
                       const ClosedLoopOptions& options)
    : scenario_(sc),
      options_(options),
      model_(world.parameters, world.environment),
      workspace_(model_),
      state_(start_state(model_, workspace_, world, sc)),
      auv_thrusters_(auv_allocation()),
      asv_thrusters_(asv_allocation()),
      auv_(model_.auv(), auv_thrusters_, auv_settings(sc)),
      asv_(model_.asv(), asv_thrusters_, asv_settings(sc)),
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
    w.strategy = sc.winch_strategy;
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
  if (sc.navigation.mode == NavigationMode::sensors)
    navigation_ =
        std::make_unique<PairNavigation>(sc.navigation.sensors, sc.navigation.seed, model_, state_);
  observe();
}

const kelp::system::SystemReportd& ClosedLoop::step() {
  if (done())
    throw kelp::error("ClosedLoop::step: the run is over (" + std::to_string(steps_) +
                      " steps of the scenario's duration)");
  // With propulsion, the controllers' per-thruster commands drive the thrusters (lag, battery);
  // without, their wrench is applied directly.
  // The controllers' chains have the ESC's 1100–1900 µs mapping (their commands are the ESC's);
  // the propulsion takes the vehicle's PWM mapping's (e.g. the BlueBoat's 1000–2000 µs).
  const kelp::control::AuvCommand& auv = auv_override_ ? *auv_override_ : *auv_command_;
  if (const auto* pm = model_.auv_propulsion())
    vehicle_commands(*pm, auv.command, inputs_.auv_commands);
  else
    inputs_.auv.tau = auv.wrench;
  const kelp::control::AsvCommand& asv = asv_override_ ? *asv_override_ : *asv_command_;
  if (const auto* pm = model_.asv_propulsion())
    vehicle_commands(*pm, asv.command, inputs_.asv_commands);
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

long ClosedLoop::run_for(double seconds) {
  KELP_CHECK(std::isfinite(seconds) && seconds >= 0,
             "ClosedLoop::run_for: seconds must be finite and non-negative");
  const long n = std::min(std::lround(seconds / dt), steps_ - k_);
  for (long i = 0; i < n; ++i) step();
  return n;
}

std::vector<EntanglementAxis> ClosedLoop::entanglement_axes(
    const kelp::system::SystemModeld& model) {
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

kelp::vehicle::ThrusterAllocationd ClosedLoop::auv_allocation() {
  const auto rov = kelp::vehicle::bluerov2_heavy<double>();
  return {rov.thruster_positions, rov.thruster_directions};
}

kelp::vehicle::ThrusterAllocationd ClosedLoop::asv_allocation() {
  const auto boat = kelp::vehicle::blueboat<double>();
  return {boat.thruster_positions, boat.thruster_directions};
}

void ClosedLoop::set_gains(kelp::control::PidGains& g, const Gains& x) {
  g.kp = x.kp;
  g.ki = x.ki;
  g.kd = x.kd;
}

kelp::control::AuvControllerSettings ClosedLoop::auv_settings(const Scenario& sc) {
  kelp::control::AuvControllerSettings s;
  s.thruster_facing = kelp::vehicle::bluerov2_heavy<double>().thruster_facing;
  s.compensate = sc.compensation;
  s.period = 1.0 / sc.auv_rate;
  set_gains(s.surge, sc.auv_surge);
  set_gains(s.sway, sc.auv_sway);
  set_gains(s.heave, sc.auv_heave);
  set_gains(s.yaw, sc.auv_yaw);
  if (sc.control_preset == ControlPreset::kelp) {
    // Track the survey's legs (a reference moving at leg_speed, at most 1 m ahead), with the
    // horizontal and vertical thrust saturated apart.
    s.follow_legs = true;
    s.max_horizontal_error = 1.0;
    s.split_saturation = true;
  }
  return s;
}

kelp::control::AsvControllerSettings ClosedLoop::asv_settings(const Scenario& sc) {
  kelp::control::AsvControllerSettings s;
  s.thruster_facing = kelp::vehicle::blueboat<double>().thruster_facing;
  s.compensate = sc.compensation;
  s.period = 1.0 / sc.asv_rate;
  s.thrust_clip = sc.asv_thrust_clip;
  if (sc.control_preset == ControlPreset::kelp) s.law = kelp::control::AsvLaw::track;
  const auto set = [&](kelp::control::PidGains& g, const Gains& x) {
    set_gains(g, x);
    g.output_limit = sc.asv_thrust_clip;
  };
  set(s.linear, sc.asv_linear);
  set(s.angular, sc.asv_angular);
  set(s.yaw, sc.asv_yaw);
  return s;
}

void vehicle_commands(const kelp::vehicle::PropulsionModeld& pm,
                      const Eigen::Ref<const Eigen::VectorXd>& esc,
                      kelp::vehicle::ThrusterVector<double>& u) {
  const auto& pp = pm.parameters();
  u.resize(esc.size());
  for (Eigen::Index i = 0; i < esc.size(); ++i)
    u(i) = esc(i) > 0.0 ? esc(i) / pp.esc_scale_forward : esc(i) / pp.esc_scale_reverse;
}

double controller_voltage(const kelp::vehicle::PropulsionModeld& pm,
                          const kelp::vehicle::PropulsionStated& x) {
  return std::isfinite(x.battery.voltage)
             ? x.battery.voltage
             : kelp::vehicle::open_circuit_voltage(
                   pm.parameters().battery,
                   kelp::vehicle::state_of_charge(pm.parameters().battery, x.battery));
}

void ClosedLoop::observe() {
  const double t = state_.time;
  // Propulsion: the controllers' inverse (command for a thrust) uses each battery's measured
  // voltage (the last step's; its open-circuit voltage before the first).
  if (const auto* pm = model_.auv_propulsion())
    auv_.set_voltage(controller_voltage(*pm, state_.auv_propulsion));
  if (const auto* pm = model_.asv_propulsion())
    asv_.set_voltage(controller_voltage(*pm, state_.asv_propulsion));
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
  const double e_auv = distance_to_segment(state_.auv.position, from, waypoints_[leg]);
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
    const int raised =
        entanglement_.update(t, state_.tether.position, state_.tether.velocity,
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

SolverSummary solver_summary(const kelp::system::SolverStatsd& stats,
                             const kelp::system::SystemParametersd& p) {
  const auto finite_or_nan = [](double x) {
    return std::isfinite(x) ? x : std::numeric_limits<double>::quiet_NaN();
  };
  SolverSummary j;
  j.integrator = kelp::tether::integrator_name(p.tether_integrator);
  j.newton_budget = p.tether_options.max_iterations;
  j.explicit_fallback = p.explicit_fallback;
  j.steps = stats.steps;
  j.tether_steps = stats.tether_steps;
  j.newton_iterations = stats.newton_iterations;
  j.newton_iterations_per_step_mean = stats.mean_step_newton_iterations();
  j.newton_iterations_per_step_max = stats.max_step_newton_iterations;
  j.newton_iterations_per_tether_step_mean = stats.mean_tether_step_newton_iterations();
  j.retried_steps = stats.retried_steps;
  j.explicit_fallbacks = stats.explicit_fallbacks;
  j.force_evaluations = stats.force_evaluations;
  j.worst_residual_m_s = finite_or_nan(stats.worst_residual);
  j.worst_rejected_residual_m_s = finite_or_nan(stats.worst_rejected_residual);
  j.residual_tolerance_m_s = p.tether_options.acceleration_tolerance * p.max_tether_dt;
  return j;
}

NavigationSummary ClosedLoop::navigation_summary() const {
  NavigationSummary n;
  n.mode = scenario_.navigation.mode;
  if (!navigation_) return n;
  const PairNavigation& v = *navigation_;
  const double deg = 180.0 / kelp::pi;
  NavigationErrorsSummary e;
  e.seed = scenario_.navigation.seed;
  e.auv_rms_position_error_m = v.auv_errors().rms_position();
  e.auv_rms_horizontal_error_m = v.auv_errors().rms_horizontal();
  e.auv_max_position_error_m = v.auv_errors().max_position;
  e.auv_rms_heading_error_deg = v.auv_errors().rms_heading() * deg;
  e.auv_rms_velocity_error_m_s = v.auv_errors().rms_velocity();
  e.asv_rms_position_error_m = v.asv_errors().rms_position();
  e.asv_rms_horizontal_error_m = v.asv_errors().rms_horizontal();
  e.asv_max_position_error_m = v.asv_errors().max_position;
  e.asv_rms_heading_error_deg = v.asv_errors().rms_heading() * deg;
  e.asv_rms_velocity_error_m_s = v.asv_errors().rms_velocity();
  e.usbl_pings = v.usbl_pings();
  e.usbl_dropouts = v.usbl_dropouts();
  e.usbl_fixes_used = v.usbl_fixes();
  e.dvl_pings_bottom = v.dvl_pings(kelp::nav::DvlMode::bottom);
  e.dvl_pings_water = v.dvl_pings(kelp::nav::DvlMode::water);
  e.dvl_pings_none = v.dvl_pings(kelp::nav::DvlMode::none);
  n.errors = e;
  return n;
}

EntanglementSummary ClosedLoop::entanglement_summary() const {
  const EntanglementMonitor& m = entanglement_;
  EntanglementSummary e;
  e.settings = m.settings();
  const auto event_summary = [&](const EntanglementEvent& v) {
    EntanglementEventSummary j;
    j.event = event_name(v.kind);
    j.time_s = v.time;
    j.obstacle = m.axes()[std::size_t(v.obstacle)].name;
    j.position_m = {v.position.x(), v.position.y(), v.position.z()};
    j.value = v.value;
    return j;
  };
  for (std::size_t k = 0; k < m.axes().size(); ++k) {
    const ObstacleWinding& w = m.obstacle(k);
    ObstacleWindingSummary o;
    o.name = m.axes()[k].name;
    o.index = m.axes()[k].index;
    o.max_abs_winding_rad = w.max_abs_winding;
    o.final_winding_rad = w.winding;
    o.entangled_s = w.first_entangled;
    o.pinned_s = w.first_pinned;
    for (const EntanglementEvent& v : m.events())
      if (std::size_t(v.obstacle) == k) o.events.push_back(event_summary(v));
    e.obstacles.push_back(std::move(o));
  }
  for (const EntanglementEvent& v : m.events()) e.events.push_back(event_summary(v));
  e.dropped_events = m.dropped_events();
  return e;
}

RunSummary ClosedLoop::summary() const {
  const RunMetrics& m = metrics_;
  RunSummary s;
  // A run stopped early (kelp/sim/stop.hpp), or a summary taken before the end: the time reached.
  s.completed = done();
  s.simulated_s = s.completed ? scenario_.duration : state_.time;
  s.auv.rms_path_error_m = m.auv_rms_error();
  s.auv.max_path_error_m = m.auv_max_error;
  s.auv.waypoints_reached = auv_.next_waypoint();
  s.auv.second_half_max_depth_error_m = m.late_depth_error;
  s.auv.second_half_max_path_error_m = m.late_auv_error;
  s.asv.rms_distance_to_auv_m = m.asv_rms_distance();
  s.asv.max_distance_to_auv_m = m.asv_max_distance;
  s.asv.second_half_max_distance_to_auv_m = m.late_asv_distance;
  TetherSummary& t = s.tether;
  t.max_tension_n = m.max_tension;
  t.mean_tension_auv_n = m.auv_mean_tension();
  t.slack_fraction = m.slack_fraction();
  t.net_turns = turns_.turns();
  t.max_abs_turns = turns_.max_abs_turns();
  // The line's partings: when, which segment, where, under what force.
  for (const auto& f : failures_)
    t.line_failures.push_back(
        {f.time, f.segment, {f.position.x(), f.position.y(), f.position.z()}, f.tension});
  // The line's structural mass and unstretched length at the start and the end (they differ
  // with a winch, which pays line out and reels it in).
  const auto& line = model_.tether_of(state_);
  t.line_mass_start_kg = line_mass_start_;
  t.line_mass_end_kg = kelp::tether::line_mass(line, state_.tether);
  t.length_start_m = length_start_;
  t.length_end_m = kelp::tether::unstretched_length(line, state_.tether);
  if (model_.winch())
    t.winch = WinchSummary{kelp::control::winch_strategy_name(winch_settings_.strategy),
                           remesh_.inserted,
                           remesh_.removed,
                           remesh_.kinetic_energy_lost,
                           min_length_,
                           max_length_};
  s.tether_solver = solver_summary(solver_stats_, model_.parameters());
  s.energy_j = kelp::system::energy(model_, state_).total();
  // Propulsion: the energy each vehicle's battery delivered [Wh] and its final state of charge.
  const auto battery = [&](const kelp::vehicle::PropulsionModeld* pm,
                           const kelp::vehicle::PropulsionStated& x,
                           std::optional<BatterySummary>& out) {
    if (pm == nullptr) return;
    out = BatterySummary{x.battery.energy_drawn / 3600.0,
                         kelp::vehicle::state_of_charge(pm->parameters().battery, x.battery)};
  };
  battery(model_.auv_propulsion(), state_.auv_propulsion, s.auv.battery);
  battery(model_.asv_propulsion(), state_.asv_propulsion, s.asv.battery);
  // What the numbers depend on beyond the scenario: the wave kernel's instruction path and the
  // C library's math (kelp/core/kernel_path.hpp); kelp-sweep merge compares them across runs.
  s.kernel = kelp::simd::kernel_name(model_.environment().waves().active_kernel());
  s.math_library = kelp::simd::math_library_fingerprint();
  s.navigation = navigation_summary();
  s.entanglement = entanglement_summary();
  s.scenario_file = options_.scenario_file;
  s.scenario = scenario_;
  return s;
}

}  // namespace sim
}  // namespace kelp

template class kelp::control::AuvControllerT<double>;
template class kelp::control::AsvControllerT<double>;
