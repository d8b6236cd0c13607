// The DDS side of kelp-tethered-pair --ros2 (Cyclone DDS's C API): a participant, and the
// publisher of the run's ROS 2 messages. The messages are the ones the MCAP bag holds
// (kelp::sim::Ros2Sampler → kelp::ros2::Messages, filled by kelp::ros2::fill_messages); here they
// are only copied, field by field, into the C structs idlc generates from idl/, whose DDS type
// names are ROS 2's. Included by bridge.cpp only.
#pragma once

#include <dds/dds.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "builtin_interfaces.h"
#include "geometry_msgs.h"
#include "kelp/sim/closed_loop.hpp"
#include "kelp/sim/ros2.hpp"
#include "kelp/sim/ros2/messages.hpp"
#include "nav_msgs.h"
#include "rosgraph_msgs.h"
#include "sensor_msgs.h"
#include "std_msgs.h"
#include "tf2_msgs.h"
#include "visualization_msgs.h"

namespace kelp_ros2 {

/// A new DDS QoS of a ROS 2 QoS profile (kelp::ros2::Qos: reliability, durability, keep-last
/// depth), with XCDR1 as the only data representation; the caller deletes it (dds_delete_qos).
dds_qos_t* make_qos(const kelp::ros2::Qos& qos);

/// A DDS domain participant and its topics, readers and writers, named as ROS 2 names them.
class Participant {
 public:
  /// A participant in `domain` (negative: ROS_DOMAIN_ID, else 0). \throws kelp::error.
  explicit Participant(int domain);
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;
  /// A writer of ROS topic `ros_name` (DDS topic "rt" + ros_name) of type `type`.
  dds_entity_t writer(const dds_topic_descriptor_t* type, const std::string& ros_name,
                      const kelp::ros2::Qos& qos);
  /// A reader of ROS topic `ros_name`.
  dds_entity_t reader(const dds_topic_descriptor_t* type, const std::string& ros_name,
                      const kelp::ros2::Qos& qos);
  /// Writes a sample. \throws kelp::error naming `what` when DDS refuses.
  void write(dds_entity_t writer, const void* sample, const char* what);
  dds_entity_t handle() const { return participant_; }
  int domain() const { return domain_; }

