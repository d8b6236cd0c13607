// A fleet scenario's world and closed-loop run (kelp/sim/fleet_run.hpp).
#include "kelp/sim/fleet_run.hpp"

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "cable.hpp"
#include "controller_io.hpp"
#include "kelp/control/controllers.hpp"
#include "kelp/core/angles.hpp"
#include "kelp/core/constants.hpp"
#include "kelp/core/rotation.hpp"
#include "kelp/sim/ros2/fleet.hpp"
#include "kelp/sim/run_log.hpp"
#include "kelp/sim/stop.hpp"
#include "kelp/sim/world.hpp"
#include "kelp/tether/failure.hpp"
#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/presets.hpp"
#include "kelp/tether/winch.hpp"

namespace kelp {
namespace sim {

namespace ks = kelp::system;
namespace kv = kelp::vehicle;
namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const std::string& file, const std::string& path, const std::string& what) {
  throw scenario_error(file + ": " + path + ": " + what);
}

// A preset's name, or a vehicle file / Gazebo model relative to the scenario's directory.
VehicleDescription load_vehicle(const std::string& spec, const std::string& file,
                                const std::string& path,
                                const kelp::environment::Environmentd& env) {
  for (const std::string& n : vehicle_preset_names())
    if (n == spec) return vehicle_preset(spec);
  fs::path p(spec);
  if (p.is_relative()) p = fs::path(file).parent_path() / p;
  const bool sdf = p.extension() == ".sdf";
  if (!sdf && p.extension() != ".json")
    fail(
        file, path,
        "\"" + spec + "\" is neither a preset (bluerov2_heavy, blueboat) nor a .json or .sdf file");
  try {
    // A Gazebo model that states no water density is in the scenario's sea.
    SdfImportOptions o;
    o.density_kg_m3 = env.water_density();
    o.gravity_m_s2 = env.gravity();
    return sdf ? import_sdf(p.string(), o).vehicle : read_vehicle_file(p.string());
  } catch (const kelp::error& e) {
    fail(file, path, e.what());
  }
}

kelp::tether::TetherParametersd line_of(const FleetTetherScenario& t) {
  kelp::tether::TetherParametersd p = kelp::tether::presets::rov_tether(t.length, t.segment_length);
  apply_cable({t.diameter, t.mass_per_length, t.axial_stiffness, std::nullopt,
               t.internal_damping_ratio, t.normal_drag, t.tangential_drag, t.breaking_strength},
              p);
  return p;
}

// A vehicle's controller: the AUV's (underwater) or the ASV's (surface, two thrusters).
struct Controller {
  std::unique_ptr<kelp::control::AuvController> auv;
  std::unique_ptr<kelp::control::AsvController> asv;
  int target = -1;  // follow: the vehicle followed
  double error_sq = 0;
  long samples = 0;
};

}  // namespace

