// The tethered pair a scenario describes (system parameters, sea, start poses) and the CSV files
// a run writes (timeseries.csv, nodes.csv). Shared by kelp-tethered-pair and kelp-sitl, so that
// a run flown by kelp's controllers and one flown by ArduPilot SITL are the same world, logged
// in the same format and plotted by the same script (plot_run.py).
#pragma once

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "kelp/core/rotation.hpp"
#include "kelp/system/presets.hpp"
#include "kelp/tether/presets.hpp"
#include "scenario.hpp"

namespace tethered_pair {

/// What a scenario builds: the system's parameters, its sea and the vehicles' start.
struct WorldSetup {
  kelp::system::SystemParametersd parameters;
  kelp::environment::Environmentd environment;
  kelp::system::presets::StartPoses<double> start;
};

/// The system, the sea and the start poses of `sc`. `file` names the scenario in errors.
/// \throws scenario_error when the tether cannot span the start poses; kelp::invalid_argument
/// from the library for parameters it refuses.
inline WorldSetup world_setup(const Scenario& sc, const std::string& file) {
  namespace sp = kelp::system::presets;
  namespace ke = kelp::environment;
  const sp::TetherKind kind =
      sc.tether_kind == "bead_chain" ? sp::TetherKind::bead_chain : sp::TetherKind::rov_tether;
  kelp::system::SystemParametersd params = sp::paper_system(sc.tether_length, kind);
  if (kind == sp::TetherKind::rov_tether)
    params.tether = kelp::tether::presets::rov_tether(sc.tether_length, sc.segment_length);
  auto& tp = params.tether;
  if (sc.diameter > 0) tp.diameter = sc.diameter;
  if (sc.mass_per_length > 0) tp.mass_per_length = sc.mass_per_length;
  if (sc.axial_stiffness > 0) tp.axial_stiffness = sc.axial_stiffness;
  if (sc.internal_damping >= 0) tp.internal_damping = sc.internal_damping;
  if (sc.normal_drag >= 0) tp.normal_drag = sc.normal_drag;
  if (sc.tangential_drag >= 0) tp.tangential_drag = sc.tangential_drag;
  params.asv_attachment = sc.asv_attachment;
  params.auv_attachment = sc.auv_attachment;
  ke::SeaStateOptions sea_options;
  sea_options.seed = sc.seed;
  sea_options.wave_components = sc.wave_components;
  ke::SeaState sea = ke::presets::calm();
  if (sc.sea == "moderate") sea = ke::presets::moderate();
  if (sc.sea == "rough") sea = ke::presets::rough();
  if (sc.sea == "custom") {
    sea = ke::SeaState{};  // no waves unless a height is given
    sea.significant_height = sc.significant_height;
    sea.peak_period = sc.peak_period;
    if (sc.significant_height > 0)
      sea.peak_enhancement = ke::dnv_peak_enhancement(sc.significant_height, sc.peak_period);
    sea.wind_speed = sc.wind_speed;
    sea.current_speed = sc.current_speed;
    sea.wave_direction = sc.wave_direction;
    sea.wind_direction = sc.wind_direction;
    sea.current_direction = sc.current_direction;
  }
  sp::StartPoses<double> start = sp::paper_start(sc.tether_length);
  if (!sc.auv_start.empty())
    start.auv.position = kelp::Vector3<double>(sc.auv_start[0], sc.auv_start[1], sc.auv_start[2]);
  const double span = (start.auv.point_position(params.auv_attachment) -
                       start.asv.point_position(params.asv_attachment))
                          .norm();
  if (span > sc.tether_length)
    throw scenario_error(file + ": /tether/length: " + std::to_string(sc.tether_length) +
                         " m is shorter than the initial distance between its ends (" +
                         std::to_string(span) + " m)");
  return {params, ke::make_environment<double>(sea, sea_options), start};
}

/// One row of timeseries.csv. Quantities a run does not have (the AUV's target and path error
/// when an autopilot flies it) are NaN, written as `nan`.
struct LogRow {
  static constexpr double none = std::numeric_limits<double>::quiet_NaN();
  double t = 0;
  const kelp::vehicle::VehicleStated* asv = nullptr;
  const kelp::vehicle::VehicleStated* auv = nullptr;
  kelp::Vector3<double> auv_target = kelp::Vector3<double>::Constant(none);
  double auv_error = none, asv_error = none;
  Eigen::Vector2d asv_thrust = Eigen::Vector2d::Constant(none);   ///< port, starboard [N]
  Eigen::Vector2d asv_command = Eigen::Vector2d::Constant(none);  ///< normalised
  Eigen::Matrix<double, 8, 1> auv_thrust =
      Eigen::Matrix<double, 8, 1>::Constant(none);  ///< [N], motor order
  Eigen::Matrix<double, 8, 1> auv_command =
      Eigen::Matrix<double, 8, 1>::Constant(none);  ///< normalised
  double tension_asv = 0, tension_auv = 0;          ///< tether force on each vehicle [N]
};

/// timeseries.csv and nodes.csv of a run (the columns are documented in the example's README).
class RunLog {
 public:
  explicit RunLog(const std::filesystem::path& dir) {
    std::filesystem::create_directories(dir);
    ts_.open(dir / "timeseries.csv");
    nodes_.open(dir / "nodes.csv");
    if (!ts_ || !nodes_)
      throw std::runtime_error("cannot write the run's CSV files in " + dir.string());
    ts_ << "t,asv_x,asv_y,asv_z,asv_roll,asv_pitch,asv_yaw,asv_u,asv_v,asv_r,"
           "auv_x,auv_y,auv_z,auv_roll,auv_pitch,auv_yaw,auv_u,auv_v,auv_w,"
           "auv_target_x,auv_target_y,auv_target_z,auv_error,asv_error,"
           "asv_thrust_port,asv_thrust_starboard";
    for (int i = 1; i <= 8; ++i) ts_ << ",auv_thrust_" << i;
    ts_ << ",asv_command_port,asv_command_starboard";
    for (int i = 1; i <= 8; ++i) ts_ << ",auv_command_" << i;
    ts_ << ",tension_asv,tension_auv\n";
    nodes_ << "t,node,x,y,z\n";
  }