 private:
  dds_entity_t topic(const dds_topic_descriptor_t* type, const std::string& ros_name);
  dds_entity_t participant_ = 0;
  int domain_ = 0;
};

namespace c {
// kelp::ros2's C++ messages → idlc's C structs. Strings and sequences point into the C++ message
// (Cyclone only reads them while writing), so the message must outlive the write.
inline char* str(const std::string& s) { return const_cast<char*>(s.c_str()); }
template <class Seq, class T>
void seq(Seq& s, T* data, std::size_t n) {
  s._maximum = s._length = static_cast<std::uint32_t>(n);
  s._buffer = data;
  s._release = false;
}
template <class Seq>
void empty(Seq& s) {
  s._maximum = s._length = 0;
  s._buffer = nullptr;
  s._release = false;
}
inline void conv(const kelp::ros2::builtin_interfaces::Time& m,
                 builtin_interfaces_msg_dds__Time_& o) {
  o.sec = m.sec;
  o.nanosec = m.nanosec;
}
inline void conv(const kelp::ros2::builtin_interfaces::Duration& m,
                 builtin_interfaces_msg_dds__Duration_& o) {
  o.sec = m.sec;
  o.nanosec = m.nanosec;
}
inline void conv(const kelp::ros2::std_msgs::Header& m, std_msgs_msg_dds__Header_& o) {
  conv(m.stamp, o.stamp);
  o.frame_id = str(m.frame_id);
}
inline void conv(const kelp::ros2::std_msgs::ColorRGBA& m, std_msgs_msg_dds__ColorRGBA_& o) {
  o.r = m.r;
  o.g = m.g;
  o.b = m.b;
  o.a = m.a;
}
template <class M, class O>
void xyz(const M& m, O& o) {
  o.x = m.x;
  o.y = m.y;
  o.z = m.z;
}
inline void conv(const kelp::ros2::geometry_msgs::Quaternion& m,
                 geometry_msgs_msg_dds__Quaternion_& o) {
  o.x = m.x;
  o.y = m.y;
  o.z = m.z;
  o.w = m.w;
}
inline void conv(const kelp::ros2::geometry_msgs::Pose& m, geometry_msgs_msg_dds__Pose_& o) {
  xyz(m.position, o.position);
  conv(m.orientation, o.orientation);
}
inline void conv(const kelp::ros2::geometry_msgs::Twist& m, geometry_msgs_msg_dds__Twist_& o) {
  xyz(m.linear, o.linear);
  xyz(m.angular, o.angular);
}
inline void conv(const kelp::ros2::geometry_msgs::Wrench& m, geometry_msgs_msg_dds__Wrench_& o) {
  xyz(m.force, o.force);
  xyz(m.torque, o.torque);
}
inline void conv(const kelp::ros2::geometry_msgs::TransformStamped& m,
                 geometry_msgs_msg_dds__TransformStamped_& o) {
  conv(m.header, o.header);
  o.child_frame_id = str(m.child_frame_id);
  xyz(m.transform.translation, o.transform.translation);
  conv(m.transform.rotation, o.transform.rotation);
}
inline void conv(const kelp::ros2::geometry_msgs::WrenchStamped& m,
                 geometry_msgs_msg_dds__WrenchStamped_& o) {
  conv(m.header, o.header);
  conv(m.wrench, o.wrench);
}
inline void conv(const kelp::ros2::nav_msgs::Odometry& m, nav_msgs_msg_dds__Odometry_& o) {
  conv(m.header, o.header);
  o.child_frame_id = str(m.child_frame_id);
  conv(m.pose.pose, o.pose.pose);
  std::memcpy(o.pose.covariance, m.pose.covariance.data(), sizeof o.pose.covariance);
  conv(m.twist.twist, o.twist.twist);
  std::memcpy(o.twist.covariance, m.twist.covariance.data(), sizeof o.twist.covariance);
}
inline void conv(const kelp::ros2::sensor_msgs::Imu& m, sensor_msgs_msg_dds__Imu_& o) {
  conv(m.header, o.header);
  conv(m.orientation, o.orientation);
  std::memcpy(o.orientation_covariance, m.orientation_covariance.data(),
              sizeof o.orientation_covariance);
  xyz(m.angular_velocity, o.angular_velocity);
  std::memcpy(o.angular_velocity_covariance, m.angular_velocity_covariance.data(),
              sizeof o.angular_velocity_covariance);
  xyz(m.linear_acceleration, o.linear_acceleration);
  std::memcpy(o.linear_acceleration_covariance, m.linear_acceleration_covariance.data(),
              sizeof o.linear_acceleration_covariance);
}
inline void conv(const kelp::ros2::rosgraph_msgs::Clock& m, rosgraph_msgs_msg_dds__Clock_& o) {
  conv(m.clock, o.clock);
}

// A JointState with its name pointers.
struct JointState {
  sensor_msgs_msg_dds__JointState_ msg{};
  std::vector<char*> names;
  void from(const kelp::ros2::sensor_msgs::JointState& m) {
    conv(m.header, msg.header);
    names.resize(m.name.size());
    for (std::size_t i = 0; i < m.name.size(); ++i) names[i] = str(m.name[i]);
    seq(msg.name, names.data(), names.size());
    seq(msg.position, const_cast<double*>(m.position.data()), m.position.size());
    seq(msg.velocity, const_cast<double*>(m.velocity.data()), m.velocity.size());
    seq(msg.effort, const_cast<double*>(m.effort.data()), m.effort.size());
  }
};

// A MarkerArray with the buffers its sequences point to (kept between samples: no allocation
// once the node count is steady).
struct MarkerArray {
  visualization_msgs_msg_dds__MarkerArray_ msg{};
  std::vector<visualization_msgs_msg_dds__Marker_> markers;
  std::vector<std::vector<geometry_msgs_msg_dds__Point_>> points;
  std::vector<std::vector<std_msgs_msg_dds__ColorRGBA_>> colors;
  std::vector<std::vector<visualization_msgs_msg_dds__UVCoordinate_>> uv;
  void from(const kelp::ros2::visualization_msgs::MarkerArray& m) {
    const std::size_t n = m.markers.size();
    markers.resize(n);
    points.resize(n);
    colors.resize(n);
    uv.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const auto& a = m.markers[i];
      auto& o = markers[i];
      conv(a.header, o.header);
      o.ns = str(a.ns);
      o.id = a.id;
      o.type = a.type;
      o.action = a.action;
      conv(a.pose, o.pose);
      xyz(a.scale, o.scale);
      conv(a.color, o.color);
      conv(a.lifetime, o.lifetime);
      o.frame_locked = a.frame_locked;
      points[i].resize(a.points.size());
      for (std::size_t k = 0; k < a.points.size(); ++k) xyz(a.points[k], points[i][k]);
      seq(o.points, points[i].data(), points[i].size());
      colors[i].resize(a.colors.size());
      for (std::size_t k = 0; k < a.colors.size(); ++k) conv(a.colors[k], colors[i][k]);
      seq(o.colors, colors[i].data(), colors[i].size());
      o.texture_resource = str(a.texture_resource);
      conv(a.texture.header, o.texture.header);
      o.texture.format = str(a.texture.format);
      seq(o.texture.data, const_cast<std::uint8_t*>(a.texture.data.data()), a.texture.data.size());
      uv[i].resize(a.uv_coordinates.size());
      for (std::size_t k = 0; k < a.uv_coordinates.size(); ++k) {
        uv[i][k].u = a.uv_coordinates[k].u;
        uv[i][k].v = a.uv_coordinates[k].v;
      }
      seq(o.uv_coordinates, uv[i].data(), uv[i].size());
      o.text = str(a.text);
      o.mesh_resource = str(a.mesh_resource);
      o.mesh_file.filename = str(a.mesh_file.filename);
      seq(o.mesh_file.data, const_cast<std::uint8_t*>(a.mesh_file.data.data()),
          a.mesh_file.data.size());
      o.mesh_use_embedded_materials = a.mesh_use_embedded_materials;
    }
    seq(msg.markers, markers.data(), markers.size());
  }
};
}  // namespace c

