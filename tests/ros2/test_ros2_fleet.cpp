// A fleet's ROS 2 messages and bag (kelp/sim/ros2/fleet.hpp): the pair described as a fleet gets
// the pair's messages (kelp/sim/ros2/messages.hpp, whose values test_ros2_messages.cpp checks
// by hand) under its own names; ends on anchors are given in `world`; names are ROS names; the
// bag has a channel per part and allocates nothing per sample once running.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>

#include "kelp/core/rotation.hpp"
#include "kelp/sim/ros2/fleet.hpp"

namespace r2 = kelp::ros2;

namespace kelp_test {
extern long allocations;  // count_allocations.cpp
}

namespace {

bool same(const r2::geometry_msgs::Vector3& a, const r2::geometry_msgs::Vector3& b) {
  return a.x == b.x && a.y == b.y && a.z == b.z;
}

// The pair of test_ros2_messages.cpp's known sample, in both forms.
struct Pair {
  kelp::vehicle::VehicleStated boat, rov;
  Eigen::Matrix<double, 3, Eigen::Dynamic> nodes{3, 3};
  Eigen::VectorXd tensions{2};
  Eigen::VectorXd boat_thrust{2}, boat_command{2}, rov_thrust{8}, rov_command{8};
  r2::RunSample pair;
  r2::FleetSample fleet;

  Pair() {
    boat.position = {10, 20, 0};
    boat.attitude = kelp::quaternion_from_euler(0.0, 0.0, 1.2);
    boat.nu << 1.5, 0.2, 0, 0, 0, 0.1;
    rov.position = {10, 20, 30};
    rov.attitude = kelp::quaternion_from_euler(0.1, -0.2, 0.3);
    rov.nu << 0.5, 0, 0.1, 0.01, 0.02, 0.03;
    nodes.col(0) = Eigen::Vector3d(10, 20, 0.5);
    nodes.col(1) = Eigen::Vector3d(11, 20, 15);
    nodes.col(2) = Eigen::Vector3d(10.2, 20, 30);
    tensions << 50, 300;
    boat_thrust << 10, -5;
    boat_command << 0.5, -0.25;
    for (int i = 0; i < 8; ++i) {
      rov_thrust(i) = i;
      rov_command(i) = 0.1 * i;
    }
    pair.time = 12.5;
    pair.boat = &boat;
    pair.rov = &rov;
    pair.nodes = &nodes;
    pair.tensions = &tensions;
    pair.force_on_boat = Eigen::Vector3d(1, -2, 40);
    pair.force_on_rov = Eigen::Vector3d(-1, 2, -60);
    pair.rov_nu_dot << 0.1, -0.2, 0.3, 0.01, 0.02, -0.03;
    pair.boat_thrust = boat_thrust;
    pair.boat_command = boat_command;
    pair.rov_thrust = rov_thrust;
    pair.rov_command = rov_command;

    fleet.time = pair.time;
    r2::FleetVehicleSample b, r;
    b.name = "boat";
    b.state = &boat;
    b.thrusters = 2;
    b.thrust = boat_thrust.data();
    b.command = boat_command.data();
    r.name = "rov";
    r.state = &rov;
    r.nu_dot = pair.rov_nu_dot;
    r.thrusters = 8;
    r.thrust = rov_thrust.data();
    r.command = rov_command.data();
    fleet.vehicles = {b, r};
    r2::FleetTetherSample t;
    t.name = "tether";
    t.nodes = &nodes;
    t.tensions = &tensions;
    t.force_at_start = pair.force_on_boat;
    t.force_at_end = pair.force_on_rov;
    t.start_vehicle = 0;
    t.end_vehicle = 1;
    fleet.tethers = {t};
  }
};

}  // namespace

TEST_CASE("ROS names: a letter, then letters, digits and single underscores", "[ros2][fleet]") {
  for (const char* ok : {"rov", "rov_a", "ROV2", "tms", "a1_b2"}) CHECK(r2::is_ros_name(ok));
  for (const char* bad :
       {"", "2rov", "_rov", "rov_", "rov__a", "rov-a", "rov/a", "rov a", "rov,a", "ünï"})
    CHECK_FALSE(r2::is_ros_name(bad));
  CHECK(r2::is_ros_name(std::string(64, 'a')));
  CHECK_FALSE(r2::is_ros_name(std::string(65, 'a')));
}

