/// \file
/// \brief The ROS 2 messages kelp publishes (in MCAP bags and on live DDS topics), as plain C++
/// structs with their fields in the order of ROS 2 Humble's `.msg` files, the topics and QoS
/// they are published with, and fill_messages(): one run sample → every message.
///
/// Sources of the field lists (ROS 2 Humble):
///   - ros2/rcl_interfaces (branch humble, 1.2.1): builtin_interfaces/msg/Time.msg, Duration.msg,
///     rosgraph_msgs/msg/Clock.msg;
///   - ros2/common_interfaces (branch humble, 4.2.4): std_msgs/msg/Header.msg, ColorRGBA.msg;
///     geometry_msgs/msg/{Vector3, Point, Quaternion, Pose, PoseWithCovariance, Twist,
///     TwistWithCovariance, Transform, TransformStamped, Wrench, WrenchStamped}.msg;
///     nav_msgs/msg/Odometry.msg; sensor_msgs/msg/{Imu, JointState, CompressedImage}.msg;
///     visualization_msgs/msg/{Marker, MarkerArray, UVCoordinate, MeshFile}.msg;
///   - ros2/geometry2 (branch humble): tf2_msgs/msg/TFMessage.msg.
/// Each struct carries its ROS type name (`type`), its `.msg` text without comments
/// (`definition`: the field and constant lines as the file has them) and `fields(m, f)`, which
/// calls `f` on every field in order: the one field list that the CDR writer and reader
/// (kelp/sim/ros2/cdr.hpp) and the schema text (schema_text()) all use.
///
/// Frames (REP 103 / REP 105): the world frame `world` is ENU, the bodies `boat/base_link` and
/// `rov/base_link` are FLU; kelp's NED/FRD numbers go through kelp/sim/ros2/frames.hpp.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/sim/export.hpp"
#include "kelp/sim/ros2/frames.hpp"
#include "kelp/vehicle/state.hpp"

namespace kelp {
namespace ros2 {

// ------------------------------------------------------------------------------------------------
// Message types
// ------------------------------------------------------------------------------------------------

/// builtin_interfaces: ROS time.
namespace builtin_interfaces {
/// \brief builtin_interfaces/msg/Time: seconds and nanoseconds.
struct Time {
  static constexpr const char* type_name = "builtin_interfaces/msg/Time";   ///< ROS type name
  static constexpr const char* definition = "int32 sec\nuint32 nanosec\n";  ///< `.msg` text
  std::int32_t sec = 0;                                                     ///< [s]
  std::uint32_t nanosec = 0;                                                ///< [ns], in [0, 1e9)
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.sec);
    f(m.nanosec);
  }
};
/// \brief builtin_interfaces/msg/Duration.
struct Duration {
  static constexpr const char* type_name = "builtin_interfaces/msg/Duration";  ///< ROS type name
  static constexpr const char* definition = "int32 sec\nuint32 nanosec\n";     ///< `.msg` text
  std::int32_t sec = 0;                                                        ///< [s]
  std::uint32_t nanosec = 0;                                                   ///< [ns]
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.sec);
    f(m.nanosec);
  }
};
}  // namespace builtin_interfaces

/// std_msgs: the header and colours.
namespace std_msgs {
/// \brief std_msgs/msg/Header: time stamp and frame.
struct Header {
  static constexpr const char* type_name = "std_msgs/msg/Header";  ///< ROS type name
  static constexpr const char* definition =
      "builtin_interfaces/Time stamp\nstring frame_id\n";  ///< `.msg` text
  builtin_interfaces::Time stamp;                          ///< simulation time
  std::string frame_id;                                    ///< TF frame of the data
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.stamp);
    f(m.frame_id);
  }
};
/// \brief std_msgs/msg/ColorRGBA (each in [0, 1]).
struct ColorRGBA {
  static constexpr const char* type_name = "std_msgs/msg/ColorRGBA";  ///< ROS type name
  static constexpr const char* definition =
      "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n";  ///< `.msg` text
  float r = 0,                                         ///< red, [0, 1]
      g = 0,                                           ///< green, [0, 1]
      b = 0,                                           ///< blue, [0, 1]
      a = 0;                                           ///< alpha (opacity), [0, 1]; 0 is invisible
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.r);
    f(m.g);
    f(m.b);
    f(m.a);
  }
};
}  // namespace std_msgs