FleetWorld fleet_world(const Scenario& sc, const std::string& file) {
  if (!sc.fleet) fail(file, "/fleet", "the scenario has no fleet");
  const FleetScenario& f = *sc.fleet;
  FleetWorld w;
  w.environment = scenario_environment(sc, file);
  const bool touch =
      w.environment.obstacles() != nullptr || std::isfinite(w.environment.seabed_depth());
  for (std::size_t i = 0; i < f.vehicles.size(); ++i) {
    const FleetVehicleScenario& v = f.vehicles[i];
    const std::string p = "/fleet/vehicles/" + std::to_string(i);
    VehicleDescription d = load_vehicle(v.vehicle, file, p + "/vehicle", w.environment);
    // A Gazebo model's water is its world's (Buoyancy's fluid density, Hydrodynamics' water
    // density), not the vehicle's: the model goes into the scenario's sea, and the run says so.
    if (fs::path(v.vehicle).extension() == ".sdf" &&
        (d.parameters.density != w.environment.water_density() ||
         d.parameters.gravity != w.environment.gravity())) {
      w.notes.push_back(p + "/vehicle: the Gazebo model's water (" +
                        std::to_string(d.parameters.density) +
                        " kg/m^3) is replaced by the scenario's sea (" +
                        std::to_string(w.environment.water_density()) + " kg/m^3)");
      d.parameters.density = w.environment.water_density();
      d.parameters.gravity = w.environment.gravity();
    }
    if (d.parameters.density != w.environment.water_density() ||
        d.parameters.gravity != w.environment.gravity())
      fail(file, p + "/vehicle",
           "its water (density " + std::to_string(d.parameters.density) + " kg/m^3, gravity " +
               std::to_string(d.parameters.gravity) + " m/s^2) is not the sea's (" +
               std::to_string(w.environment.water_density()) + ", " +
               std::to_string(w.environment.gravity()) + ")");
    ks::FleetVehicle<double> fv{v.name, d.parameters, d.propulsion, {}};
    // The thrusters' lag is the vehicle's own (its file's); the scenario's `thrusters.lag: false`
    // turns it off.
    if (d.propulsion && !sc.thruster_lag) fv.propulsion->time_constant = 0.0;
    // The hull touches the seabed and the obstacles when there are any (as the pair's).
    if (touch && d.hull) fv.hull = d.hull;
    w.parameters.vehicles.push_back(std::move(fv));
    kv::VehicleStated x;
    x.position = v.start;
    x.attitude = Eigen::Quaterniond(Eigen::AngleAxisd(v.heading, Eigen::Vector3d::UnitZ()));
    w.start.push_back(x);
    w.vehicles.push_back(std::move(d));
  }
  for (const FleetPointMassScenario& m : f.point_masses) {
    ks::PointMassParametersd p;
    p.name = m.name;
    p.mass = m.mass;
    p.volume = m.volume;
    p.added_mass_coefficient = m.added_mass_coefficient;
    p.drag_area = m.drag_area;
    w.parameters.point_masses.push_back(p);
    w.point_mass_start.push_back(m.start);
  }
  // A tether end by name: a vehicle (its attachment point: the tether's or the file's), a point
  // mass, an anchor or "free"; and where it starts.
  const auto end_of = [&](const std::string& name, const std::optional<Vector3<double>>& point,
                          Vector3<double>& where) {
    for (std::size_t i = 0; i < f.vehicles.size(); ++i)
      if (f.vehicles[i].name == name) {
        const Vector3<double> r = point.value_or(w.vehicles[i].attachment);
        where = w.start[i].point_position(r);
        return ks::TetherEnd<double>::on_vehicle(int(i), r);
      }
    for (std::size_t j = 0; j < f.point_masses.size(); ++j)
      if (f.point_masses[j].name == name) {
        where = f.point_masses[j].start;
        return ks::TetherEnd<double>::on_point_mass(int(j));
      }
    for (const FleetAnchorScenario& a : f.anchors)
      if (a.name == name) {
        where = a.position;
        return ks::TetherEnd<double>::at_anchor(a.position);
      }
    where.setConstant(std::numeric_limits<double>::quiet_NaN());
    return ks::TetherEnd<double>::hanging_free();
  };
  for (std::size_t k = 0; k < f.tethers.size(); ++k) {
    const FleetTetherScenario& t = f.tethers[k];
    const std::string p = "/fleet/tethers/" + std::to_string(k);
    ks::FleetTether<double> ft;
    ft.name = t.name;
    ft.parameters = line_of(t);
    Vector3<double> a, b;
    ft.start = end_of(t.from, t.from_point, a);
    ft.end = end_of(t.to, t.to_point, b);
    if (a.allFinite() && b.allFinite() && (b - a).norm() > t.length)
      fail(file, p + "/length",
           std::to_string(t.length) + " m is shorter than the distance between its ends (" +
               std::to_string((b - a).norm()) + " m)");
    if (t.winch.enabled) {
      kelp::tether::WinchParametersd wp;
      wp.max_speed = t.winch.max_speed;
      wp.max_acceleration = t.winch.max_acceleration;
      wp.max_pull = t.winch.max_pull;
      wp.min_length = t.winch.min_length;
      wp.max_length = t.winch.max_length;
      ft.winch = wp;
    }
    w.parameters.tethers.push_back(std::move(ft));
  }
  w.parameters.explicit_fallback = sc.explicit_fallback;
  try {
    ks::validate(w.parameters);
  } catch (const kelp::invalid_argument& e) {
    fail(file, "/fleet", e.what());
  }
  return w;
}

