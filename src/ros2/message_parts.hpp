// The parts of kelp's ROS 2 messages that the pair's topics (messages.cpp) and a fleet's
// (fleet.cpp) share: kelp's NED/FRD values into the messages' ENU/FLU fields. Private to
// kelp::sim.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>

#include "kelp/sim/ros2/frames.hpp"
#include "kelp/sim/ros2/messages.hpp"

namespace kelp {
namespace ros2 {
namespace detail {

inline void set(geometry_msgs::Vector3& m, const Eigen::Vector3d& v) {
  m.x = v.x();
  m.y = v.y();
  m.z = v.z();
}
inline void set(geometry_msgs::Point& m, const Eigen::Vector3d& v) {
  m.x = v.x();
  m.y = v.y();
  m.z = v.z();
}
inline void set(geometry_msgs::Quaternion& m, const Eigen::Quaterniond& q) {
  m.x = q.x();
  m.y = q.y();
  m.z = q.z();
  m.w = q.w();
}
inline void header(std_msgs::Header& h, const builtin_interfaces::Time& t, const char* frame) {
  h.stamp = t;
  h.frame_id = frame;  // same length each time: no allocation after the first
}
inline void odometry(nav_msgs::Odometry& m, const builtin_interfaces::Time& t, const char* child,
                     const kelp::vehicle::VehicleStated& x) {
  header(m.header, t, world_frame);
  m.child_frame_id = child;
  set(m.pose.pose.position, ned_to_enu(x.position));
  set(m.pose.pose.orientation, ned_frd_to_enu_flu(x.attitude));
  set(m.twist.twist.linear, frd_to_flu(x.nu.head<3>()));
  set(m.twist.twist.angular, frd_to_flu(x.nu.tail<3>()));
}
// The tether force on a vehicle as a wrench in its body frame (FLU) about its origin: the force
// acts at the tether's end node, r = Rᵀ (p_end − p) from the body origin.
inline void end_wrench(geometry_msgs::WrenchStamped& m, const builtin_interfaces::Time& t,
                       const char* frame, const kelp::vehicle::VehicleStated& x,
                       const Eigen::Vector3d& end, const Eigen::Vector3d& force_ned) {
  header(m.header, t, frame);
  const Eigen::Vector3d f = x.attitude.conjugate() * force_ned;
  const Eigen::Vector3d r = x.attitude.conjugate() * (end - x.position);
  set(m.wrench.force, frd_to_flu(f));
  set(m.wrench.torque, frd_to_flu(r.cross(f)));
}
inline void joints(sensor_msgs::JointState& m, const builtin_interfaces::Time& t, const char* frame,
                   const char* const* names, int n, const double* command, const double* thrust) {
  header(m.header, t, frame);
  m.name.resize(static_cast<std::size_t>(n));
  m.velocity.resize(static_cast<std::size_t>(n));
  m.effort.resize(static_cast<std::size_t>(n));
  m.position.clear();
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    m.name[k] = names[i];
    m.velocity[k] = command[i];
    m.effort[k] = thrust[i];
  }
}
// Tension → colour: blue (0 N) to red (≥ scale), opaque.
inline std_msgs::ColorRGBA tension_colour(double tension, double scale) {
  double f = scale > 0 ? tension / scale : 0;
  f = std::isfinite(f) ? std::min(1.0, std::max(0.0, f)) : 0;
  std_msgs::ColorRGBA c;
  c.r = static_cast<float>(f);
  c.g = 0.2f;
  c.b = static_cast<float>(1 - f);
  c.a = 1;
  return c;
}
inline void box(visualization_msgs::Marker& m, const builtin_interfaces::Time& t, const char* frame,
                const char* ns, const Eigen::Vector3d& size, float r, float g, float b) {
  header(m.header, t, frame);
  m.ns = ns;
  m.id = 0;
  m.type = visualization_msgs::Marker::CUBE;
  m.action = visualization_msgs::Marker::ADD;
  m.pose = geometry_msgs::Pose{};
  set(m.scale, size);
  m.color.r = r;
  m.color.g = g;
  m.color.b = b;
  m.color.a = 0.9f;
  m.frame_locked = true;
}
// World → a body's frame on /tf: its pose in ENU/FLU.
inline void transform(geometry_msgs::TransformStamped& ts, const builtin_interfaces::Time& t,
                      const char* child, const Eigen::Vector3d& position_ned,
                      const Eigen::Quaterniond& attitude) {
  header(ts.header, t, world_frame);
  ts.child_frame_id = child;
  set(ts.transform.translation, ned_to_enu(position_ned));
  set(ts.transform.rotation, ned_frd_to_enu_flu(attitude));
}
// An IMU on a body at its origin: orientation, rates and the specific force
// f = ν̇₁ + ω × ν₁ − Rᵀ g e_z (body; kelp/nav/sensors.hpp's ideal accelerometer) in FLU; with ν̇
// unknown the linear acceleration is zero and its covariance's element 0 is −1 ("no estimate").
inline void imu(sensor_msgs::Imu& m, const builtin_interfaces::Time& t, const char* frame,
                const kelp::vehicle::VehicleStated& x, const Eigen::Matrix<double, 6, 1>& nu_dot,
                double gravity) {
  header(m.header, t, frame);
  set(m.orientation, ned_frd_to_enu_flu(x.attitude));
  set(m.angular_velocity, frd_to_flu(x.nu.tail<3>()));
  if (nu_dot.allFinite()) {
    const Eigen::Vector3d v = x.nu.head<3>(), w = x.nu.tail<3>();
    const Eigen::Vector3d f =
        nu_dot.head<3>() + w.cross(v) - x.attitude.conjugate() * Eigen::Vector3d(0, 0, gravity);
    set(m.linear_acceleration, frd_to_flu(f));
    m.linear_acceleration_covariance[0] = 0;
  } else {
    m.linear_acceleration = geometry_msgs::Vector3{};
    m.linear_acceleration_covariance[0] = -1;
  }
}
// A tether as a LINE_STRIP in `world` through its nodes, each vertex coloured by the larger
// tension of the segments that meet there (blue 0 N → red `scale`); no tensions: uncoloured.
inline void line_strip(visualization_msgs::Marker& line, const builtin_interfaces::Time& t,
                       const std::string& ns, const Eigen::Matrix<double, 3, Eigen::Dynamic>& nodes,
                       const Eigen::VectorXd* tensions, double scale) {
  const Eigen::Index n = nodes.cols();
  header(line.header, t, world_frame);
  line.ns = ns;
  line.id = 0;
  line.type = visualization_msgs::Marker::LINE_STRIP;
  line.action = visualization_msgs::Marker::ADD;
  line.pose = geometry_msgs::Pose{};
  line.scale = geometry_msgs::Vector3{};
  line.scale.x = 0.03;  // line width [m]
  line.color = tension_colour(0, 1);
  line.points.resize(static_cast<std::size_t>(n));
  line.colors.resize(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    set(line.points[k], ned_to_enu(nodes.col(i)));
    double tension = 0;
    if (tensions) {
      const Eigen::VectorXd& ts = *tensions;
      tension = i == 0 ? ts(0) : i == n - 1 ? ts(n - 2) : std::max(ts(i - 1), ts(i));
    }
    line.colors[k] = tension_colour(tension, scale);
  }
}

}  // namespace detail
}  // namespace ros2
}  // namespace kelp
