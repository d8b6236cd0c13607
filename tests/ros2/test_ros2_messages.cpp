// kelp's NED/FRD → ROS's ENU/FLU, and the messages filled from a run sample.
#include <catch2/catch.hpp>
#include <cmath>

#include "kelp/core/rotation.hpp"
#include "kelp/sim/ros2/messages.hpp"

namespace r2 = kelp::ros2;
using Catch::Matchers::WithinAbs;

namespace {
constexpr double pi = 3.14159265358979323846;

Eigen::Quaterniond q_of(const r2::geometry_msgs::Quaternion& m) {
  return Eigen::Quaterniond(m.w, m.x, m.y, m.z);
}
// ZYX yaw of a rotation matrix (the same angle convention in both worlds).
double yaw_of(const Eigen::Matrix3d& R) { return std::atan2(R(1, 0), R(0, 0)); }
double pitch_of(const Eigen::Matrix3d& R) { return -std::asin(R(2, 0)); }
double roll_of(const Eigen::Matrix3d& R) { return std::atan2(R(2, 1), R(2, 2)); }
}  // namespace

TEST_CASE("NED and FRD vectors map to ENU and FLU by the REP 103 axis changes", "[ros2]") {
  // North 1, east 2, down 3 → east 2, north 1, up −3.
  const Eigen::Vector3d enu = r2::ned_to_enu(Eigen::Vector3d(1, 2, 3));
  CHECK(enu == Eigen::Vector3d(2, 1, -3));
  // Forward 1, starboard 2, down 3 → forward 1, left −2, up −3.
  const Eigen::Vector3d flu = r2::frd_to_flu(Eigen::Vector3d(1, 2, 3));
  CHECK(flu == Eigen::Vector3d(1, -2, -3));
}

TEST_CASE("Attitudes: known rotations in ROS's angles", "[ros2]") {
  SECTION("level, heading north: ROS yaw +90 deg (x points north = ENU +y)") {
    const Eigen::Quaterniond q = r2::ned_frd_to_enu_flu(Eigen::Quaterniond::Identity());
    CHECK_THAT(q.w(), WithinAbs(std::sqrt(0.5), 1e-15));
    CHECK_THAT(q.z(), WithinAbs(std::sqrt(0.5), 1e-15));
    CHECK_THAT(q.x(), WithinAbs(0, 1e-15));
    CHECK_THAT(q.y(), WithinAbs(0, 1e-15));
  }
  SECTION("heading east (kelp yaw +90 deg): ROS yaw 0") {
    const Eigen::Quaterniond q =
        r2::ned_frd_to_enu_flu(kelp::quaternion_from_euler(0.0, 0.0, pi / 2));
    CHECK_THAT(std::abs(q.w()), WithinAbs(1, 1e-15));
  }
  SECTION("roll, pitch, yaw: ROS roll = roll, pitch = -pitch, yaw = 90 deg - yaw") {
    const double roll = 0.3, pitch = -0.4, yaw = 1.1;
    const Eigen::Matrix3d R =
        r2::ned_frd_to_enu_flu(kelp::quaternion_from_euler(roll, pitch, yaw)).toRotationMatrix();
    CHECK_THAT(roll_of(R), WithinAbs(roll, 1e-12));
    CHECK_THAT(pitch_of(R), WithinAbs(-pitch, 1e-12));
    CHECK_THAT(yaw_of(R), WithinAbs(pi / 2 - yaw, 1e-12));
  }
  SECTION("the defining property: rotate then convert == convert then rotate") {
    for (int k = 0; k < 20; ++k) {
      const Eigen::Quaterniond q = Eigen::Quaterniond::UnitRandom();
      const Eigen::Vector3d v = Eigen::Vector3d::Random();
      const Eigen::Vector3d a = r2::ned_to_enu(q * v);
      const Eigen::Vector3d b = r2::ned_frd_to_enu_flu(q) * r2::frd_to_flu(v);
      CHECK((a - b).norm() < 1e-14);
      CHECK(r2::ned_frd_to_enu_flu(q).w() >= 0);
    }
  }
}