/// geometry_msgs: points, poses, velocities, forces, transforms.
namespace geometry_msgs {
/// \brief geometry_msgs/msg/Vector3.
struct Vector3 {
  static constexpr const char* type_name = "geometry_msgs/msg/Vector3";           ///< ROS type name
  static constexpr const char* definition = "float64 x\nfloat64 y\nfloat64 z\n";  ///< `.msg` text
  double x = 0,  ///< x component (ENU: east; FLU: forward)
      y = 0,     ///< y component (ENU: north; FLU: left)
      z = 0;     ///< z component (ENU: up; FLU: up)
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.x);
    f(m.y);
    f(m.z);
  }
};
/// \brief geometry_msgs/msg/Point.
struct Point {
  static constexpr const char* type_name = "geometry_msgs/msg/Point";             ///< ROS type name
  static constexpr const char* definition = "float64 x\nfloat64 y\nfloat64 z\n";  ///< `.msg` text
  double x = 0,  ///< x [m] (ENU: east)
      y = 0,     ///< y [m] (ENU: north)
      z = 0;     ///< z [m] (ENU: up)
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.x);
    f(m.y);
    f(m.z);
  }
};
/// \brief geometry_msgs/msg/Quaternion (x, y, z, w; identity by default, as the `.msg` says).
struct Quaternion {
  static constexpr const char* type_name = "geometry_msgs/msg/Quaternion";  ///< ROS type name
  static constexpr const char* definition =
      "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n";  ///< `.msg` text
  double x = 0,                                                ///< vector part, x
      y = 0,                                                   ///< vector part, y
      z = 0,                                                   ///< vector part, z
      w = 1;                                                   ///< scalar part
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.x);
    f(m.y);
    f(m.z);
    f(m.w);
  }
};
/// \brief geometry_msgs/msg/Pose.
struct Pose {
  static constexpr const char* type_name = "geometry_msgs/msg/Pose";  ///< ROS type name
  static constexpr const char* definition =
      "Point position\nQuaternion orientation\n";  ///< `.msg` text
  Point position;                                  ///< [m]
  Quaternion orientation;                          ///< body → parent frame
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.position);
    f(m.orientation);
  }
};
/// \brief geometry_msgs/msg/PoseWithCovariance.
struct PoseWithCovariance {
  static constexpr const char* type_name =
      "geometry_msgs/msg/PoseWithCovariance";  ///< ROS type name
  static constexpr const char* definition = "Pose pose\nfloat64[36] covariance\n";  ///< `.msg` text
  Pose pose;                                                                        ///< the pose
  std::array<double, 36> covariance{};  ///< row-major 6×6 (x, y, z, rot x, rot y, rot z)
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.pose);
    f(m.covariance);
  }
};
/// \brief geometry_msgs/msg/Twist.
struct Twist {
  static constexpr const char* type_name = "geometry_msgs/msg/Twist";  ///< ROS type name
  static constexpr const char* definition = "Vector3  linear\nVector3  angular\n";  ///< `.msg` text
  Vector3 linear;                                                                   ///< [m/s]
  Vector3 angular;                                                                  ///< [rad/s]
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.linear);
    f(m.angular);
  }
};
/// \brief geometry_msgs/msg/TwistWithCovariance.
struct TwistWithCovariance {
  static constexpr const char* type_name =
      "geometry_msgs/msg/TwistWithCovariance";  ///< ROS type name
  static constexpr const char* definition =
      "Twist twist\nfloat64[36] covariance\n";  ///< `.msg` text
  Twist twist;                                  ///< the twist
  std::array<double, 36> covariance{};          ///< row-major 6×6
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.twist);
    f(m.covariance);
  }
};
/// \brief geometry_msgs/msg/Transform.
struct Transform {
  static constexpr const char* type_name = "geometry_msgs/msg/Transform";  ///< ROS type name
  static constexpr const char* definition =
      "Vector3 translation\nQuaternion rotation\n";  ///< `.msg` text
  Vector3 translation;                               ///< [m]
  Quaternion rotation;                               ///< child → parent
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.translation);
    f(m.rotation);
  }
};
/// \brief geometry_msgs/msg/TransformStamped.
struct TransformStamped {
  static constexpr const char* type_name = "geometry_msgs/msg/TransformStamped";  ///< ROS type name
  static constexpr const char* definition =
      "std_msgs/Header header\nstring child_frame_id\nTransform transform\n";  ///< `.msg` text
  std_msgs::Header header;                                                     ///< parent frame
  std::string child_frame_id;                                                  ///< child frame
  Transform transform;  ///< child's pose in the parent frame
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.header);
    f(m.child_frame_id);
    f(m.transform);
  }
};
/// \brief geometry_msgs/msg/Wrench.
struct Wrench {
  static constexpr const char* type_name = "geometry_msgs/msg/Wrench";            ///< ROS type name
  static constexpr const char* definition = "Vector3  force\nVector3  torque\n";  ///< `.msg` text
  Vector3 force;                                                                  ///< [N]
  Vector3 torque;                                                                 ///< [N m]
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.force);
    f(m.torque);
  }
};
/// \brief geometry_msgs/msg/WrenchStamped.
struct WrenchStamped {
  static constexpr const char* type_name = "geometry_msgs/msg/WrenchStamped";  ///< ROS type name
  static constexpr const char* definition =
      "std_msgs/Header header\nWrench wrench\n";  ///< `.msg` text
  std_msgs::Header header;                        ///< frame of the wrench
  Wrench wrench;                                  ///< force and moment about the frame's origin
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.header);
    f(m.wrench);
  }
};
}  // namespace geometry_msgs