  void row(const LogRow& r) {
    const Eigen::Vector3d ea = kelp::euler_from_quaternion(r.asv->attitude);
    const Eigen::Vector3d eb = kelp::euler_from_quaternion(r.auv->attitude);
    const auto& a = *r.asv;
    const auto& b = *r.auv;
    ts_ << num(r.t);
    for (double v :
         {a.position.x(),   a.position.y(), a.position.z(), ea.x(),           ea.y(),
          ea.z(),           a.nu(0),        a.nu(1),        a.nu(5),          b.position.x(),
          b.position.y(),   b.position.z(), eb.x(),         eb.y(),           eb.z(),
          b.nu(0),          b.nu(1),        b.nu(2),        r.auv_target.x(), r.auv_target.y(),
          r.auv_target.z(), r.auv_error,    r.asv_error,    r.asv_thrust(0),  r.asv_thrust(1)})
      ts_ << ',' << num(v);
    for (int i = 0; i < 8; ++i) ts_ << ',' << num(r.auv_thrust(i));
    ts_ << ',' << num(r.asv_command(0)) << ',' << num(r.asv_command(1));
    for (int i = 0; i < 8; ++i) ts_ << ',' << num(r.auv_command(i));
    ts_ << ',' << num(r.tension_asv) << ',' << num(r.tension_auv) << '\n';
  }

  void nodes(double t, const kelp::tether::TetherStated& tether) {
    for (Eigen::Index i = 0; i < tether.position.cols(); ++i)
      nodes_ << num(t) << ',' << i << ',' << num(tether.position(0, i)) << ','
             << num(tether.position(1, i)) << ',' << num(tether.position(2, i)) << '\n';
  }

  void flush() {
    ts_.flush();
    nodes_.flush();
  }
  void close() {
    ts_.close();
    nodes_.close();
  }

 private:
  const char* num(double v) {
    std::snprintf(buf_, sizeof buf_, "%.6g", v);
    return buf_;
  }
  std::ofstream ts_, nodes_;
  char buf_[64] = {};
};

}  // namespace tethered_pair