TEST_CASE("ROS time of a simulation time", "[ros2]") {
  CHECK(r2::to_time(0).sec == 0);
  CHECK(r2::to_time(12.25).sec == 12);
  CHECK(r2::to_time(12.25).nanosec == 250000000u);
  // Rounding up to a whole second carries.
  CHECK(r2::to_time(0.9999999999).sec == 1);
  CHECK(r2::to_time(0.9999999999).nanosec == 0u);
  CHECK(r2::to_nanoseconds(r2::to_time(3.5)) == 3500000000ULL);
  CHECK_THROWS_AS(r2::to_time(-1), kelp::invalid_argument);
  CHECK_THROWS_AS(r2::to_time(std::nan("")), kelp::invalid_argument);
}

TEST_CASE("ros2msg schema text: the root, then each dependency once, in name order", "[ros2]") {
  const std::string s = r2::schema_text<r2::geometry_msgs::WrenchStamped>();
  const std::string bar(80, '=');
  CHECK(s == std::string("std_msgs/Header header\nWrench wrench\n") + "\n" + bar +
                 "\nMSG: geometry_msgs/Wrench\nVector3  force\nVector3  torque\n\n" + bar +
                 "\nMSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n\n" + bar +
                 "\nMSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n\n" +
                 bar + "\nMSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n");
  // Marker's nested types are all there, each once.
  const std::string m = r2::schema_text<r2::visualization_msgs::MarkerArray>();
  for (const char* t : {"visualization_msgs/Marker", "visualization_msgs/UVCoordinate",
                        "visualization_msgs/MeshFile", "sensor_msgs/CompressedImage",
                        "std_msgs/ColorRGBA", "builtin_interfaces/Duration",
                        "builtin_interfaces/Time", "geometry_msgs/Point", "geometry_msgs/Pose"}) {
    const std::string d = "MSG: " + std::string(t) + "\n";
    const auto first = m.find(d);
    CHECK(first != std::string::npos);
    CHECK(m.find(d, first + 1) == std::string::npos);
  }
}