/// nav_msgs: odometry.
namespace nav_msgs {
/// \brief nav_msgs/msg/Odometry: the pose in header.frame_id, the twist in child_frame_id.
struct Odometry {
  static constexpr const char* type_name = "nav_msgs/msg/Odometry";  ///< ROS type name
  static constexpr const char* definition =
      "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance "
      "pose\ngeometry_msgs/TwistWithCovariance twist\n";  ///< `.msg` text
  std_msgs::Header header;                                ///< world frame
  std::string child_frame_id;                             ///< body frame
  geometry_msgs::PoseWithCovariance pose;                 ///< body pose in the world frame
  geometry_msgs::TwistWithCovariance twist;               ///< body velocity in body axes
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.header);
    f(m.child_frame_id);
    f(m.pose);
    f(m.twist);
  }
};
}  // namespace nav_msgs

/// sensor_msgs: IMU, joint states (thrusters), compressed image (a Marker field).
namespace sensor_msgs {
/// \brief sensor_msgs/msg/Imu. A covariance whose element 0 is −1 marks an estimate the IMU
/// does not provide (the `.msg`'s rule).
struct Imu {
  static constexpr const char* type_name = "sensor_msgs/msg/Imu";  ///< ROS type name
  static constexpr const char* definition =
      "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] "
      "orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\nfloat64[9] "
      "angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\nfloat64[9] "
      "linear_acceleration_covariance\n";                  ///< `.msg` text
  std_msgs::Header header;                                 ///< body frame
  geometry_msgs::Quaternion orientation;                   ///< body → world
  std::array<double, 9> orientation_covariance{};          ///< row-major
  geometry_msgs::Vector3 angular_velocity;                 ///< [rad/s], body axes
  std::array<double, 9> angular_velocity_covariance{};     ///< row-major
  geometry_msgs::Vector3 linear_acceleration;              ///< specific force [m/s²], body axes
  std::array<double, 9> linear_acceleration_covariance{};  ///< row-major
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.header);
    f(m.orientation);
    f(m.orientation_covariance);
    f(m.angular_velocity);
    f(m.angular_velocity_covariance);
    f(m.linear_acceleration);
    f(m.linear_acceleration_covariance);
  }
};
/// \brief sensor_msgs/msg/JointState (kelp's thrusters: name, velocity = command, effort =
/// thrust [N]).
struct JointState {
  static constexpr const char* type_name = "sensor_msgs/msg/JointState";  ///< ROS type name
  static constexpr const char* definition =
      "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] "
      "effort\n";                 ///< `.msg` text
  std_msgs::Header header;        ///< stamp and frame
  std::vector<std::string> name;  ///< joint names
  std::vector<double> position;   ///< positions (kelp: empty)
  std::vector<double> velocity;   ///< velocities (kelp: the normalised command)
  std::vector<double> effort;     ///< efforts (kelp: the thrust [N])
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.header);
    f(m.name);
    f(m.position);
    f(m.velocity);
    f(m.effort);
  }
};
/// \brief sensor_msgs/msg/CompressedImage (Marker's texture; kelp leaves it empty).
struct CompressedImage {
  static constexpr const char* type_name = "sensor_msgs/msg/CompressedImage";  ///< ROS type name
  static constexpr const char* definition =
      "std_msgs/Header header\nstring format\nuint8[] data\n";  ///< `.msg` text
  std_msgs::Header header;                                      ///< stamp and frame
  std::string format;                                           ///< e.g. "png"
  std::vector<std::uint8_t> data;                               ///< the image
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.header);
    f(m.format);
    f(m.data);
  }
};
}  // namespace sensor_msgs