TEST_CASE("the pair as a fleet: the pair's messages under the parts' names", "[ros2][fleet]") {
  Pair p;
  r2::Messages pm;
  r2::fill_messages(p.pair, pm);
  r2::FleetMessages fm;
  r2::fill_fleet_messages(p.fleet, fm);

  CHECK(fm.clock.clock.sec == pm.clock.clock.sec);
  CHECK(fm.clock.clock.nanosec == pm.clock.clock.nanosec);
  REQUIRE(fm.tf.transforms.size() == 2);
  for (std::size_t i = 0; i < 2; ++i) {
    CHECK(fm.tf.transforms[i].child_frame_id == pm.tf.transforms[i].child_frame_id);
    CHECK(
        same(fm.tf.transforms[i].transform.translation, pm.tf.transforms[i].transform.translation));
  }
  const r2::nav_msgs::Odometry* odoms[2] = {&pm.boat_odom, &pm.rov_odom};
  for (std::size_t i = 0; i < 2; ++i) {
    const auto &a = fm.odom[i], &b = *odoms[i];
    CHECK(a.header.frame_id == "world");
    CHECK(a.child_frame_id == b.child_frame_id);
    CHECK(a.pose.pose.position.x == b.pose.pose.position.x);
    CHECK(a.pose.pose.orientation.w == b.pose.pose.orientation.w);
    CHECK(a.pose.pose.orientation.z == b.pose.pose.orientation.z);
    CHECK(same(a.twist.twist.linear, b.twist.twist.linear));
    CHECK(same(a.twist.twist.angular, b.twist.twist.angular));
  }
  // The ROV's IMU with its ν̇; the boat's has none ("no estimate").
  CHECK(same(fm.imu[1].linear_acceleration, pm.rov_imu.linear_acceleration));
  CHECK(same(fm.imu[1].angular_velocity, pm.rov_imu.angular_velocity));
  CHECK(fm.imu[1].header.frame_id == "rov/base_link");
  CHECK(fm.imu[0].linear_acceleration_covariance[0] == -1);
  // End wrenches: start end (the boat's) then the far end (the ROV's), as the pair's.
  REQUIRE(fm.end_forces.size() == 2);
  CHECK(fm.end_forces[0].header.frame_id == "boat/base_link");
  CHECK(same(fm.end_forces[0].wrench.force, pm.boat_end_force.wrench.force));
  CHECK(same(fm.end_forces[0].wrench.torque, pm.boat_end_force.wrench.torque));
  CHECK(fm.end_forces[1].header.frame_id == "rov/base_link");
  CHECK(same(fm.end_forces[1].wrench.force, pm.rov_end_force.wrench.force));
  CHECK(same(fm.end_forces[1].wrench.torque, pm.rov_end_force.wrench.torque));
  // Thrusters: the same commands and thrusts (the fleet names them thruster1…).
  CHECK(fm.thrusters[1].effort == pm.rov_thrusters.effort);
  CHECK(fm.thrusters[1].velocity == pm.rov_thrusters.velocity);
  CHECK(fm.thrusters[0].effort == pm.boat_thrusters.effort);
  CHECK(fm.thrusters[0].name[1] == "thruster2");
  // Markers: the line (ns the tether's name) with the pair's points and colours, then a box per
  // vehicle in its frame.
  REQUIRE(fm.markers.markers.size() == 3);
  const auto &line = fm.markers.markers[0], &pair_line = pm.markers.markers[0];
  CHECK(line.ns == "tether");
  REQUIRE(line.points.size() == pair_line.points.size());
  for (std::size_t i = 0; i < line.points.size(); ++i) {
    CHECK(line.points[i].z == pair_line.points[i].z);
    CHECK(line.colors[i].r == pair_line.colors[i].r);
  }
  CHECK(fm.markers.markers[2].header.frame_id == "rov/base_link");
  CHECK(fm.markers.markers[2].type == r2::visualization_msgs::Marker::CUBE);
}

