// The ROS 2 messages of a run sample (kelp/sim/ros2/messages.hpp) and kelp's frames to ROS's
// (kelp/sim/ros2/frames.hpp): the non-template bodies.
#include <algorithm>
#include <cmath>

#include "kelp/sim/ros2/frames.hpp"
#include "kelp/sim/ros2/messages.hpp"
#include "message_parts.hpp"

namespace kelp {
namespace ros2 {

Eigen::Quaterniond ned_frd_to_enu_flu(const Eigen::Quaterniond& q) {
  const double s = std::sqrt(0.5);
  const Eigen::Quaterniond world(0.0, s, s, 0.0);     // ENU ← NED
  const Eigen::Quaterniond body(0.0, 1.0, 0.0, 0.0);  // FRD ← FLU (its own inverse)
  Eigen::Quaterniond r = world * q * body;
  if (r.w() < 0) r.coeffs() = -r.coeffs();
  return r;
}

namespace detail {
std::string short_name(const std::string& type) {
  const auto p = type.find("/msg/");
  return p == std::string::npos ? type : type.substr(0, p) + type.substr(p + 4);
}
}  // namespace detail

const std::array<Topic, static_cast<int>(TopicId::count)>& topics() {
  static const std::array<Topic, static_cast<int>(TopicId::count)> t = {{
      {TopicId::clock, "/clock", rosgraph_msgs::Clock::type_name, clock_qos},
      {TopicId::tf, "/tf", tf2_msgs::TFMessage::type_name, tf_qos},
      {TopicId::boat_odom, "/boat/odom", nav_msgs::Odometry::type_name, state_qos},
      {TopicId::rov_odom, "/rov/odom", nav_msgs::Odometry::type_name, state_qos},
      {TopicId::rov_imu, "/rov/imu", sensor_msgs::Imu::type_name, sensor_data_qos},
      {TopicId::end_forces, "/tether/end_forces", geometry_msgs::WrenchStamped::type_name,
       sensor_data_qos},
      {TopicId::markers, "/tether/markers", visualization_msgs::MarkerArray::type_name, state_qos},
      {TopicId::rov_thrusters, "/rov/thrusters", sensor_msgs::JointState::type_name,
       sensor_data_qos},
      {TopicId::boat_thrusters, "/boat/thrusters", sensor_msgs::JointState::type_name,
       sensor_data_qos},
  }};
  return t;
}

builtin_interfaces::Time to_time(double t) {
  KELP_CHECK(std::isfinite(t) && t >= 0 && t < 2147483647.0,
             "ros2::to_time: the time must be finite, >= 0 and < 2^31 s");
  double s = std::floor(t);
  long long ns = std::llround((t - s) * 1e9);
  if (ns >= 1000000000LL) {
    s += 1;
    ns -= 1000000000LL;
  }
  builtin_interfaces::Time r;
  r.sec = static_cast<std::int32_t>(s);
  r.nanosec = static_cast<std::uint32_t>(ns);
  return r;
}

void fill_messages(const RunSample& s, Messages& m) {
  KELP_CHECK(s.boat && s.rov, "ros2::fill_messages: the sample needs both vehicle states");
  KELP_CHECK(s.nodes && s.nodes->cols() >= 2,
             "ros2::fill_messages: the sample needs the tether's nodes (at least 2)");
  KELP_CHECK(!s.tensions || s.tensions->size() == s.nodes->cols() - 1,
             "ros2::fill_messages: one tension a segment (nodes - 1)");
  const builtin_interfaces::Time t = to_time(s.time);
  const auto& boat = *s.boat;
  const auto& rov = *s.rov;
  const auto& nodes = *s.nodes;
  const Eigen::Index n = nodes.cols();

  m.clock.clock = t;

  m.tf.transforms.resize(2);
  const kelp::vehicle::VehicleStated* bodies[2] = {&boat, &rov};
  const char* frames[2] = {boat_frame, rov_frame};
  for (int i = 0; i < 2; ++i)
    detail::transform(m.tf.transforms[static_cast<std::size_t>(i)], t, frames[i],
                      bodies[i]->position, bodies[i]->attitude);

  detail::odometry(m.boat_odom, t, boat_frame, boat);
  detail::odometry(m.rov_odom, t, rov_frame, rov);

  detail::imu(m.rov_imu, t, rov_frame, rov, s.rov_nu_dot, s.gravity);

  detail::end_wrench(m.boat_end_force, t, boat_frame, boat, nodes.col(0), s.force_on_boat);
  detail::end_wrench(m.rov_end_force, t, rov_frame, rov, nodes.col(n - 1), s.force_on_rov);

  m.markers.markers.resize(3);
  detail::line_strip(m.markers.markers[0], t, "tether", nodes, s.tensions, s.tension_scale);
  // Display boxes: BlueBoat ~1.2 × 1.0 × 0.3 m, BlueROV2 Heavy ~0.46 × 0.58 × 0.25 m.
  detail::box(m.markers.markers[1], t, boat_frame, "boat", Eigen::Vector3d(1.2, 1.0, 0.3), 0.1f,
              0.4f, 0.9f);
  detail::box(m.markers.markers[2], t, rov_frame, "rov", Eigen::Vector3d(0.46, 0.58, 0.25), 0.9f,
              0.7f, 0.1f);

  static const char* const rov_names[8] = {"thruster1", "thruster2", "thruster3", "thruster4",
                                           "thruster5", "thruster6", "thruster7", "thruster8"};
  static const char* const boat_names[2] = {"port", "starboard"};
  detail::joints(m.rov_thrusters, t, rov_frame, rov_names, 8, s.rov_command.data(),
                 s.rov_thrust.data());
  detail::joints(m.boat_thrusters, t, boat_frame, boat_names, 2, s.boat_command.data(),
                 s.boat_thrust.data());
}

}  // namespace ros2
}  // namespace kelp