/// tf2_msgs: the transform tree.
namespace tf2_msgs {
/// \brief tf2_msgs/msg/TFMessage.
struct TFMessage {
  static constexpr const char* type_name = "tf2_msgs/msg/TFMessage";  ///< ROS type name
  static constexpr const char* definition =
      "geometry_msgs/TransformStamped[] transforms\n";      ///< `.msg` text
  std::vector<geometry_msgs::TransformStamped> transforms;  ///< the transforms
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.transforms);
  }
};
}  // namespace tf2_msgs

/// visualization_msgs: markers.
namespace visualization_msgs {
/// \brief visualization_msgs/msg/UVCoordinate.
struct UVCoordinate {
  static constexpr const char* type_name =
      "visualization_msgs/msg/UVCoordinate";                           ///< ROS type name
  static constexpr const char* definition = "float32 u\nfloat32 v\n";  ///< `.msg` text
  float u = 0,  ///< texture coordinate u, [0, 1]
      v = 0;    ///< texture coordinate v, [0, 1]
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.u);
    f(m.v);
  }
};
/// \brief visualization_msgs/msg/MeshFile.
struct MeshFile {
  static constexpr const char* type_name = "visualization_msgs/msg/MeshFile";   ///< ROS type name
  static constexpr const char* definition = "string filename\nuint8[] data\n";  ///< `.msg` text
  std::string filename;            ///< file name (its extension gives the format)
  std::vector<std::uint8_t> data;  ///< the file
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.filename);
    f(m.data);
  }
};
/// \brief visualization_msgs/msg/Marker, every field of ROS 2 Humble's definition.
struct Marker {
  static constexpr const char* type_name = "visualization_msgs/msg/Marker";  ///< ROS type name
  /// `.msg` text (the constants, then the fields)
  static constexpr const char* definition =
      "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\nint32 LINE_STRIP=4\nint32 "
      "LINE_LIST=5\nint32 CUBE_LIST=6\nint32 SPHERE_LIST=7\nint32 POINTS=8\nint32 "
      "TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\nint32 TRIANGLE_LIST=11\n"
      "int32 ADD=0\nint32 MODIFY=0\nint32 DELETE=2\nint32 DELETEALL=3\n"
      "std_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\n"
      "geometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\n"
      "builtin_interfaces/Duration lifetime\nbool frame_locked\ngeometry_msgs/Point[] points\n"
      "std_msgs/ColorRGBA[] colors\nstring texture_resource\nsensor_msgs/CompressedImage "
      "texture\nUVCoordinate[] uv_coordinates\nstring text\nstring mesh_resource\nMeshFile "
      "mesh_file\nbool mesh_use_embedded_materials\n";
  static constexpr std::int32_t CUBE = 1;        ///< a box of size `scale`
  static constexpr std::int32_t SPHERE = 2;      ///< an ellipsoid of diameters `scale`
  static constexpr std::int32_t LINE_STRIP = 4;  ///< a polyline through `points`
  static constexpr std::int32_t ADD = 0;         ///< add or replace (ns, id)
  std_msgs::Header header;                       ///< frame of `pose`
  std::string ns;                                ///< namespace: with `id`, the marker's key
  std::int32_t id = 0;                           ///< id within `ns`
  std::int32_t type = 0;                         ///< CUBE, LINE_STRIP, ...
  std::int32_t action = 0;                       ///< ADD, DELETE, DELETEALL
  geometry_msgs::Pose pose;                      ///< the marker's pose in the header's frame
  geometry_msgs::Vector3 scale;                  ///< size [m] (LINE_STRIP: x is the line width)
  std_msgs::ColorRGBA color;                     ///< colour (unless per point)
  builtin_interfaces::Duration lifetime;         ///< 0: until replaced
  bool frame_locked = false;                     ///< re-transform with its frame
  std::vector<geometry_msgs::Point> points;      ///< LINE_STRIP's vertices
  std::vector<std_msgs::ColorRGBA> colors;       ///< a colour per point
  std::string texture_resource;                  ///< (unused)
  sensor_msgs::CompressedImage texture;          ///< (unused)
  std::vector<UVCoordinate> uv_coordinates;      ///< (unused)
  std::string text;                              ///< TEXT_VIEW_FACING's text
  std::string mesh_resource;                     ///< MESH_RESOURCE's URI
  MeshFile mesh_file;                            ///< (unused)
  bool mesh_use_embedded_materials = false;      ///< MESH_RESOURCE's materials
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.header);
    f(m.ns);
    f(m.id);
    f(m.type);
    f(m.action);
    f(m.pose);
    f(m.scale);
    f(m.color);
    f(m.lifetime);
    f(m.frame_locked);
    f(m.points);
    f(m.colors);
    f(m.texture_resource);
    f(m.texture);
    f(m.uv_coordinates);
    f(m.text);
    f(m.mesh_resource);
    f(m.mesh_file);
    f(m.mesh_use_embedded_materials);
  }
};
/// \brief visualization_msgs/msg/MarkerArray.
struct MarkerArray {
  static constexpr const char* type_name = "visualization_msgs/msg/MarkerArray";  ///< ROS type name
  static constexpr const char* definition = "Marker[] markers\n";                 ///< `.msg` text
  std::vector<Marker> markers;                                                    ///< the markers
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.markers);
  }
};
}  // namespace visualization_msgs