TEST_CASE("a fleet's anchor and point mass ends are given in world; bad samples refused",
          "[ros2][fleet]") {
  Pair p;
  // The line now runs from an anchor to a clump weight; the ROV holds nothing.
  r2::FleetTetherSample& t = p.fleet.tethers[0];
  t.start_vehicle = -1;
  t.end_vehicle = -1;
  r2::FleetPointMassSample clump;
  clump.name = "clump";
  clump.position = Eigen::Vector3d(10.2, 20, 30);
  clump.diameter = 0.4;
  p.fleet.point_masses = {clump};
  r2::FleetMessages m;
  r2::fill_fleet_messages(p.fleet, m);
  CHECK(m.end_forces[0].header.frame_id == "world");
  // NED (1, −2, 40) → ENU (−2, 1, −40); no moment about the end node.
  CHECK(m.end_forces[0].wrench.force.x == -2);
  CHECK(m.end_forces[0].wrench.force.y == 1);
  CHECK(m.end_forces[0].wrench.force.z == -40);
  CHECK(m.end_forces[0].wrench.torque.x == 0);
  REQUIRE(m.tf.transforms.size() == 3);
  CHECK(m.tf.transforms[2].child_frame_id == "clump");
  CHECK(m.tf.transforms[2].transform.translation.z == -30);
  REQUIRE(m.markers.markers.size() == 4);
  CHECK(m.markers.markers[3].type == r2::visualization_msgs::Marker::SPHERE);
  CHECK(m.markers.markers[3].scale.x == 0.4);

  r2::FleetSample bad = p.fleet;
  bad.vehicles[0].name = "boat one";
  CHECK_THROWS_AS(r2::fill_fleet_messages(bad, m), kelp::invalid_argument);
  bad = p.fleet;
  bad.tethers[0].end_vehicle = 2;  // there are two vehicles
  CHECK_THROWS_AS(r2::fill_fleet_messages(bad, m), kelp::invalid_argument);
  bad = p.fleet;
  bad.vehicles[1].state = nullptr;
  CHECK_THROWS_AS(r2::fill_fleet_messages(bad, m), kelp::invalid_argument);
  bad = p.fleet;
  Eigen::VectorXd wrong(5);
  bad.tethers[0].tensions = &wrong;
  CHECK_THROWS_AS(r2::fill_fleet_messages(bad, m), kelp::invalid_argument);
}

TEST_CASE("FleetBagWriter: a channel per part, no heap allocation per sample once running",
          "[ros2][fleet][mcap]") {
  Pair p;
  const std::filesystem::path path = "test_ros2_fleet_bag.mcap";
  {
    r2::FleetSample twice = p.fleet;
    twice.vehicles[1].name = "boat";
    CHECK_THROWS_AS(r2::FleetBagWriter(path, twice), kelp::invalid_argument);
  }
  r2::FleetBagWriter bag(path, p.fleet);
  r2::FleetMessages m;
  int k = 0;
  // Warm up: the first chunks size every buffer (at the same marker rate: a chunk of smaller
  // samples holds more of them, and each channel's message index grows with that count).
  for (; k < 3000; ++k) {
    p.fleet.time = 0.1 * k;
    r2::fill_fleet_messages(p.fleet, m);
    bag.write(m, k % 10 == 0);
  }
  const long before = kelp_test::allocations;
  for (; k < 3100; ++k) {
    p.fleet.time = 0.1 * k;
    r2::fill_fleet_messages(p.fleet, m);
    bag.write(m, k % 10 == 0);
  }
  // Only a chunk index entry a flushed chunk may allocate (a few per 100 samples at most).
  CHECK(kelp_test::allocations - before <= 8);
  // Per sample: clock, tf, 2 × (odom, imu, thrusters), 2 end forces; markers every 10th.
  CHECK(bag.mcap().message_count() == 3100u * 10 + 310u);
  r2::FleetMessages other;
  r2::FleetSample one = p.fleet;
  one.vehicles.pop_back();
  one.tethers.clear();
  r2::fill_fleet_messages(one, other);
  CHECK_THROWS_AS(bag.write(other), kelp::invalid_argument);
  bag.close();
  std::filesystem::remove(path);
}