ks::FleetStated fleet_start_state(const ks::FleetModeld& model, ks::FleetWorkspaced& ws,
                                  const FleetWorld& w, const Scenario& sc,
                                  const std::string& file) {
  ks::FleetStated state;
  try {
    state = ks::initial_state(model, ws, w.start, w.point_mass_start);
  } catch (const kelp::numerical_error& e) {
    fail(file, "/fleet/tethers", e.what());
  }
  const auto& env = model.environment();
  if (sc.start_with_water) {  // everything starts moving with the water, as the pair does
    for (auto& v : state.vehicles) {
      const auto e = env.sample(v.position, state.time, false);
      v.nu.head<3>() = v.attitude.conjugate() * (e.current + e.wave_velocity);
      v.nu.tail<3>().setZero();
    }
    for (auto& m : state.point_masses) {
      const auto e = env.sample(m.position, state.time, false);
      m.velocity = e.current + e.wave_velocity;
    }
    for (int k = 0; k < model.tether_count(); ++k)
      kelp::tether::move_with_water(model.tether(k), env, state.tethers[std::size_t(k)]);
  }
  return state;
}

FleetRunSummary run_fleet(const Scenario& sc, const std::string& file, const std::string& out,
                          const std::function<bool()>& should_stop) {
  FleetWorld w = fleet_world(sc, file);
  const FleetScenario& f = *sc.fleet;
  const ks::FleetModeld model(w.parameters, w.environment);
  ks::FleetWorkspaced ws(model);
  ks::FleetStated state = fleet_start_state(model, ws, w, sc, file);
  const auto& env = model.environment();
  // The controllers.
  const int n = model.vehicle_count(), m = model.tether_count();
  std::vector<Controller> control(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const FleetControllerScenario& c = f.vehicles[std::size_t(i)].controller;
    if (c.type == FleetControl::none) continue;
    const std::string p = "/fleet/vehicles/" + std::to_string(i) + "/controller";
    const kv::PropulsionModeld* pm = model.propulsion(i);
    if (pm == nullptr) fail(file, p, "the vehicle has no thrusters to control");
    Eigen::VectorXd facing(pm->size());
    for (Eigen::Index j = 0; j < pm->size(); ++j) facing(j) = pm->facing()(j);
    Controller& ctl = control[std::size_t(i)];
    const bool surface = model.vehicle(i).parameters().hydrostatics == kv::Hydrostatics::surface;
    if (surface) {
      if (c.type == FleetControl::waypoints)
        fail(file, p + "/type", "a surface vehicle holds station or follows (not waypoints)");
      kelp::control::AsvControllerSettings s;
      s.thruster_facing = facing;
      s.law = kelp::control::AsvLaw::track;
      s.follow_offset = c.offset;
      ctl.asv =
          std::make_unique<kelp::control::AsvController>(model.vehicle(i), pm->allocation(), s);
      if (c.type == FleetControl::follow) {
        ctl.asv->follow_auv();
        ctl.target = model.vehicle_index(c.target);
      } else {
        ctl.asv->station(c.position, c.heading);
      }
    } else {
      if (c.type == FleetControl::follow)
        fail(file, p + "/type", "an underwater vehicle holds or follows waypoints (not follow)");
      kelp::control::AuvControllerSettings s;
      s.thruster_facing = facing;
      s.follow_legs = true;
      s.leg_speed = c.leg_speed;
      s.max_horizontal_error = 1.0;
      s.split_saturation = true;
      ctl.auv =
          std::make_unique<kelp::control::AuvController>(model.vehicle(i), pm->allocation(), s);
      if (c.type == FleetControl::waypoints)
        ctl.auv->follow(c.waypoints);
      else
        ctl.auv->hold(c.position, c.heading);
    }
  }
  // The outputs.
  // The CSV files in whole lines (LineFile, kelp/sim/run_log.hpp), written out at least once a
  // simulated second: a run killed mid-way leaves files that end on a whole line.
  fs::create_directories(out);
  LineFile series, nodes;
  try {
    series.open(fs::path(out) / "timeseries.csv");
    nodes.open(fs::path(out) / "nodes.csv");
  } catch (const kelp::error&) {
    throw kelp::invalid_argument("run_fleet: cannot write into " + out);
  }
  std::string& st = series.text();
  std::string& nt = nodes.text();
  st += "t";
  for (const auto& v : f.vehicles)
    for (const char* c : {".x", ".y", ".z", ".roll", ".pitch", ".yaw", ".u", ".v", ".w"})
      st += ',' + v.name + c;
  for (const auto& p : f.point_masses)
    for (const char* c : {".x", ".y", ".z"}) st += ',' + p.name + c;
  for (const auto& t : f.tethers)
    for (const char* c : {".tension_start", ".tension_end", ".length"}) st += ',' + t.name + c;
  series.end_line();
  nt += "t,tether,node,x,y,z";
  nodes.end_line();
  series.write_out();
  nodes.write_out();
  char buf[64];
  const auto num = [&](std::string& o, double x) {
    std::snprintf(buf, sizeof buf, "%.6g", x);
    o += ',';
    o += buf;
  };
  const auto log_row = [&](const ks::FleetReportd* r) {
    std::snprintf(buf, sizeof buf, "%.3f", state.time);
    st += buf;
    for (const auto& v : state.vehicles) {
      const Vector3<double> e = kelp::euler_from_quaternion(v.attitude);
      for (int j = 0; j < 3; ++j) num(st, v.position(j));
      for (int j = 0; j < 3; ++j) num(st, e(j));
      for (int j = 0; j < 3; ++j) num(st, v.nu(j));
    }
    for (const auto& p : state.point_masses)
      for (int j = 0; j < 3; ++j) num(st, p.position(j));
    for (int k = 0; k < m; ++k) {
      num(st, r ? r->force_at_start[std::size_t(k)].norm() : 0.0);
      num(st, r ? r->force_at_end[std::size_t(k)].norm() : 0.0);
      num(st, kelp::tether::unstretched_length(model.tether_of(k, state.tethers[std::size_t(k)]),
                                               state.tethers[std::size_t(k)]));
    }
    series.end_line();
  };
  const auto log_nodes = [&] {
    for (int k = 0; k < m; ++k) {
      const auto& x = state.tethers[std::size_t(k)].position;
      for (Eigen::Index i = 0; i < x.cols(); ++i) {
        std::snprintf(buf, sizeof buf, "%.3f", state.time);
        nt += buf;
        nt += ',';
        nt += f.tethers[std::size_t(k)].name;
        std::snprintf(buf, sizeof buf, ",%ld", static_cast<long>(i));
        nt += buf;
        for (int j = 0; j < 3; ++j) num(nt, x(j, i));
        nodes.end_line();
      }
    }
  };
  // run.mcap (output.mcap, the default): the fleet's ROS 2 bag (kelp/sim/ros2/fleet.hpp), every
  // logged sample, the markers at the node rate (as the pair's bag).
  std::unique_ptr<ros2::FleetBagWriter> bag;
  ros2::FleetSample sample;
  ros2::FleetMessages messages;
  std::vector<Eigen::VectorXd> tensions(static_cast<std::size_t>(m)),
      commands(static_cast<std::size_t>(n));
  double next_marker = 0;
  if (sc.mcap) {
    sample.gravity = env.gravity();
    for (int i = 0; i < n; ++i) {
      ros2::FleetVehicleSample v;
      v.name = f.vehicles[std::size_t(i)].name;
      v.state = &state.vehicles[std::size_t(i)];
      const kv::PropulsionModeld* pm = model.propulsion(i);
      v.thrusters = pm ? static_cast<int>(pm->size()) : 0;
      commands[std::size_t(i)] = Eigen::VectorXd::Zero(v.thrusters);
      v.thrust = state.propulsion[std::size_t(i)].thrust.data();
      v.command = commands[std::size_t(i)].data();
      if (const auto& h = w.vehicles[std::size_t(i)].hull) v.size = 2 * h->half_extents;
      sample.vehicles.push_back(std::move(v));
    }
    for (int k = 0; k < m; ++k) {
      const ks::FleetTether<double>& t = w.parameters.tethers[std::size_t(k)];
      ros2::FleetTetherSample l;
      l.name = t.name;
      l.nodes = &state.tethers[std::size_t(k)].position;
      l.tensions = &tensions[std::size_t(k)];
      if (t.start.kind == ks::EndKind::vehicle) l.start_vehicle = t.start.index;
      if (t.end.kind == ks::EndKind::vehicle) l.end_vehicle = t.end.index;
      sample.tethers.push_back(std::move(l));
    }
    for (const ks::PointMassParametersd& p : w.parameters.point_masses) {
      ros2::FleetPointMassSample q;
      q.name = p.name;
      q.diameter = p.volume > 0 ? std::cbrt(6 * p.volume / kelp::pi) : 0.3;
      sample.point_masses.push_back(std::move(q));
    }
    bag = std::make_unique<ros2::FleetBagWriter>(fs::path(out) / "run.mcap", sample);
  }
  const auto record = [&](const ks::FleetReportd* r, const ks::FleetInputsd& inputs) {
    if (!bag) return;
    sample.time = state.time;
    for (int i = 0; i < n; ++i) {
      ros2::FleetVehicleSample& v = sample.vehicles[std::size_t(i)];
      v.nu_dot = state.vehicle_nu_dot[std::size_t(i)];
      const auto& u = inputs.commands[std::size_t(i)];
      Eigen::VectorXd& c = commands[std::size_t(i)];
      if (u.size() == c.size())
        c = u;
      else
        c.setZero();
    }
    for (int k = 0; k < m; ++k) {
      const auto& x = state.tethers[std::size_t(k)];
      const auto& line = model.tether_of(k, x);
      Eigen::VectorXd& ts = tensions[std::size_t(k)];
      ts.resize(x.position.cols() - 1);
      for (Eigen::Index i = 0; i + 1 < x.position.cols(); ++i)
        ts(i) = kelp::tether::segment_axial_force(line, x, static_cast<int>(i));
      ros2::FleetTetherSample& l = sample.tethers[std::size_t(k)];
      l.force_at_start = r ? r->force_at_start[std::size_t(k)] : Vector3<double>::Zero();
      l.force_at_end = r ? r->force_at_end[std::size_t(k)] : Vector3<double>::Zero();
    }
    for (std::size_t j = 0; j < state.point_masses.size(); ++j)
      sample.point_masses[j].position = state.point_masses[j].position;
    ros2::fill_fleet_messages(sample, messages);
    const bool markers = state.time + 1e-9 >= next_marker;
    if (markers) next_marker = state.time + 1.0 / sc.node_rate;
    bag->write(messages, markers);
  };
  const double dt = 0.01;
  const long steps = std::lround(sc.duration / dt);
  const long log_every = std::max(1L, std::lround(1.0 / (sc.log_rate * dt)));
  const long node_every = std::max(1L, std::lround(1.0 / (sc.node_rate * dt)));
  ks::FleetInputsd in(model);
  for (int k = 0; k < m; ++k)
    if (model.winch(k))
      in.winch_payout_rates[std::size_t(k)] = f.tethers[std::size_t(k)].winch.payout_rate;
  FleetRunSummary s;
  s.notes = w.notes;
  s.max_tension.assign(std::size_t(m), 0.0);
  s.slack_fraction.assign(std::size_t(m), 0.0);
  long newton = 0;
  log_row(nullptr);
  log_nodes();
  record(nullptr, in);
  const auto wall0 = std::chrono::steady_clock::now();
  double next_flush = state.time + 1.0;
  for (long step = 1; step <= steps; ++step) {
    // A stop (kelp/sim/stop.hpp): the run ends here, between two steps.
    if (stop_requested() || (should_stop && should_stop())) break;
    const double t = state.time;
    for (int i = 0; i < n; ++i) {
      Controller& c = control[std::size_t(i)];
      const auto nav = kelp::control::navigation_of(state.vehicles[std::size_t(i)]);
      Vector3<double> error;
      // The controllers' thrust inverse at the battery's voltage; their ESC commands to the
      // vehicle's (as the pair's closed loop does).
      const kv::PropulsionModeld* pm = model.propulsion(i);
      if (c.auv) {
        c.auv->set_voltage(controller_voltage(*pm, state.propulsion[std::size_t(i)]));
        const auto& cmd = c.auv->update(nav, t);
        vehicle_commands(*pm, cmd.command, in.commands[std::size_t(i)]);
        error = cmd.position_error;
      } else if (c.asv) {
        c.asv->set_voltage(controller_voltage(*pm, state.propulsion[std::size_t(i)]));
        const Vector3<double> target =
            c.target >= 0 ? state.vehicles[std::size_t(c.target)].position : nav.position;
        const auto& cmd = c.asv->update(nav, target, t);
        vehicle_commands(*pm, cmd.command, in.commands[std::size_t(i)]);
        error = cmd.position_error;
        error.z() = 0;
      } else {
        continue;
      }
      c.error_sq += error.squaredNorm();
      ++c.samples;
    }
    const ks::FleetReportd& r = ks::step(model, ws, state, in, dt);
    newton += r.tether.newton_iterations;
    s.newton_max = std::max(s.newton_max, r.tether.newton_iterations);
    s.retried_steps += r.tether.retries > 0;
    s.explicit_fallbacks += r.tether_fallbacks;
    for (int k = 0; k < m; ++k) {
      const double a = r.force_at_start[std::size_t(k)].norm(),
                   b = r.force_at_end[std::size_t(k)].norm();
      s.max_tension[std::size_t(k)] = std::max(s.max_tension[std::size_t(k)], std::max(a, b));
      if (b < 0.5 && f.tethers[std::size_t(k)].to != "free")
        s.slack_fraction[std::size_t(k)] += 1.0;
    }
    if (step % log_every == 0) {
      log_row(&r);
      record(&r, in);
    }
    if (step % node_every == 0) log_nodes();
    if (state.time + 1e-9 >= next_flush) {
      next_flush = state.time + 1.0;
      series.write_out();
      nodes.write_out();
    }
    s.steps = step;
  }
  s.completed = s.steps == steps;
  s.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  s.simulated_s = state.time;
  s.newton_mean = s.steps > 0 ? double(newton) / double(s.steps) : 0.0;
  for (double& x : s.slack_fraction) x = s.steps > 0 ? x / double(s.steps) : 0.0;
  for (const Controller& c : control)
    s.rms_position_error.push_back(c.samples > 0 ? std::sqrt(c.error_sq / double(c.samples))
                                                 : std::numeric_limits<double>::quiet_NaN());
  series.close();
  nodes.close();
  if (bag) bag->close();
  // summary.json
  nlohmann::json j;
  j["source"] = "kelp-tethered-pair (fleet)";
  j["scenario"] = file;
  j["completed"] = s.completed;
  j["simulated_s"] = s.simulated_s;
  j["wall_s"] = s.wall_s;
  j["realtime_factor"] = s.wall_s > 0 ? s.simulated_s / s.wall_s : 0.0;
  if (!s.notes.empty()) j["notes"] = s.notes;
  for (int i = 0; i < n; ++i) {
    const auto& x = state.vehicles[std::size_t(i)];
    nlohmann::json v;
    v["vehicle"] = f.vehicles[std::size_t(i)].vehicle;
    v["controller"] = choice_name(f.vehicles[std::size_t(i)].controller.type, fleet_control_names);
    v["final_position_m"] = {x.position.x(), x.position.y(), x.position.z()};
    if (std::isfinite(s.rms_position_error[std::size_t(i)]))
      v["rms_position_error_m"] = s.rms_position_error[std::size_t(i)];
    // The hull box as loaded (file or preset): what the replay draws (kelp/sim/replay.hpp).
    if (const auto& h = w.vehicles[std::size_t(i)].hull)
      v["hull"] = {
          {"center_m", {h->center.x(), h->center.y(), h->center.z()}},
          {"half_extents_m", {h->half_extents.x(), h->half_extents.y(), h->half_extents.z()}}};
    j["vehicles"][f.vehicles[std::size_t(i)].name] = v;
  }
  for (std::size_t i = 0; i < f.point_masses.size(); ++i) {
    const auto& x = state.point_masses[i].position;
    j["point_masses"][f.point_masses[i].name]["final_position_m"] = {x.x(), x.y(), x.z()};
  }
  for (int k = 0; k < m; ++k) {
    nlohmann::json t;
    t["from"] = f.tethers[std::size_t(k)].from;
    t["to"] = f.tethers[std::size_t(k)].to;
    t["max_tension_n"] = s.max_tension[std::size_t(k)];
    t["slack_fraction"] = s.slack_fraction[std::size_t(k)];
    t["final_length_m"] = kelp::tether::unstretched_length(
        model.tether_of(k, state.tethers[std::size_t(k)]), state.tethers[std::size_t(k)]);
    j["tethers"][f.tethers[std::size_t(k)].name] = t;
  }
  j["tether_solver"] = {{"newton_iterations_per_step_mean", s.newton_mean},
                        {"newton_iterations_per_step_max", s.newton_max},
                        {"retried_steps", s.retried_steps},
                        {"explicit_fallbacks", s.explicit_fallbacks}};
  // The scenario as run, every field (as the pair's summary echoes it in `scenario`): what the
  // replay rebuilds the sea and the fleet from when the scenario file is gone or changed.
  j["scenario_echo"] = nlohmann::json::parse(scenario_json(sc));
  // Atomically: a run directory with summary.json has all of it.
  write_file_atomically(fs::path(out) / "summary.json", j.dump(2) + '\n');
  return s;
}

}  // namespace sim
}  // namespace kelp