/// rosgraph_msgs: the simulation clock.
namespace rosgraph_msgs {
/// \brief rosgraph_msgs/msg/Clock.
struct Clock {
  static constexpr const char* type_name = "rosgraph_msgs/msg/Clock";           ///< ROS type name
  static constexpr const char* definition = "builtin_interfaces/Time clock\n";  ///< `.msg` text
  builtin_interfaces::Time clock;  ///< the current (simulation) time
  /// \brief Calls f on each field, in the `.msg` order.
  /// \tparam S this struct, const or not \tparam F a callable taking every field's type
  /// \param m the message \param f called with a reference to each field
  template <class S, class F>
  static void fields(S& m, F&& f) {
    f(m.clock);
  }
};
}  // namespace rosgraph_msgs

// ------------------------------------------------------------------------------------------------
// Schema text (ros2msg)
// ------------------------------------------------------------------------------------------------

namespace detail {
template <class T, class = void>
struct is_message : std::false_type {};
template <class T>
struct is_message<T, std::void_t<decltype(T::definition)>> : std::true_type {};
template <class T>
struct is_vector : std::false_type {};
template <class T, class A>
struct is_vector<std::vector<T, A>> : std::true_type {};

/// \brief "pkg/msg/Name" → "pkg/Name" (the name a `.msg` file and the schema's delimiter use;
/// schema_text() calls it, so it is exported).
KELP_SIM_API std::string short_name(const std::string& type);

// The message types T's fields name directly (their short names, sorted, each once).
struct DependencyCollector {
  std::set<std::string>* out;
  template <class U>
  void operator()(const U&) const {
    if constexpr (is_message<U>::value) {
      out->insert(short_name(U::type_name));
    } else if constexpr (is_vector<U>::value) {
      using E = typename U::value_type;
      if constexpr (is_message<E>::value) out->insert(short_name(E::type_name));
    }
  }
};
template <class T>
void direct_dependencies(std::set<std::string>& out) {
  const T m{};
  T::fields(m, DependencyCollector{&out});
}
}  // namespace detail