TEST_CASE("fill_messages: a known sample in ROS's frames", "[ros2]") {
  kelp::vehicle::VehicleStated boat, rov;
  boat.position = {10, 20, 0};                                    // 10 m north, 20 m east
  boat.attitude = kelp::quaternion_from_euler(0.0, 0.0, pi / 2);  // heading east
  boat.nu << 1.5, 0.2, 0, 0, 0, 0.1;                              // surge, sway, yaw rate
  rov.position = {10, 20, 30};                                    // 30 m below the boat
  rov.attitude = Eigen::Quaterniond::Identity();                  // heading north, level
  rov.nu << 0.5, 0, 0.1, 0.01, 0.02, 0.03;
  Eigen::Matrix<double, 3, Eigen::Dynamic> nodes(3, 3);
  nodes.col(0) = Eigen::Vector3d(10, 20, 0.5);  // boat's attachment 0.5 m below its origin
  nodes.col(1) = Eigen::Vector3d(11, 20, 15);
  nodes.col(2) = Eigen::Vector3d(10.2, 20, 30);  // 0.2 m ahead of the ROV's origin
  Eigen::VectorXd tensions(2);
  tensions << 50, 300;
  r2::RunSample s;
  s.time = 12.5;
  s.boat = &boat;
  s.rov = &rov;
  s.nodes = &nodes;
  s.tensions = &tensions;
  s.force_on_boat = Eigen::Vector3d(0, 0, 40);  // pulled down
  s.force_on_rov = Eigen::Vector3d(0, 0, -60);  // pulled up
  s.rov_nu_dot.setZero();
  s.boat_thrust << 10, -5;
  s.boat_command << 0.5, -0.25;
  for (int i = 0; i < 8; ++i) {
    s.rov_thrust(i) = i;
    s.rov_command(i) = 0.1 * i;
  }
  r2::Messages m;
  r2::fill_messages(s, m);

  CHECK(m.clock.clock.sec == 12);
  CHECK(m.clock.clock.nanosec == 500000000u);
  REQUIRE(m.tf.transforms.size() == 2);
  CHECK(m.tf.transforms[0].header.frame_id == "world");
  CHECK(m.tf.transforms[0].child_frame_id == "boat/base_link");
  CHECK(m.tf.transforms[1].child_frame_id == "rov/base_link");
  CHECK(m.tf.transforms[1].transform.translation.x == 20);   // east
  CHECK(m.tf.transforms[1].transform.translation.y == 10);   // north
  CHECK(m.tf.transforms[1].transform.translation.z == -30);  // up
  // The boat heads east: ROS yaw 0.
  CHECK_THAT(std::abs(q_of(m.boat_odom.pose.pose.orientation).w()), WithinAbs(1, 1e-15));
  CHECK(m.boat_odom.child_frame_id == "boat/base_link");
  CHECK(m.boat_odom.twist.twist.linear.x == 1.5);
  CHECK(m.boat_odom.twist.twist.linear.y == -0.2);   // starboard → left
  CHECK(m.boat_odom.twist.twist.angular.z == -0.1);  // yaw rate about down → about up
  CHECK(m.rov_odom.twist.twist.linear.z == -0.1);
  CHECK(m.rov_odom.twist.twist.angular.x == 0.01);
  CHECK(m.rov_odom.twist.twist.angular.y == -0.02);
  // The IMU at zero ν̇: f = ω × v − Rᵀ g e_z, in FLU: about +g up.
  const Eigen::Vector3d v(0.5, 0, 0.1), w(0.01, 0.02, 0.03);
  const Eigen::Vector3d f = r2::frd_to_flu(w.cross(v) - Eigen::Vector3d(0, 0, s.gravity));
  CHECK_THAT(m.rov_imu.linear_acceleration.z, WithinAbs(f.z(), 1e-15));
  CHECK(m.rov_imu.linear_acceleration.z > 9.7);
  CHECK(m.rov_imu.linear_acceleration_covariance[0] == 0);
  // End wrenches: force in the body's FLU axes, moment about its origin.
  CHECK(m.boat_end_force.header.frame_id == "boat/base_link");
  CHECK(m.boat_end_force.wrench.force.z == -40);                      // down → −up
  CHECK_THAT(m.boat_end_force.wrench.torque.x, WithinAbs(0, 1e-12));  // r ∥ F: no moment
  CHECK(m.rov_end_force.wrench.force.z == 60);
  // ROV: r = (0.2, 0, 0) FRD, F = (0, 0, −60) FRD: r × F = (0, 12, 0) FRD → (0, −12, 0) FLU.
  CHECK_THAT(m.rov_end_force.wrench.torque.y, WithinAbs(-12, 1e-12));
  // Markers: the line in world ENU, vertices coloured by tension (red at ≥ the scale).
  REQUIRE(m.markers.markers.size() == 3);
  const auto& line = m.markers.markers[0];
  CHECK(line.type == r2::visualization_msgs::Marker::LINE_STRIP);
  REQUIRE(line.points.size() == 3);
  REQUIRE(line.colors.size() == 3);
  CHECK(line.points[1].x == 20);
  CHECK(line.points[1].y == 11);
  CHECK(line.points[1].z == -15);
  CHECK(line.colors[0].r == Approx(0.25));  // 50 N of 200
  CHECK(line.colors[1].r == 1.0f);          // max(50, 300) clipped
  CHECK(m.markers.markers[1].header.frame_id == "boat/base_link");
  CHECK(m.markers.markers[2].type == r2::visualization_msgs::Marker::CUBE);
  // Thrusters.
  REQUIRE(m.rov_thrusters.name.size() == 8);
  CHECK(m.rov_thrusters.name[7] == "thruster8");
  CHECK(m.rov_thrusters.effort[3] == 3);
  CHECK(m.rov_thrusters.velocity[3] == 0.1 * 3);
  CHECK(m.boat_thrusters.name[1] == "starboard");
  CHECK(m.boat_thrusters.effort[1] == -5);

  SECTION("without ν̇ the IMU says it has no linear acceleration estimate") {
    s.rov_nu_dot.setConstant(std::nan(""));
    r2::fill_messages(s, m);
    CHECK(m.rov_imu.linear_acceleration_covariance[0] == -1);
    CHECK(m.rov_imu.linear_acceleration.z == 0);
  }
  SECTION("bad samples are refused") {
    r2::RunSample bad = s;
    bad.nodes = nullptr;
    CHECK_THROWS_AS(r2::fill_messages(bad, m), kelp::invalid_argument);
    bad = s;
    Eigen::VectorXd wrong(5);
    bad.tensions = &wrong;
    CHECK_THROWS_AS(r2::fill_messages(bad, m), kelp::invalid_argument);
    bad = s;
    bad.rov = nullptr;
    CHECK_THROWS_AS(r2::fill_messages(bad, m), kelp::invalid_argument);
  }
}