/// Publishes the run's messages on their ROS 2 topics (kelp::ros2::topics(): names, types, QoS).
class Publisher {
 public:
  /// Writers for every topic; /clock only when `clock` (paced mode: kelp owns the clock).
  Publisher(Participant& p, bool clock) : p_(p) {
    using kelp::ros2::TopicId;
    const auto& t = kelp::ros2::topics();
    const auto make = [&](TopicId id, const dds_topic_descriptor_t* type) {
      const auto& topic = t[static_cast<std::size_t>(id)];
      writers_[static_cast<std::size_t>(id)] = p.writer(type, topic.name, topic.qos);
    };
    if (clock) make(TopicId::clock, &rosgraph_msgs_msg_dds__Clock__desc);
    make(TopicId::tf, &tf2_msgs_msg_dds__TFMessage__desc);
    make(TopicId::boat_odom, &nav_msgs_msg_dds__Odometry__desc);
    make(TopicId::rov_odom, &nav_msgs_msg_dds__Odometry__desc);
    make(TopicId::rov_imu, &sensor_msgs_msg_dds__Imu__desc);
    make(TopicId::end_forces, &geometry_msgs_msg_dds__WrenchStamped__desc);
    make(TopicId::markers, &visualization_msgs_msg_dds__MarkerArray__desc);
    make(TopicId::rov_thrusters, &sensor_msgs_msg_dds__JointState__desc);
    make(TopicId::boat_thrusters, &sensor_msgs_msg_dds__JointState__desc);
  }

  /// /clock at simulation time t [s] (paced mode).
  void clock(double t) {
    rosgraph_msgs_msg_dds__Clock_ m{};
    c::conv(kelp::ros2::to_time(t), m.clock);
    write(kelp::ros2::TopicId::clock, &m);
  }

  /// Every message of the loop's current sample (the bag's messages at this time); the
  /// markers only when `markers` (the node rate, as the bag's).
  void publish(const kelp::sim::ClosedLoop& loop, bool markers) {
    using kelp::ros2::TopicId;
    const kelp::ros2::Messages& m = sampler_.messages(loop.sample());
    tf_.transforms_.resize(m.tf.transforms.size());
    for (std::size_t i = 0; i < m.tf.transforms.size(); ++i)
      c::conv(m.tf.transforms[i], tf_.transforms_[i]);
    c::seq(tf_.msg.transforms, tf_.transforms_.data(), tf_.transforms_.size());
    write(TopicId::tf, &tf_.msg);
    c::conv(m.boat_odom, odom_);
    write(TopicId::boat_odom, &odom_);
    c::conv(m.rov_odom, odom_);
    write(TopicId::rov_odom, &odom_);
    c::conv(m.rov_imu, imu_);
    write(TopicId::rov_imu, &imu_);
    c::conv(m.boat_end_force, wrench_);
    write(TopicId::end_forces, &wrench_);
    c::conv(m.rov_end_force, wrench_);
    write(TopicId::end_forces, &wrench_);
    if (markers) {
      markers_.from(m.markers);
      write(TopicId::markers, &markers_.msg);
    }
    joints_.from(m.rov_thrusters);
    write(TopicId::rov_thrusters, &joints_.msg);
    joints_.from(m.boat_thrusters);
    write(TopicId::boat_thrusters, &joints_.msg);
  }

  /// Messages published per ROS topic.
  nlohmann::json counts() const {
    nlohmann::json j = nlohmann::json::object();
    for (const auto& t : kelp::ros2::topics())
      if (writers_[static_cast<std::size_t>(t.id)] != 0)
        j[t.name] = counts_[static_cast<std::size_t>(t.id)];
    return j;
  }

 private:
  void write(kelp::ros2::TopicId id, const void* sample) {
    const auto i = static_cast<std::size_t>(id);
    p_.write(writers_[i], sample, kelp::ros2::topics()[i].name);
    ++counts_[i];
  }
  static constexpr std::size_t n_topics = static_cast<std::size_t>(kelp::ros2::TopicId::count);
  Participant& p_;
  std::array<dds_entity_t, n_topics> writers_{};
  std::array<std::uint64_t, n_topics> counts_{};
  kelp::sim::Ros2Sampler sampler_;
  struct {
    tf2_msgs_msg_dds__TFMessage_ msg{};
    std::vector<geometry_msgs_msg_dds__TransformStamped_> transforms_;
  } tf_;
  nav_msgs_msg_dds__Odometry_ odom_{};
  sensor_msgs_msg_dds__Imu_ imu_{};
  geometry_msgs_msg_dds__WrenchStamped_ wrench_{};
  c::MarkerArray markers_;
  c::JointState joints_;
};

}  // namespace kelp_ros2
