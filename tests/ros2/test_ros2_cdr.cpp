// CDR bytes of the ROS 2 messages, worked out by hand from the XCDR1 rules, and round trips.
#include <catch2/catch.hpp>
#include <cstring>

#include "kelp/sim/ros2/cdr.hpp"

namespace r2 = kelp::ros2;

namespace {
std::vector<std::uint8_t> le64(double v) {
  std::uint64_t u;
  std::memcpy(&u, &v, 8);
  std::vector<std::uint8_t> b;
  for (int i = 0; i < 8; ++i) b.push_back(static_cast<std::uint8_t>(u >> (8 * i)));
  return b;
}
void append(std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
  a.insert(a.end(), b.begin(), b.end());
}
template <class M>
M round_trip(const M& m) {
  std::vector<std::uint8_t> bytes;
  r2::serialize(m, bytes);
  M back;
  r2::deserialize(bytes.data(), bytes.size(), back);
  return back;
}
}  // namespace

TEST_CASE("CDR: geometry_msgs/Vector3 is the header and three float64", "[ros2][cdr]") {
  r2::geometry_msgs::Vector3 v;
  v.x = 1;
  v.y = -2;
  v.z = 0.5;
  std::vector<std::uint8_t> bytes;
  r2::serialize(v, bytes);
  // 1.0 = 0x3FF0000000000000, −2.0 = 0xC000000000000000, 0.5 = 0x3FE0000000000000 (IEEE 754).
  const std::vector<std::uint8_t> expected = {
      0x00, 0x01, 0x00, 0x00,                          // CDR_LE, options
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xF0, 0x3F,  // x
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xC0,  // y
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xE0, 0x3F,  // z
  };
  CHECK(bytes == expected);
}

TEST_CASE("CDR: a header, then a float64 aligned to 8 after the string", "[ros2][cdr]") {
  r2::geometry_msgs::WrenchStamped w;
  w.header.stamp.sec = 1;
  w.header.stamp.nanosec = 2;
  w.header.frame_id = "ab";
  w.wrench.force.x = 1;
  w.wrench.torque.z = 0.5;
  std::vector<std::uint8_t> bytes;
  r2::serialize(w, bytes);
  // Offsets after the encapsulation header: sec 0–3, nanosec 4–7, string length 8–11 (3: "ab"
  // and its NUL), bytes 12–14, one byte of padding (15) to put force.x at 16.
  std::vector<std::uint8_t> e = {0x00, 0x01, 0x00, 0x00, 1, 0, 0,   0,   2, 0,
                                 0,    0,    3,    0,    0, 0, 'a', 'b', 0, 0};
  append(e, le64(1));
  for (int i = 0; i < 4; ++i) append(e, le64(0));  // force y, z; torque x, y
  append(e, le64(0.5));
  CHECK(bytes.size() == 4 + 16 + 48);
  CHECK(bytes == e);
}

TEST_CASE("CDR: sequences of strings and float64, a bool and a uint8 sequence", "[ros2][cdr]") {
  r2::sensor_msgs::JointState j;
  j.header.frame_id = "";  // length 1: only the NUL
  j.name = {"a"};
  j.velocity = {2.0};
  std::vector<std::uint8_t> bytes;
  r2::serialize(j, bytes);
  // stamp 0–7; frame_id: length 1 at 8, NUL at 12; pad to 16; name count 1 at 16, length 2 at
  // 20, "a\0" at 24–25; pad to 28: position count 0; velocity count 1 at 32, pad to 40, 2.0 at
  // 40–47; effort count 0 at 48.
  std::vector<std::uint8_t> e = {0x00, 0x01, 0x00, 0x00, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0,   0,
                                 0,    0,    0,    0,    0, 1, 0, 0, 0, 2, 0, 0, 0, 'a', 0,
                                 0,    0,    0,    0,    0, 0, 1, 0, 0, 0, 0, 0, 0, 0};
  append(e, le64(2.0));
  append(e, {0, 0, 0, 0});
  CHECK(bytes == e);

  r2::visualization_msgs::MeshFile f;
  f.filename = "x";
  f.data = {7, 8};
  r2::serialize(f, bytes);
  CHECK(bytes == std::vector<std::uint8_t>{0x00, 0x01, 0x00, 0x00, 2, 0, 0, 0, 'x', 0, 0, 0, 2, 0,
                                           0, 0, 7, 8});
}

