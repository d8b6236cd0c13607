// Thrusters (kelp/vehicle/thrusters.hpp) and the thruster layouts of the presets
// (kelp/vehicle/presets.hpp).
#include <catch2/catch.hpp>
#include <cmath>

#include "kelp/vehicle/presets.hpp"
#include "kelp/vehicle/thrusters.hpp"

using kelp::Vector3;
using kelp::Vector6;
namespace kv = kelp::vehicle;

TEST_CASE("BlueROV2 Heavy allocation matches ArduSub's vectored_6dof motor factors",
          "[vehicle][thrusters]") {
  const auto p = kv::bluerov2_heavy<double>();
  const kv::ThrusterAllocation<double> alloc(p.thruster_positions, p.thruster_directions);
  REQUIRE(alloc.size() == 8);
  CHECK(alloc.rank() == 6);
  // ArduSub AP_Motors6DOF.cpp vectored_6dof factors (ArduPilot, setup_motors), per motor:
  // roll, pitch, yaw, throttle (climb), forward, lateral. A positive factor means a positive
  // output pushes the vehicle along that demand: roll → +K, pitch → +M, yaw → +N,
  // climb → −Z (NED), forward → +X, lateral → +Y.
  const double factors[8][6] = {{0, 0, +1, 0, -1, +1}, {0, 0, -1, 0, -1, -1}, {0, 0, -1, 0, +1, +1},
                                {0, 0, +1, 0, +1, -1}, {+1, -1, 0, -1, 0, 0}, {-1, -1, 0, -1, 0, 0},
                                {+1, +1, 0, -1, 0, 0}, {-1, +1, 0, -1, 0, 0}};
  const auto& B = alloc.matrix();
  // ArduSub's table is idealised: where a factor is 0 the real geometry may still give a small
  // term (the horizontal thrusters sit 8.5 cm below the CO, so they also roll and pitch by at
  // most 0.085 m × 1/√2 = 0.06 m); where it is ±1 the sign must match.
  const int rows[6] = {3, 4, 5, 2, 0, 1};
  const double flip[6] = {1, 1, 1, -1, 1, 1};  // climb is −Z in NED
  for (int i = 0; i < 8; ++i) {
    for (int j = 0; j < 6; ++j) {
      INFO("motor " << i + 1 << " factor " << j);
      const double b = flip[j] * B(rows[j], i);
      if (factors[i][j] == 0) {
        CHECK(std::abs(b) < 0.061);
      } else {
        CHECK(b * factors[i][j] > 0.05);
      }
    }
  }
  // Symmetry of the layout: all four verticals at +1 give a pure downward force 4 N, no moment;
  // the four horizontals at the "forward" pattern give pure surge 4/√2 N.
  Eigen::VectorXd f = Eigen::VectorXd::Zero(8);
  f.tail<4>().setOnes();
  Vector6<double> expected = Vector6<double>::Zero();
  expected(2) = 4;
  CHECK((alloc.wrench(f) - expected).norm() < 1e-12);
  f.setZero();
  f.head<4>() << -1, -1, 1, 1;
  expected.setZero();
  expected(0) = 4 / std::sqrt(2.0);
  expected(4) = 0.085 * 4 / std::sqrt(2.0);  // thrust 8.5 cm below the CO pitches the nose up
  CHECK((alloc.wrench(f) - expected).norm() < 1e-12);
}

TEST_CASE("pseudo-inverse allocation reproduces any wrench of a fully actuated vehicle",
          "[vehicle][thrusters]") {
  const auto p = kv::bluerov2_heavy<double>();
  const kv::ThrusterAllocation<double> alloc(p.thruster_positions, p.thruster_directions);
  Eigen::VectorXd f(8);
  for (int k = 0; k < 20; ++k) {
    const Vector6<double> tau = Vector6<double>::Random() * 20;
    alloc.distribute(tau, f);
    CHECK((alloc.wrench(f) - tau).norm() < 1e-9 * tau.norm());
  }
}