/// \brief The ros2msg schema of message type T: its `.msg` text, then each type it uses (in
/// name order, depth first, each once) after a line of 80 `=` and a line `MSG: pkg/Name`: the
/// text rosbag2's MCAP storage writes (MCAP registry, schema encoding `ros2msg`).
/// \tparam T a message struct of this header (e.g. nav_msgs::Odometry)
/// \return the schema's text (UTF-8, lines ended by `\n`)
template <class T>
std::string schema_text();

namespace detail {
template <class T>
void append_dependencies(std::string& text, std::set<std::string>& seen);
// Appends U's definition after its delimiter, then its own dependencies, unless already there:
// rosbag2's MCAP storage does the same (rosbag2_storage_mcap/src/message_definition_cache.cpp,
// humble: the root's text, then for each dependency in name order "\n", a line of 80 '=',
// "MSG: pkg/Name\n" and its text followed by its dependencies, depth first, each once).
template <class U>
void append_one(std::string& text, std::set<std::string>& seen) {
  const std::string name = short_name(U::type_name);
  if (!seen.insert(name).second) return;
  text += "\n================================================================================\n";
  text += "MSG: " + name + "\n";
  text += U::definition;
  append_dependencies<U>(text, seen);
}
// Calls append_one for each message type T's fields use, in name order (std::set's, as the
// dependency set of rosbag2's cache).
template <class T>
struct OrderedAppender {
  std::string* text;
  std::set<std::string>* seen;
  const std::string* next;  // the name to append in this pass
  template <class U>
  void operator()(const U&) const {
    if constexpr (is_message<U>::value) {
      if (short_name(U::type_name) == *next) append_one<U>(*text, *seen);
    } else if constexpr (is_vector<U>::value) {
      using E = typename U::value_type;
      if constexpr (is_message<E>::value)
        if (short_name(E::type_name) == *next) append_one<E>(*text, *seen);
    }
  }
};
template <class T>
void append_dependencies(std::string& text, std::set<std::string>& seen) {
  std::set<std::string> deps;
  direct_dependencies<T>(deps);
  const T m{};
  for (const std::string& d : deps) T::fields(m, OrderedAppender<T>{&text, &seen, &d});
}
}  // namespace detail

template <class T>
std::string schema_text() {
  std::string text = T::definition;
  std::set<std::string> seen;
  detail::append_dependencies<T>(text, seen);
  return text;
}

// ------------------------------------------------------------------------------------------------
// Topics and QoS
// ------------------------------------------------------------------------------------------------

/// \brief A QoS reliability policy (rmw_qos_reliability_policy_t's values, rmw/types.h).
enum class Reliability : int {
  reliable = 1,    ///< RMW_QOS_POLICY_RELIABILITY_RELIABLE: every message delivered
  best_effort = 2  ///< RMW_QOS_POLICY_RELIABILITY_BEST_EFFORT: messages may be dropped
};
/// \brief A QoS durability policy (rmw_qos_durability_policy_t's values, rmw/types.h).
enum class Durability : int {
  transient_local = 1,     ///< RMW_QOS_POLICY_DURABILITY_TRANSIENT_LOCAL: kept for late joiners
  durability_volatile = 2  ///< RMW_QOS_POLICY_DURABILITY_VOLATILE: not kept
};

/// \brief The QoS a topic is published with (history is always keep-last).
struct Qos {
  Reliability reliability = Reliability::reliable;          ///< reliable or best effort
  Durability durability = Durability::durability_volatile;  ///< volatile or transient local
  int depth = 10;                                           ///< keep-last depth
};

