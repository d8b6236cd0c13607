// A fleet's ROS 2 messages and bag (kelp/sim/ros2/fleet.hpp).
#include "kelp/sim/ros2/fleet.hpp"

#include <cmath>
#include <set>
#include <string>

#include "kelp/core/error.hpp"
#include "kelp/vehicle/propulsion.hpp"
#include "message_parts.hpp"

namespace kelp {
namespace ros2 {

namespace {

void check_name(const std::string& name, const char* what) {
  KELP_CHECK(is_ros_name(name), std::string("ros2: the ") + what + " name \"" + name +
                                    "\" is not a ROS name (a letter, then letters, digits and "
                                    "single underscores, at most 64 characters)");
}

const char* const thruster_names[kelp::vehicle::max_thrusters] = {
    "thruster1", "thruster2", "thruster3", "thruster4",
    "thruster5", "thruster6", "thruster7", "thruster8"};

}  // namespace

void fill_fleet_messages(const FleetSample& s, FleetMessages& m) {
  const std::size_t nv = s.vehicles.size(), nt = s.tethers.size(), np = s.point_masses.size();
  for (const FleetVehicleSample& v : s.vehicles) {
    check_name(v.name, "vehicle");
    KELP_CHECK(v.state, "ros2::fill_fleet_messages: vehicle \"" + v.name + "\" has no state");
    KELP_CHECK(v.thrusters >= 0 && v.thrusters <= kelp::vehicle::max_thrusters &&
                   (v.thrusters == 0 || (v.thrust && v.command)),
               "ros2::fill_fleet_messages: vehicle \"" + v.name +
                   "\": 0 to 8 thrusters, with their thrusts and commands");
  }
  for (const FleetTetherSample& l : s.tethers) {
    check_name(l.name, "tether");
    KELP_CHECK(l.nodes && l.nodes->cols() >= 2,
               "ros2::fill_fleet_messages: tether \"" + l.name + "\" needs its nodes (at least 2)");
    KELP_CHECK(
        !l.tensions || l.tensions->size() == l.nodes->cols() - 1,
        "ros2::fill_fleet_messages: tether \"" + l.name + "\": one tension a segment (nodes - 1)");
    for (const int e : {l.start_vehicle, l.end_vehicle})
      KELP_CHECK(e >= -1 && e < static_cast<int>(nv),
                 "ros2::fill_fleet_messages: tether \"" + l.name + "\" ends on vehicle " +
                     std::to_string(e) + " of " + std::to_string(nv));
  }
  for (const FleetPointMassSample& p : s.point_masses) check_name(p.name, "point mass");
  const builtin_interfaces::Time t = to_time(s.time);

  m.frames.resize(nv);
  for (std::size_t i = 0; i < nv; ++i) {
    const std::string& name = s.vehicles[i].name;
    std::string& f = m.frames[i];
    if (f.size() != name.size() + 10 || f.compare(0, name.size(), name) != 0)
      f = name + "/base_link";
  }
  m.clock.clock = t;

  m.tf.transforms.resize(nv + np);
  for (std::size_t i = 0; i < nv; ++i)
    detail::transform(m.tf.transforms[i], t, m.frames[i].c_str(), s.vehicles[i].state->position,
                      s.vehicles[i].state->attitude);
  for (std::size_t j = 0; j < np; ++j)
    detail::transform(m.tf.transforms[nv + j], t, s.point_masses[j].name.c_str(),
                      s.point_masses[j].position, Eigen::Quaterniond::Identity());

  m.odom.resize(nv);
  m.imu.resize(nv);
  m.thrusters.resize(nv);
  for (std::size_t i = 0; i < nv; ++i) {
    const FleetVehicleSample& v = s.vehicles[i];
    const char* frame = m.frames[i].c_str();
    detail::odometry(m.odom[i], t, frame, *v.state);
    detail::imu(m.imu[i], t, frame, *v.state, v.nu_dot, s.gravity);
    detail::joints(m.thrusters[i], t, frame, thruster_names, v.thrusters, v.command, v.thrust);
  }

  m.end_forces.resize(2 * nt);
  for (std::size_t k = 0; k < nt; ++k) {
    const FleetTetherSample& l = s.tethers[k];
    const Eigen::Index n = l.nodes->cols();
    const int holders[2] = {l.start_vehicle, l.end_vehicle};
    const Eigen::Vector3d forces[2] = {l.force_at_start, l.force_at_end};
    for (int e = 0; e < 2; ++e) {
      geometry_msgs::WrenchStamped& w = m.end_forces[2 * k + std::size_t(e)];
      const Eigen::Vector3d node = l.nodes->col(e == 0 ? 0 : n - 1);
      if (holders[e] >= 0) {
        const auto i = static_cast<std::size_t>(holders[e]);
        detail::end_wrench(w, t, m.frames[i].c_str(), *s.vehicles[i].state, node, forces[e]);
      } else {  // an anchor, a point mass or a free end: the force in `world`, about the node
        detail::header(w.header, t, world_frame);
        detail::set(w.wrench.force, ned_to_enu(forces[e]));
        w.wrench.torque = geometry_msgs::Vector3{};
      }
    }
  }

  m.markers.markers.resize(nt + nv + np);
  for (std::size_t k = 0; k < nt; ++k)
    detail::line_strip(m.markers.markers[k], t, s.tethers[k].name, *s.tethers[k].nodes,
                       s.tethers[k].tensions, s.tension_scale);
  for (std::size_t i = 0; i < nv; ++i)
    detail::box(m.markers.markers[nt + i], t, m.frames[i].c_str(), s.vehicles[i].name.c_str(),
                s.vehicles[i].size, 0.9f, 0.7f, 0.1f);
  for (std::size_t j = 0; j < np; ++j) {
    visualization_msgs::Marker& b = m.markers.markers[nt + nv + j];
    const double d = s.point_masses[j].diameter;
    detail::box(b, t, s.point_masses[j].name.c_str(), s.point_masses[j].name.c_str(),
                Eigen::Vector3d(d, d, d), 0.6f, 0.6f, 0.6f);
    b.type = visualization_msgs::Marker::SPHERE;
  }
}

FleetBagWriter::FleetBagWriter(const std::filesystem::path& path, const FleetSample& layout,
                               const McapOptions& options) {
  std::set<std::string> vehicles, tethers;
  for (const FleetVehicleSample& v : layout.vehicles) {
    check_name(v.name, "vehicle");
    KELP_CHECK(vehicles.insert(v.name).second,
               "ros2::FleetBagWriter: two vehicles named \"" + v.name + "\"");
  }
  for (const FleetTetherSample& l : layout.tethers) {
    check_name(l.name, "tether");
    KELP_CHECK(tethers.insert(l.name).second,
               "ros2::FleetBagWriter: two tethers named \"" + l.name + "\"");
  }
  mcap_.open(path, options);
  std::uint16_t odometry = 0, imu = 0, joints = 0, wrench = 0;
  const auto schema = [&](std::uint16_t& id, const char* type, const std::string& text) {
    if (id == 0) id = mcap_.add_schema(type, "ros2msg", text);
    return id;
  };
  const auto channel = [&](std::uint16_t schema_id, const std::string& topic, const Qos& qos) {
    const std::uint16_t c = mcap_.add_channel(schema_id, topic, "cdr",
                                              {{"offered_qos_profiles", offered_qos_yaml(qos)}});
    if (sequence_.size() <= c) sequence_.resize(std::size_t(c) + 1, 0);
    return c;
  };
  clock_ = channel(mcap_.add_schema(rosgraph_msgs::Clock::type_name, "ros2msg",
                                    schema_text<rosgraph_msgs::Clock>()),
                   "/clock", clock_qos);
  tf_ = channel(mcap_.add_schema(tf2_msgs::TFMessage::type_name, "ros2msg",
                                 schema_text<tf2_msgs::TFMessage>()),
                "/tf", tf_qos);
  for (const FleetVehicleSample& v : layout.vehicles) {
    odom_.push_back(
        channel(schema(odometry, nav_msgs::Odometry::type_name, schema_text<nav_msgs::Odometry>()),
                "/" + v.name + "/odom", state_qos));
    imu_.push_back(
        channel(schema(imu, sensor_msgs::Imu::type_name, schema_text<sensor_msgs::Imu>()),
                "/" + v.name + "/imu", sensor_data_qos));
    thrusters_.push_back(v.thrusters > 0
                             ? channel(schema(joints, sensor_msgs::JointState::type_name,
                                              schema_text<sensor_msgs::JointState>()),
                                       "/" + v.name + "/thrusters", sensor_data_qos)
                             : std::uint16_t(0));
  }
  for (const FleetTetherSample& l : layout.tethers)
    end_forces_.push_back(channel(schema(wrench, geometry_msgs::WrenchStamped::type_name,
                                         schema_text<geometry_msgs::WrenchStamped>()),
                                  "/" + l.name + "/end_forces", sensor_data_qos));
  markers_ = channel(mcap_.add_schema(visualization_msgs::MarkerArray::type_name, "ros2msg",
                                      schema_text<visualization_msgs::MarkerArray>()),
                     "/markers", state_qos);
}

template <class M>
void FleetBagWriter::put(std::uint16_t channel, const M& m, const builtin_interfaces::Time& stamp) {
  serialize(m, buf_);
  mcap_.write(channel, sequence_[channel]++, to_nanoseconds(stamp), buf_.data(), buf_.size());
}

void FleetBagWriter::write(const FleetMessages& m, bool markers) {
  KELP_CHECK(m.odom.size() == odom_.size() && m.imu.size() == imu_.size() &&
                 m.thrusters.size() == thrusters_.size() &&
                 m.end_forces.size() == 2 * end_forces_.size(),
             "ros2::FleetBagWriter::write: the messages are not of the bag's vehicles and tethers");
  const builtin_interfaces::Time& t = m.clock.clock;
  put(clock_, m.clock, t);
  put(tf_, m.tf, t);
  for (std::size_t i = 0; i < odom_.size(); ++i) {
    put(odom_[i], m.odom[i], t);
    put(imu_[i], m.imu[i], t);
    if (thrusters_[i] != 0) put(thrusters_[i], m.thrusters[i], t);
  }
  for (std::size_t k = 0; k < end_forces_.size(); ++k) {
    put(end_forces_[k], m.end_forces[2 * k], t);
    put(end_forces_[k], m.end_forces[2 * k + 1], t);
  }
  if (markers) put(markers_, m.markers, t);
}

}  // namespace ros2
}  // namespace kelp