TEST_CASE("CDR: every message type round-trips", "[ros2][cdr]") {
  r2::visualization_msgs::MarkerArray a;
  a.markers.resize(2);
  a.markers[0].header.frame_id = "world";
  a.markers[0].ns = "tether";
  a.markers[0].type = r2::visualization_msgs::Marker::LINE_STRIP;
  a.markers[0].frame_locked = true;
  a.markers[0].points.resize(3);
  a.markers[0].points[2].z = -4.25;
  a.markers[0].colors.resize(3);
  a.markers[0].colors[1].r = 0.5f;
  a.markers[0].uv_coordinates.resize(1);
  a.markers[0].uv_coordinates[0].v = 0.75f;
  a.markers[0].texture.data = {1, 2, 3};
  a.markers[1].mesh_file.filename = "rov.stl";
  a.markers[1].mesh_use_embedded_materials = true;
  const auto b = round_trip(a);
  REQUIRE(b.markers.size() == 2);
  CHECK(b.markers[0].ns == "tether");
  CHECK(b.markers[0].type == 4);
  CHECK(b.markers[0].frame_locked);
  CHECK(b.markers[0].points[2].z == -4.25);
  CHECK(b.markers[0].colors[1].r == 0.5f);
  CHECK(b.markers[0].uv_coordinates[0].v == 0.75f);
  CHECK(b.markers[0].texture.data == std::vector<std::uint8_t>{1, 2, 3});
  CHECK(b.markers[1].mesh_file.filename == "rov.stl");
  CHECK(b.markers[1].mesh_use_embedded_materials);

  r2::nav_msgs::Odometry o;
  o.header.frame_id = "world";
  o.child_frame_id = "rov/base_link";
  o.pose.pose.orientation.w = 0.6;
  o.pose.covariance[35] = 3;
  o.twist.twist.angular.y = -1e-300;
  const auto o2 = round_trip(o);
  CHECK(o2.child_frame_id == "rov/base_link");
  CHECK(o2.pose.pose.orientation.w == 0.6);
  CHECK(o2.pose.covariance[35] == 3);
  CHECK(o2.twist.twist.angular.y == -1e-300);

  r2::sensor_msgs::Imu imu;
  imu.linear_acceleration_covariance[0] = -1;
  imu.angular_velocity.z = 2;
  const auto imu2 = round_trip(imu);
  CHECK(imu2.linear_acceleration_covariance[0] == -1);
  CHECK(imu2.angular_velocity.z == 2);

  r2::tf2_msgs::TFMessage tf;
  tf.transforms.resize(2);
  tf.transforms[1].child_frame_id = "boat/base_link";
  tf.transforms[1].transform.rotation.z = 0.5;
  const auto tf2 = round_trip(tf);
  CHECK(tf2.transforms[1].child_frame_id == "boat/base_link");
  CHECK(tf2.transforms[1].transform.rotation.z == 0.5);

  r2::rosgraph_msgs::Clock c;
  c.clock.sec = 7;
  c.clock.nanosec = 999999999u;
  CHECK(round_trip(c).clock.nanosec == 999999999u);
}

TEST_CASE("CDR: malformed data is refused", "[ros2][cdr]") {
  r2::std_msgs::Header h;
  h.frame_id = "world";
  std::vector<std::uint8_t> bytes;
  r2::serialize(h, bytes);
  r2::std_msgs::Header back;
  // Truncated.
  CHECK_THROWS_AS(r2::deserialize(bytes.data(), bytes.size() - 2, back), kelp::error);
  // Big-endian encapsulation (00 00) is not what kelp reads.
  std::vector<std::uint8_t> be = bytes;
  be[1] = 0x00;
  CHECK_THROWS_AS(r2::deserialize(be.data(), be.size(), back), kelp::error);
  // A string without its NUL.
  std::vector<std::uint8_t> nonul = bytes;
  nonul.back() = 'x';
  CHECK_THROWS_AS(r2::deserialize(nonul.data(), nonul.size(), back), kelp::error);
  // A sequence count larger than the data.
  r2::sensor_msgs::JointState j;
  r2::serialize(j, bytes);
  bytes[16] = 0xFF;  // name count
  r2::sensor_msgs::JointState jb;
  CHECK_THROWS_AS(r2::deserialize(bytes.data(), bytes.size(), jb), kelp::error);
}
