// The ROS 2 commands (commands.hpp) without DDS: frames (FLU → FRD), refusals and their reasons,
// the timeout, and no allocation in a step's apply().
#include <Eigen/Core>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "commands.hpp"
#include "kelp/sim/closed_loop.hpp"

namespace {

kelp::sim::Scenario calm() {
  kelp::sim::Scenario sc;
  sc.sea = kelp::sim::Sea::calm;
  sc.duration = 5.0;
  sc.segment_length = 1.0;
  return sc;
}

const double not_a_number = std::numeric_limits<double>::quiet_NaN();

}  // namespace

TEST_CASE("ROS 2 wrench commands are turned from FLU to FRD and allocated") {
  kelp::sim::ClosedLoop loop(calm());
  kelp_ros2::PairCommander cmd(loop);
  REQUIRE(loop.auv_override() == nullptr);
  // 30 N to the left (FLU +y) and 20 N up (FLU +z): to port (FRD −y) and up (FRD −z).
  const double f[3] = {0, 30, 20}, t[3] = {0, 0, 0};
  REQUIRE(cmd.rov_wrench(f, t) == kelp_ros2::Refusal::none);
  cmd.apply();
  const kelp::control::AuvCommand* o = loop.auv_override();
  REQUIRE(o != nullptr);
  CHECK(o->wrench(0) == Approx(0).margin(0.5));
  CHECK(o->wrench(1) == Approx(-30).epsilon(0.05));
  CHECK(o->wrench(2) == Approx(-20).epsilon(0.05));
  // A yaw moment to the left (FLU +z, counter-clockwise from above) is FRD −N.
  const double f0[3] = {0, 0, 0}, left[3] = {0, 0, 5};
  REQUIRE(cmd.rov_wrench(f0, left) == kelp_ros2::Refusal::none);
  cmd.apply();
  CHECK(loop.auv_override()->wrench(5) == Approx(-5).epsilon(0.05));
}

TEST_CASE("ROS 2 commands that are not finite or absurd are refused and change nothing") {
  kelp::sim::ClosedLoop loop(calm());
  kelp_ros2::PairCommander cmd(loop);
  const double z[3] = {0, 0, 0}, bad[3] = {not_a_number, 0, 0}, huge[3] = {1e6, 0, 0};
  const double inf[3] = {0, 0, std::numeric_limits<double>::infinity()};
  CHECK(cmd.rov_wrench(bad, z) == kelp_ros2::Refusal::not_finite);
  CHECK(cmd.rov_wrench(z, inf) == kelp_ros2::Refusal::not_finite);
  CHECK(cmd.rov_wrench(huge, z) == kelp_ros2::Refusal::out_of_range);
  CHECK(cmd.rov_velocity(bad, z) == kelp_ros2::Refusal::not_finite);
  const double fast[3] = {6, 0, 0};
  CHECK(cmd.rov_velocity(fast, z) == kelp_ros2::Refusal::out_of_range);
  CHECK(cmd.boat_velocity(fast, z) == kelp_ros2::Refusal::out_of_range);
  CHECK(cmd.payout(not_a_number) == kelp_ros2::Refusal::not_finite);
  CHECK(cmd.payout(0.1) == kelp_ros2::Refusal::unavailable);  // no winch in this scenario
  cmd.apply();
  CHECK(loop.auv_override() == nullptr);
  CHECK(loop.asv_override() == nullptr);
  CHECK_FALSE(cmd.rov_commanded());
  // Within the margin a wrench beyond the thrusters is delivered saturated, not refused.
  const double strong[3] = {250, 0, 0};
  CHECK(cmd.rov_wrench(strong, z) == kelp_ros2::Refusal::none);
  cmd.apply();
  CHECK(loop.auv_override()->saturated);
  CHECK(loop.auv_override()->wrench(0) < 250);

  kelp_ros2::SubscriptionCounters c;
  c.count(kelp_ros2::Refusal::none);
  c.count(kelp_ros2::Refusal::not_finite);
  c.count(kelp_ros2::Refusal::out_of_range);
  CHECK(c.received == 3);
  CHECK(c.accepted == 1);
  CHECK(c.refused() == 2);
}