/// \brief The QoS of sensor data: rclcpp::SensorDataQoS (best effort, volatile, keep last 5;
/// rclcpp/include/rclcpp/qos.hpp, humble, from rmw_qos_profile_sensor_data).
inline constexpr Qos sensor_data_qos{Reliability::best_effort, Durability::durability_volatile, 5};
/// \brief The QoS of state: rclcpp::QoS(10) on rmw_qos_profile_default (reliable, volatile, keep
/// last 10).
inline constexpr Qos state_qos{Reliability::reliable, Durability::durability_volatile, 10};
/// \brief The QoS of /tf: tf2_ros::DynamicBroadcasterQoS (rclcpp::QoS(100): reliable, volatile,
/// keep last 100; ros2/geometry2 tf2_ros/include/tf2_ros/qos.hpp, humble).
inline constexpr Qos tf_qos{Reliability::reliable, Durability::durability_volatile, 100};
/// \brief The QoS of /clock: rclcpp::ClockQoS (best effort, volatile, keep last 1).
inline constexpr Qos clock_qos{Reliability::best_effort, Durability::durability_volatile, 1};

/// \brief The topics kelp publishes, in the order of TopicId.
enum class TopicId : int {
  clock,           ///< /clock (rosgraph_msgs/msg/Clock)
  tf,              ///< /tf (tf2_msgs/msg/TFMessage)
  boat_odom,       ///< /boat/odom (nav_msgs/msg/Odometry)
  rov_odom,        ///< /rov/odom (nav_msgs/msg/Odometry)
  rov_imu,         ///< /rov/imu (sensor_msgs/msg/Imu)
  end_forces,      ///< /tether/end_forces (geometry_msgs/msg/WrenchStamped)
  markers,         ///< /tether/markers (visualization_msgs/msg/MarkerArray)
  rov_thrusters,   ///< /rov/thrusters (sensor_msgs/msg/JointState)
  boat_thrusters,  ///< /boat/thrusters (sensor_msgs/msg/JointState)
  count            ///< the number of topics (not a topic)
};

/// \brief A topic: its ROS name, ROS type and QoS.
struct Topic {
  TopicId id;        ///< its index
  const char* name;  ///< ROS topic name
  const char* type;  ///< ROS type name (pkg/msg/Name)
  Qos qos;           ///< QoS it is published with
};

/// \brief Every topic kelp publishes (the README's "With ROS 2" table).
/// \return the topics, indexed by TopicId (a static table)
KELP_SIM_API const std::array<Topic, static_cast<int>(TopicId::count)>& topics();

// ------------------------------------------------------------------------------------------------
// A run sample → the messages
// ------------------------------------------------------------------------------------------------

/// \brief ROS time of a simulation time t ≥ 0 [s] (nanoseconds rounded to nearest).
/// \param t the time [s], finite, in [0, 2³¹) \return seconds and nanoseconds (< 10⁹)
/// \throws kelp::invalid_argument for a negative, non-finite or too large (≥ 2³¹ s) time.
KELP_SIM_API builtin_interfaces::Time to_time(double t);

/// \brief Nanoseconds of a ROS time (the MCAP log time of a message stamped with it).
/// \param t the time (sec ≥ 0) \return sec · 10⁹ + nanosec [ns]
inline std::uint64_t to_nanoseconds(const builtin_interfaces::Time& t) {
  return static_cast<std::uint64_t>(t.sec) * 1000000000ULL + t.nanosec;
}

/// \brief What the messages are made from: one sample of a run (kelp's frames: NED, FRD).
///
/// The vehicle states and the tether's nodes are pointed to, not copied: they must outlive the
/// call to fill_messages().
struct RunSample {
  /// The value of a quantity the run does not have.
  static constexpr double none = std::numeric_limits<double>::quiet_NaN();
  double time = 0;                                     ///< simulation time [s]
  const kelp::vehicle::VehicleStated* boat = nullptr;  ///< the boat's (ASV's) state (required)
  const kelp::vehicle::VehicleStated* rov = nullptr;   ///< the ROV's (AUV's) state (required)
  /// The ROV's acceleration ν̇ (body FRD) for its IMU's specific force; NaN: unknown (the IMU's
  /// linear acceleration is then marked "no estimate").
  Eigen::Matrix<double, 6, 1> rov_nu_dot = Eigen::Matrix<double, 6, 1>::Constant(none);
  double gravity = kelp::standard_gravity;  ///< g [m/s²] (the environment's)
  /// The tether's node positions, NED [m]: node 0 at the boat's attachment, the last at the
  /// ROV's (required, at least 2 nodes).
  const Eigen::Matrix<double, 3, Eigen::Dynamic>* nodes = nullptr;
  /// Axial tension of each segment [N] (nodes − 1 values); null: the line is drawn uncoloured.
  const Eigen::VectorXd* tensions = nullptr;
  Eigen::Vector3d force_on_boat = Eigen::Vector3d::Zero();  ///< tether force on the boat, NED [N]
  Eigen::Vector3d force_on_rov = Eigen::Vector3d::Zero();   ///< tether force on the ROV, NED [N]
  Eigen::Vector2d boat_thrust = Eigen::Vector2d::Constant(none);   ///< port, starboard [N]
  Eigen::Vector2d boat_command = Eigen::Vector2d::Constant(none);  ///< normalised [-1, 1]
  Eigen::Matrix<double, 8, 1> rov_thrust =
      Eigen::Matrix<double, 8, 1>::Constant(none);  ///< [N], motor order
  Eigen::Matrix<double, 8, 1> rov_command =
      Eigen::Matrix<double, 8, 1>::Constant(none);  ///< normalised, motor order
  double tension_scale = 200;                       ///< tension drawn fully red [N]
};

