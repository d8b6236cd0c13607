// The ROS 2 messages of a run sample (kelp/sim/ros2/messages.hpp) and kelp's frames to ROS's
// (kelp/sim/ros2/frames.hpp): the non-template bodies.
#include <algorithm>
#include <cmath>

#include "kelp/sim/ros2/frames.hpp"
#include "kelp/sim/ros2/messages.hpp"

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

namespace detail {
namespace {
void set(geometry_msgs::Vector3& m, const Eigen::Vector3d& v) {
  m.x = v.x();
  m.y = v.y();
  m.z = v.z();
}
void set(geometry_msgs::Point& m, const Eigen::Vector3d& v) {
  m.x = v.x();
  m.y = v.y();
  m.z = v.z();
}
void set(geometry_msgs::Quaternion& m, const Eigen::Quaterniond& q) {
  m.x = q.x();
  m.y = q.y();
  m.z = q.z();
  m.w = q.w();
}
void header(std_msgs::Header& h, const builtin_interfaces::Time& t, const char* frame) {
  h.stamp = t;
  h.frame_id = frame;  // same length each time: no allocation after the first
}
void odometry(nav_msgs::Odometry& m, const builtin_interfaces::Time& t, const char* child,
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
void end_wrench(geometry_msgs::WrenchStamped& m, const builtin_interfaces::Time& t,
                const char* frame, const kelp::vehicle::VehicleStated& x,
                const Eigen::Vector3d& end, const Eigen::Vector3d& force_ned) {
  header(m.header, t, frame);
  const Eigen::Vector3d f = x.attitude.conjugate() * force_ned;
  const Eigen::Vector3d r = x.attitude.conjugate() * (end - x.position);
  set(m.wrench.force, frd_to_flu(f));
  set(m.wrench.torque, frd_to_flu(r.cross(f)));
}
void joints(sensor_msgs::JointState& m, const builtin_interfaces::Time& t, const char* frame,
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
std_msgs::ColorRGBA tension_colour(double tension, double scale) {
  double f = scale > 0 ? tension / scale : 0;
  f = std::isfinite(f) ? std::min(1.0, std::max(0.0, f)) : 0;
  std_msgs::ColorRGBA c;
  c.r = static_cast<float>(f);
  c.g = 0.2f;
  c.b = static_cast<float>(1 - f);
  c.a = 1;
  return c;
}
void box(visualization_msgs::Marker& m, const builtin_interfaces::Time& t, const char* frame,
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
}  // namespace
}  // namespace detail

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
  for (int i = 0; i < 2; ++i) {
    geometry_msgs::TransformStamped& ts = m.tf.transforms[static_cast<std::size_t>(i)];
    detail::header(ts.header, t, world_frame);
    ts.child_frame_id = frames[i];
    detail::set(ts.transform.translation, ned_to_enu(bodies[i]->position));
    detail::set(ts.transform.rotation, ned_frd_to_enu_flu(bodies[i]->attitude));
  }

  detail::odometry(m.boat_odom, t, boat_frame, boat);
  detail::odometry(m.rov_odom, t, rov_frame, rov);

  detail::header(m.rov_imu.header, t, rov_frame);
  detail::set(m.rov_imu.orientation, ned_frd_to_enu_flu(rov.attitude));
  detail::set(m.rov_imu.angular_velocity, frd_to_flu(rov.nu.tail<3>()));
  if (s.rov_nu_dot.allFinite()) {
    const Eigen::Vector3d v = rov.nu.head<3>(), w = rov.nu.tail<3>();
    const Eigen::Vector3d f = s.rov_nu_dot.head<3>() + w.cross(v) -
                              rov.attitude.conjugate() * Eigen::Vector3d(0, 0, s.gravity);
    detail::set(m.rov_imu.linear_acceleration, frd_to_flu(f));
    m.rov_imu.linear_acceleration_covariance[0] = 0;
  } else {
    m.rov_imu.linear_acceleration = geometry_msgs::Vector3{};
    m.rov_imu.linear_acceleration_covariance[0] = -1;
  }

  detail::end_wrench(m.boat_end_force, t, boat_frame, boat, nodes.col(0), s.force_on_boat);
  detail::end_wrench(m.rov_end_force, t, rov_frame, rov, nodes.col(n - 1), s.force_on_rov);

  m.markers.markers.resize(3);
  visualization_msgs::Marker& line = m.markers.markers[0];
  detail::header(line.header, t, world_frame);
  line.ns = "tether";
  line.id = 0;
  line.type = visualization_msgs::Marker::LINE_STRIP;
  line.action = visualization_msgs::Marker::ADD;
  line.pose = geometry_msgs::Pose{};
  line.scale = geometry_msgs::Vector3{};
  line.scale.x = 0.03;  // line width [m]
  line.color = detail::tension_colour(0, 1);
  line.points.resize(static_cast<std::size_t>(n));
  line.colors.resize(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    detail::set(line.points[k], ned_to_enu(nodes.col(i)));
    double tension = 0;
    if (s.tensions) {
      const Eigen::VectorXd& ts = *s.tensions;
      // A vertex takes the larger tension of the segments that meet there.
      tension = i == 0 ? ts(0) : i == n - 1 ? ts(n - 2) : std::max(ts(i - 1), ts(i));
    }
    line.colors[k] = detail::tension_colour(tension, s.tension_scale);
  }
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