TEST_CASE("a ROS 2 command lapses after its timeout and kelp's controller flies again") {
  kelp::sim::ClosedLoop loop(calm());
  kelp_ros2::PairCommander cmd(loop);
  const double f[3] = {20, 0, 0}, z[3] = {0, 0, 0};
  REQUIRE(cmd.rov_wrench(f, z) == kelp_ros2::Refusal::none);
  const double turn_left[3] = {0, 0, 0.3}, ahead[3] = {0.5, 0, 0};
  REQUIRE(cmd.boat_velocity(ahead, turn_left) == kelp_ros2::Refusal::none);
  cmd.apply();
  REQUIRE(cmd.rov_commanded());
  REQUIRE(cmd.boat_commanded());
  // Turning left (FLU +z yaw rate) at rest: more thrust to starboard than to port.
  CHECK(loop.asv_override()->right > loop.asv_override()->left);
  for (int i = 0; i < 40; ++i) {  // 0.4 s: still held, and no allocation in apply()
    Eigen::internal::set_is_malloc_allowed(false);
    cmd.apply();
    Eigen::internal::set_is_malloc_allowed(true);
    loop.step();
  }
  CHECK(cmd.rov_commanded());
  CHECK(loop.state().auv.nu(0) > 0.01);  // pushed forward
  for (int i = 0; i < 20; ++i) {         // past 0.5 s without a new command
    cmd.apply();
    loop.step();
  }
  cmd.apply();
  CHECK_FALSE(cmd.rov_commanded());
  CHECK_FALSE(cmd.boat_commanded());
  CHECK(loop.auv_override() == nullptr);
  CHECK(loop.asv_override() == nullptr);
}

TEST_CASE("ROS 2 velocity commands drive the ROV through its velocity loop") {
  kelp::sim::ClosedLoop loop(calm());
  kelp_ros2::PairCommander cmd(loop);
  const double v[3] = {0.3, 0, 0}, z[3] = {0, 0, 0};
  for (int i = 0; i < 300; ++i) {  // 3 s at 0.3 m/s forward, commanded at 100 Hz
    REQUIRE(cmd.rov_velocity(v, z) == kelp_ros2::Refusal::none);
    cmd.apply();
    loop.step();
  }
  CHECK(loop.state().auv.nu(0) == Approx(0.3).margin(0.1));
}

TEST_CASE("/tether/cmd_payout drives the winch through ClosedLoop's override, within its limits") {
  kelp::sim::Scenario sc = calm();
  sc.winch.enabled = true;  // the scenario file's defaults (e.g. max_speed 0.5 m/s)
  kelp::sim::ClosedLoop loop(sc);
  kelp_ros2::PairCommander cmd(loop);
  const double top = loop.model().winch()->winch().max_speed;
  CHECK(cmd.payout(3 * top) == kelp_ros2::Refusal::out_of_range);
  const double length0 = loop.sample().tether_length;
  for (int i = 0; i < 200; ++i) {  // 2 s paying out at 0.2 m/s, commanded at 100 Hz
    REQUIRE(cmd.payout(0.2) == kelp_ros2::Refusal::none);
    cmd.apply();
    loop.step();
  }
  CHECK(cmd.payout_commanded());
  CHECK(loop.state().tether.payout_rate == Approx(0.2).margin(1e-9));
  CHECK(loop.sample().tether_length > length0 + 0.25);
  // 1.5 × the top speed is accepted (within the margin) and limited by the winch.
  for (int i = 0; i < 300; ++i) {
    REQUIRE(cmd.payout(1.5 * top) == kelp_ros2::Refusal::none);
    cmd.apply();
    loop.step();
  }
  CHECK(loop.state().tether.payout_rate == Approx(top).margin(1e-9));
}