/// \brief The messages of one sample (what fill_messages() writes), one member a topic;
/// /tether/end_forces carries two messages per sample (boat's end, then the ROV's).
struct Messages {
  rosgraph_msgs::Clock clock;                   ///< /clock
  tf2_msgs::TFMessage tf;                       ///< /tf: world → boat, world → rov
  nav_msgs::Odometry boat_odom;                 ///< /boat/odom
  nav_msgs::Odometry rov_odom;                  ///< /rov/odom
  sensor_msgs::Imu rov_imu;                     ///< /rov/imu
  geometry_msgs::WrenchStamped boat_end_force;  ///< /tether/end_forces, frame boat/base_link
  geometry_msgs::WrenchStamped rov_end_force;   ///< /tether/end_forces, frame rov/base_link
  visualization_msgs::MarkerArray markers;      ///< /tether/markers
  sensor_msgs::JointState rov_thrusters;        ///< /rov/thrusters
  sensor_msgs::JointState boat_thrusters;       ///< /boat/thrusters
};

/// Frame names (REP 105 style; the bodies FLU).
inline constexpr const char* world_frame = "world";          ///< ENU world frame
inline constexpr const char* boat_frame = "boat/base_link";  ///< the boat's body (FLU)
inline constexpr const char* rov_frame = "rov/base_link";    ///< the ROV's body (FLU)

/// \brief Every message of sample `s`, into `m` (reused: after the first call with the same node
/// count no allocation happens). Frames: poses in `world` (ENU), twists, IMU, end wrenches and
/// thrusters in each body's FLU frame; all stamps are the simulation time `s.time`.
///
/// - /tf: world → boat/base_link, world → rov/base_link (each body's pose).
/// - /boat/odom, /rov/odom: pose in `world`, twist (ν) in the body frame; zero covariances.
/// - /rov/imu: orientation, angular velocity and the specific force f = ν̇₁ + ω × ν₁ − Rᵀ g e_z
///   (body; kelp/nav/sensors.hpp's ideal accelerometer) in FLU; with ν̇ unknown the linear
///   acceleration is zero and its covariance's element 0 is −1 ("no estimate", Imu.msg).
/// - /tether/end_forces: the tether's force on each vehicle as a wrench in its body frame about
///   its origin (force at the end node); frame_id says which end.
/// - /tether/markers: ns "tether" LINE_STRIP in `world` through the nodes, each vertex coloured
///   by the tension of its segment(s) (blue 0 N → red tension_scale); ns "boat" and "rov" CUBEs
///   in the body frames (display sizes roughly the hulls').
/// - /rov/thrusters, /boat/thrusters: name, velocity = normalised command, effort = thrust [N].
/// \throws kelp::invalid_argument when a vehicle or the nodes are missing, fewer than 2 nodes, a
/// time ros2::to_time refuses, or tensions of the wrong size.
/// \param s the sample (kelp's frames: NED, FRD) \param m the messages, overwritten
KELP_SIM_API void fill_messages(const RunSample& s, Messages& m);

}  // namespace ros2
}  // namespace kelp
