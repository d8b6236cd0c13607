// Controllers: the PID's saturation and anti-windup; the AUV controller holds depth, heading and
// position and flies a square of waypoints on the BlueROV2 Heavy preset; the ASV controller keeps
// station and follows the AUV on the BlueBoat preset; the disturbance feedforward lowers the
// error in a current.
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "kelp/control/controllers.hpp"
#include "kelp/control/pid.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/vehicle/integrators.hpp"
#include "kelp/vehicle/presets.hpp"

namespace kc = kelp::control;
namespace kv = kelp::vehicle;
namespace ke = kelp::environment;
using kelp::Vector3;
using kelp::Vector6;

TEST_CASE("PID: proportional, integral, derivative on measurement, saturation without windup",
          "[control][pid]") {
  kc::Pid p({2.0, 0.5, 0.3, 10.0});
  // First update: no derivative memory; P + I.
  CHECK(p.update(1.0, 0.1) == Approx(2.0 + 0.5 * 0.1));
  // Backward difference of the error: (0.5 − 1)/0.1 = −5 → kd·(−5) = −1.5.
  CHECK(p.update(0.5, 0.1) == Approx(2.0 * 0.5 + 0.5 * 0.15 - 1.5));
  // A measured rate replaces the difference.
  CHECK(p.update(0.5, 0.1, 2.0) == Approx(1.0 + 0.5 * 0.2 + 0.6));
  // Saturated with the error pushing out: the output is clamped and the integral frozen.
  p.reset();
  for (int k = 0; k < 100; ++k) p.update(50.0, 0.1);
  CHECK(p.output() == 10.0);
  CHECK(p.saturated());
  CHECK(p.integral() == Approx(0.0).margin(1e-12));  // 2·50 alone saturates: never integrated
  // The error reverses: the output leaves saturation at once (no wound-up integral to unwind).
  CHECK(p.update(-1.0, 0.1) < 0.0);
  CHECK_THROWS_AS(kc::Pid({-1.0, 0, 0}), kelp::invalid_argument);
  CHECK_THROWS_AS(kc::Pid({1.0, 0, 0, 0.0}), kelp::invalid_argument);
  CHECK_THROWS_AS(p.update(std::nan(""), 0.1), kelp::invalid_argument);
  CHECK_THROWS_AS(p.update(1.0, 0.0), kelp::invalid_argument);
}

namespace {

struct Rov {
  kv::VehiclePresetd preset = kv::bluerov2_heavy<double>();
  kv::VehicleModeld model{preset.parameters};
  kv::ThrusterAllocationd thrusters{preset.thruster_positions, preset.thruster_directions};
  kv::VehicleWorkspaced ws;
  kv::VehicleStated x;
};

// Steps the ROV under its controller for `seconds` in `env`; calls f(t, command) each step.
template <typename F>
void fly(Rov& r, kc::AuvController& c, const ke::Environmentd& env, double& t, double seconds,
         F&& f) {
  const double dt = 0.01;
  const int n = static_cast<int>(std::lround(seconds / dt));
  for (int k = 0; k < n; ++k) {
    const kc::AuvCommand& cmd = c.update(kc::navigation_of(r.x), t);
    kv::step_rk4(r.model, r.ws, r.x, dt, cmd.wrench, Vector6<double>::Zero(), env, t);
    t += dt;
    f(t, cmd);
  }
}

}  // namespace

TEST_CASE("AUV controller: depth, heading and position hold in calm water", "[control][auv]") {
  Rov r;
  r.x.position = Vector3<double>(1.0, -1.0, 4.0);  // 1.4 m off, 1 m shallow, heading north
  kc::AuvController c(r.model, r.thrusters);
  c.hold(Vector3<double>(0, 0, 5), 0.5);
  const ke::Environmentd env;
  double t = 0, worst_z = 0, worst_xy = 0, worst_psi = 0, peak_command = 0;
  fly(r, c, env, t, 60.0, [&](double now, const kc::AuvCommand& cmd) {
    peak_command = std::max(peak_command, cmd.command.cwiseAbs().maxCoeff());
    if (now < 30.0) return;  // settled after 30 s
    worst_z = std::max(worst_z, std::abs(r.x.position.z() - 5.0));
    worst_xy = std::max(worst_xy, r.x.position.head<2>().norm());
    worst_psi = std::max(worst_psi, std::abs(kc::wrap_angle(kc::heading_of(r.x.attitude) - 0.5)));
  });
  INFO("after settling: depth error " << worst_z << " m, horizontal " << worst_xy << " m, heading "
                                      << worst_psi << " rad; peak command " << peak_command);
  CHECK(worst_z < 0.05);
  CHECK(worst_xy < 0.05);
  CHECK(worst_psi < 0.02);
  CHECK(peak_command <= kv::t200_peak_command + 1e-12);
}