TEST_CASE("BlueBoat skid steering: equal thrust surges, differential thrust yaws",
          "[vehicle][thrusters]") {
  const auto p = kv::blueboat<double>();
  const kv::ThrusterAllocation<double> alloc(p.thruster_positions, p.thruster_directions);
  CHECK(alloc.rank() == 2);
  const Vector6<double> fwd = alloc.wrench(Eigen::Vector2d(10, 10));
  CHECK(fwd(0) == Approx(20));
  CHECK(fwd(5) == Approx(0).margin(1e-12));
  // Left (port, y = -0.295) forward, right reverse: turn to starboard, N = 2 · 10 · 0.295 > 0.
  const Vector6<double> turn = alloc.wrench(Eigen::Vector2d(10, -10));
  CHECK(turn(0) == Approx(0).margin(1e-12));
  CHECK(turn(5) == Approx(2 * 10 * 0.295));
  // Least squares for a wrench it cannot make exactly: the surge and yaw parts are met.
  Vector6<double> tau = Vector6<double>::Zero();
  tau << 20, 5, 0, 0, 0, 3;
  Eigen::VectorXd f(2);
  alloc.distribute(tau, f);
  const Vector6<double> got = alloc.wrench(f);
  CHECK(got(0) == Approx(20).epsilon(0.02));
  CHECK(got(5) == Approx(3).epsilon(0.02));
}

TEMPLATE_TEST_CASE("von Benzon's T200 polynomial, its peak and its inverse", "[vehicle][thrusters]",
                   double, float) {
  using S = TestType;
  const kv::ThrusterModel& m = kv::von_benzon_t200_model;
  // F(1) = −140.3 + 389.9 − 404.1 + 176.0 + 8.9 = 30.4 N (sum of the coefficients).
  CHECK(double(kv::thrust(m, S(1))) == Approx(30.4).epsilon(1e-6));
  CHECK(kv::thrust(m, S(0)) == S(0));
  CHECK(double(kv::thrust(m, S(-0.6))) == Approx(-double(kv::thrust(m, S(0.6)))));
  CHECK(kv::thrust(m, S(2)) == kv::thrust(m, S(1)));  // clamped
  // The published constants: slope zero at the peak, peak value = max thrust.
  CHECK(std::abs(kv::thrust_slope(m, kv::von_benzon_t200_peak_command)) < 1e-3);  // 8e-5
  CHECK(kv::thrust(m, kv::von_benzon_t200_peak_command) ==
        Approx(kv::von_benzon_t200_max_thrust).epsilon(1e-5));
  // Monotone on [0, u_peak].
  for (int i = 1; i <= 100; ++i) {
    const double u = kv::von_benzon_t200_peak_command * i / 100.0;
    CHECK(kv::thrust_slope(m, u) > 0);
  }
  const double tol = std::is_same<S, float>::value ? 1e-3 : 1e-9;
  for (double f = -30.0; f <= 30.0; f += 0.75) {
    const S u = kv::command_for_thrust(m, S(f));
    CHECK(double(kv::thrust(m, u)) == Approx(f).margin(tol * 30));
    CHECK(std::abs(double(u)) <= kv::von_benzon_t200_peak_command + 1e-6);
  }
  CHECK(double(kv::command_for_thrust(m, S(100))) == Approx(kv::von_benzon_t200_peak_command));
  CHECK(double(kv::command_for_thrust(m, S(-100))) == Approx(-kv::von_benzon_t200_peak_command));
  // The datasheet curve is another model: 51.6 N forward at 16 V against 30.4 N.
  CHECK(double(kv::thrust(kv::t200_model, S(1))) > 50.0);
}

TEMPLATE_TEST_CASE("PWM <-> command mapping with deadband", "[vehicle][thrusters]", double, float) {
  using S = TestType;
  const kv::PwmMapping<S> m;  // 1100-1500-1900, ±25 µs
  kv::validate(m);
  CHECK(kv::command_from_pwm(S(1900), m) == S(1));
  CHECK(kv::command_from_pwm(S(1100), m) == S(-1));
  CHECK(kv::command_from_pwm(S(1500), m) == S(0));
  CHECK(kv::command_from_pwm(S(1520), m) == S(0));
  CHECK(kv::command_from_pwm(S(1475), m) == S(0));
  CHECK(double(kv::command_from_pwm(S(1600), m)) == Approx(0.25));  // (1600−1500)/400
  CHECK(double(kv::command_from_pwm(S(1300), m)) == Approx(-0.5));
  CHECK(kv::command_from_pwm(S(2100), m) == S(1));
  CHECK(double(kv::pwm_from_command(S(0.25), m)) == Approx(1600));
  CHECK(double(kv::pwm_from_command(S(-1), m)) == Approx(1100));
  CHECK(double(kv::pwm_from_command(S(3), m)) == Approx(1900));
  for (double u = -1; u <= 1; u += 0.125) {
    if (std::abs(u) * 400 <= 25) continue;
    CHECK(double(kv::command_from_pwm(kv::pwm_from_command(S(u), m), m)) == Approx(u).margin(1e-6));
  }
  kv::PwmMapping<S> bad;
  bad.deadband_us = S(450);
  CHECK_THROWS_WITH(kv::validate(bad), Catch::Contains("deadband_us"));
  bad = kv::PwmMapping<S>();
  bad.max_us = S(1400);
  CHECK_THROWS_WITH(kv::validate(bad), Catch::Contains("max_us"));
}