TEST_CASE("AUV controller: a 10 m square of waypoints at 5 m depth", "[control][auv]") {
  Rov r;
  r.x.position = Vector3<double>(0, 0, 5);
  kc::AuvController c(r.model, r.thrusters);
  const std::vector<Vector3<double>> square{{10, 0, 5}, {10, 10, 5}, {0, 10, 5}, {0, 0, 5}};
  c.follow(square);
  const ke::Environmentd env;
  double t = 0, worst_depth = 0, done_at = -1;
  fly(r, c, env, t, 200.0, [&](double now, const kc::AuvCommand&) {
    worst_depth = std::max(worst_depth, std::abs(r.x.position.z() - 5.0));
    if (done_at < 0 && c.next_waypoint() == square.size()) done_at = now;
  });
  INFO("all waypoints reached at " << done_at << " s; worst depth error " << worst_depth << " m");
  CHECK(done_at > 0);
  CHECK(worst_depth < 0.1);
  CHECK((r.x.position - square.back()).norm() < 0.5);
  CHECK_THROWS_AS(c.follow({}), kelp::invalid_argument);
}

TEST_CASE("AUV controller: the disturbance feedforward lowers the error in a current",
          "[control][auv][compensation]") {
  // A 0.4 m/s current from the side switches on at t = 10 s; the ROV holds its position. The
  // feedforward sees only the ROV's own model and navigation.
  const auto run = [](bool compensate) {
    Rov r;
    r.x.position = Vector3<double>(0, 0, 5);
    kc::AuvControllerSettings s;
    s.compensate = compensate;
    kc::AuvController c(r.model, r.thrusters, s);
    c.hold(Vector3<double>(0, 0, 5), 0.0);
    ke::Environmentd still, current;
    ke::CurrentParameters cp;
    cp.speed = 0.4;
    cp.direction = 0.5 * kelp::pi;  // towards the east: sideways for the ROV
    current.set_current(ke::CurrentModeld(cp));
    double t = 0, sum = 0;
    int n = 0;
    fly(r, c, still, t, 10.0, [](double, const kc::AuvCommand&) {});
    fly(r, c, current, t, 40.0, [&](double, const kc::AuvCommand&) {
      sum += r.x.position.head<2>().squaredNorm();
      ++n;
    });
    return std::sqrt(sum / n);
  };
  const double off = run(false), on = run(true);
  INFO("RMS horizontal error over the 40 s after the current starts: " << off << " m without, "
                                                                       << on << " m with");
  CHECK(on < off);
}

namespace {

struct Boat {
  kv::VehiclePresetd preset = kv::blueboat<double>();
  kv::VehicleModeld model{preset.parameters};
  kv::ThrusterAllocationd thrusters{preset.thruster_positions, preset.thruster_directions};
  kv::VehicleWorkspaced ws;
  kv::VehicleStated x;
};

}  // namespace

TEST_CASE("ASV controller: station keeping and following with the paper's gains",
          "[control][asv]") {
  Boat b;
  b.x.position = Vector3<double>(-8, 5, 0);
  kc::AsvController c(b.model, b.thrusters);
  c.station(Vector3<double>(0, 0, 0), 0.0);
  const ke::Environmentd env;
  double t = 0, worst = 0, peak = 0;
  const double dt = 0.01;
  for (int k = 0; k < 24000; ++k) {  // 240 s
    const kc::AsvCommand& cmd = c.update(kc::navigation_of(b.x), Vector3<double>::Zero(), t);
    peak = std::max({peak, std::abs(cmd.left), std::abs(cmd.right)});
    kv::step_rk4(b.model, b.ws, b.x, dt, cmd.wrench, Vector6<double>::Zero(), env, t);
    t += dt;
    if (t > 120.0) worst = std::max(worst, b.x.position.head<2>().norm());
  }
  INFO("station keeping: largest distance over the last 120 s " << worst << " m; peak thrust "
                                                                << peak << " N");
  CHECK(worst < 1.0);
  CHECK(peak <= 15.0);
  // Follow an AUV 6 m east of the station, 10 m below: the boat ends above it.
  c.follow_auv();
  const Vector3<double> auv(0, 6, 10);
  for (int k = 0; k < 24000; ++k) {
    const kc::AsvCommand& cmd = c.update(kc::navigation_of(b.x), auv, t);
    kv::step_rk4(b.model, b.ws, b.x, dt, cmd.wrench, Vector6<double>::Zero(), env, t);
    t += dt;
  }
  const double off = (b.x.position - auv).head<2>().norm();
  INFO("following: horizontal distance to the AUV after 240 s " << off << " m");
  CHECK(off < 1.0);
}