TEMPLATE_TEST_CASE(
    "the thruster chain PWM -> command -> thrust -> wrench is the composition of its "
    "parts",
    "[vehicle][thrusters]", double, float) {
  using S = TestType;
  const auto rov = kv::bluerov2_heavy<S>();
  const kv::ThrusterAllocation<S> alloc(rov.thruster_positions, rov.thruster_directions);
  const kv::ThrusterChain<S> chain(alloc, kv::t200_model, rov.pwm);
  Eigen::Matrix<S, 8, 1> pwm, u, f, u_ref, f_ref;
  pwm << S(1100), S(1300), S(1490), S(1510), S(1530), S(1700), S(1900), S(2000);
  const Vector6<S> w = chain.wrench_from_pwm(pwm, u, f);
  for (int i = 0; i < 8; ++i) {
    u_ref(i) = kv::command_from_pwm(pwm(i), rov.pwm);
    f_ref(i) = kv::t200_thrust(u_ref(i));
    CHECK(u(i) == u_ref(i));
    CHECK(f(i) == f_ref(i));
    S c(-7);
    CHECK(chain.thrust_of_pwm(i, pwm(i), &c) == f_ref(i));
    CHECK(c == u_ref(i));
  }
  CHECK(u(2) == S(0));  // inside the dead band
  CHECK(u(7) == S(1));  // clamped
  const Vector6<S> w_ref = alloc.wrench(f_ref);
  CHECK((w - w_ref).norm() <= S(1e-5) * w_ref.norm());
  // The other way, as the controllers use it: desired force -> command -> delivered thrust,
  // saturated at the largest thrust that way (forward 51.6 N, reverse 39.8 N at 16 V).
  Eigen::Matrix<S, 8, 1> want, cmd, got;
  want << S(-45), S(-30), S(-5), S(0), S(0.5), S(12), S(50), S(100);
  chain.commands_for(want, cmd, got);
  const double up = kv::t200_max_thrust(16.0), down = kv::t200_max_reverse_thrust(16.0);
  for (int i = 0; i < 8; ++i) {
    CHECK(cmd(i) == kv::t200_command(want(i)));
    CHECK(got(i) == kv::t200_thrust(cmd(i)));
    const double wanted = double(want(i));
    if (wanted < up && wanted > -down)
      CHECK(double(got(i)) == Approx(wanted).margin(1e-3));
    else
      CHECK(double(got(i)) == Approx(wanted > 0 ? up : -down).epsilon(1e-5));
  }
  // One curve, written once: the slope is the derivative of the thrust (central differences).
  for (double x = -0.95; x <= 0.95; x += 0.05) {
    const double h = 1e-6;
    const double fd = (kv::t200_thrust(x + h) - kv::t200_thrust(x - h)) / (2 * h);
    CHECK(kv::t200_thrust_slope(x) == Approx(fd).epsilon(1e-6));
  }
  // A model with other coefficients changes the chain in one place.
  const kv::ThrusterChain<S> poly(alloc, kv::von_benzon_t200_model, rov.pwm);
  kv::ThrusterModel half = kv::von_benzon_t200_model;
  for (double& c : half.odd_coefficients) c *= 0.5;
  half.max_thrust *= 0.5;
  const kv::ThrusterChain<S> weak(alloc, half, rov.pwm);
  Eigen::Matrix<S, 8, 1> u1, f1, u2, f2;
  const Vector6<S> w1 = poly.wrench_from_pwm(pwm, u1, f1);
  const Vector6<S> w2 = weak.wrench_from_pwm(pwm, u2, f2);
  CHECK((w2 - S(0.5) * w1).norm() <= S(1e-5) * w1.norm());
  kv::ThrusterModel bad = kv::von_benzon_t200_model;
  bad.peak_command = 1.5;
  CHECK_THROWS_AS(kv::ThrusterChain<S>(alloc, bad), kelp::invalid_argument);
}
