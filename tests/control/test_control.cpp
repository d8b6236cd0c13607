// Controllers: the PID's saturation and anti-windup, its integral set back within its limit; the
// AUV controller holds depth, heading and position and flies a square of waypoints on the
// BlueROV2 Heavy preset; the ASV controller keeps station and follows the AUV on the BlueBoat
// preset, holding the heading it arrived with; the disturbance feedforward lowers the error in a
// current.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
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

TEST_CASE("PID: set_integral refuses a non-finite value and clamps into the integral limit",
          "[control][pid]") {
  kc::Pid p({1.0, 0.5, 0.0, 10.0, 2.0});
  p.set_integral(1.5);
  CHECK(p.integral() == 1.5);  // a value within the limit is kept exactly
  p.set_integral(5.0);
  CHECK(p.integral() == 2.0);
  p.set_integral(-5.0);
  CHECK(p.integral() == -2.0);
  p.set_integral(0.25);
  CHECK_THROWS_AS(p.set_integral(std::nan("")), kelp::invalid_argument);
  CHECK_THROWS_AS(p.set_integral(std::numeric_limits<double>::infinity()), kelp::invalid_argument);
  CHECK(p.integral() == 0.25);  // the refused values changed nothing
  // Without a limit any finite value is kept.
  kc::Pid q({1.0, 0.5, 0.0});
  q.set_integral(-1e6);
  CHECK(q.integral() == -1e6);
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
    kv::step_rk4(r.model, r.ws, env, r.x, {cmd.wrench, Vector6<double>::Zero()}, dt);
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
  CHECK(peak_command <= 1.0);
}

TEST_CASE(
    "AUV controller: saturation follows the thrusters' forward/reverse limits at the "
    "supply voltage",
    "[control][auv][t200]") {
  Rov r;
  r.x.position = Vector3<double>(0, 0, 5);
  // A stiff surge loop (kp 400 N/m, no output limit to speak of) asks for far more than the
  // thrusters give for a target 2 m ahead.
  kc::AuvControllerSettings stiff;
  stiff.surge = kc::PidGains{400.0, 0.0, 0.0, 2000.0, 10.0};
  kc::AuvController c(r.model, r.thrusters, stiff);
  CHECK(c.voltage() == kv::t200_nominal_voltage);
  CHECK(kc::AuvControllerSettings().max_thrust == kv::t200_max_thrust(kv::t200_nominal_voltage));
  c.hold(Vector3<double>(100, 0, 5), 0.0);
  const kc::AuvCommand& at16 = c.update(kc::navigation_of(r.x), 0.0);
  REQUIRE(at16.saturated);
  // Surge uses motors 1-2 on their reverse branch and 3-4 forward (BlueROV2 Heavy, all facing
  // +1): the reverse side limits, so the two front thrusters sit at the 16 V reverse maximum.
  const double rev16 = kv::t200_max_reverse_thrust(16.0);
  CHECK(at16.thrust.head<4>().cwiseAbs().maxCoeff() == Approx(rev16).epsilon(1e-6));
  CHECK(at16.thrust(0) == Approx(-rev16).epsilon(1e-6));
  CHECK(at16.command(0) == Approx(-1.0).epsilon(1e-9));
  const double x16 = at16.wrench(0);
  CHECK(x16 > 0.0);
  // On a sagging battery (12 V) the same demand delivers the 12 V limits: 28.7/39.8 of it.
  kc::AuvController low(r.model, r.thrusters, stiff);
  low.set_voltage(12.0);
  low.hold(Vector3<double>(100, 0, 5), 0.0);
  const kc::AuvCommand& at12 = low.update(kc::navigation_of(r.x), 0.0);
  CHECK(at12.wrench(0) / x16 == Approx(kv::t200_max_reverse_thrust(12.0) / rev16).epsilon(1e-6));
  CHECK_THROWS_AS(low.set_voltage(30.0), kelp::invalid_argument);
  CHECK(low.voltage() == 12.0);
  // The settings' voltage is the starting one.
  kc::AuvControllerSettings s;
  s.voltage = 14.8;
  const kc::AuvController c148(r.model, r.thrusters, s);
  CHECK(c148.voltage() == 14.8);
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
  // The current does push the ROV off: without the feedforward the side drag (≈ 0.4 m/s on the
  // sway damping) is taken up only as the PID's integral builds, over tens of seconds, so the
  // error is tens of centimetres, far above the hold error of calm water (< 5 cm above).
  CHECK(off > 0.1);
  // With it the observer (time constant 1 s) estimates the drag within a few seconds and the
  // thrusters cancel it, leaving only that transient: at least a factor of two less error
  // (a feedforward that only nudged the result, on ≈ off, must fail here).
  CHECK(on < 0.5 * off);
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
  // Within arrive_radius (1 m) the controller gives no surge thrust and only holds the heading,
  // so the boat coasts: it may end anywhere in the circle, or drift out of it by as much as it
  // coasts before the controller takes it back. With surge damping X_u u + X_|u|u |u| u and
  // mass m + X_u̇, a boat at speed u₀ coasts s(u₀) = (m + X_u̇)/X_|u|u · ln(1 + X_|u|u u₀/X_u)
  // (the integral of u du / u̇); surge coasts farthest (sway is damped harder). The bound on its
  // distance from the target is therefore arrive_radius + s(fastest speed inside the circle).
  const auto& bp = b.model.parameters();
  const double coast_mass = bp.mass + bp.added_mass(0, 0), x_u = bp.damping.linear(0, 0),
               x_uu = bp.damping.quadratic(0);
  const auto coast = [&](double u0) { return coast_mass / x_uu * std::log1p(x_uu * u0 / x_u); };
  const double radius = kc::AsvControllerSettings{}.arrive_radius;
  double t = 0, worst = 0, peak = 0, inside_speed = 0, late_speed = 0;
  const double dt = 0.01;
  for (int k = 0; k < 24000; ++k) {  // 240 s
    const kc::AsvCommand& cmd = c.update(kc::navigation_of(b.x), Vector3<double>::Zero(), t);
    peak = std::max({peak, std::abs(cmd.left), std::abs(cmd.right)});
    kv::step_rk4(b.model, b.ws, env, b.x, {cmd.wrench, Vector6<double>::Zero()}, dt);
    t += dt;
    const double d = b.x.position.head<2>().norm(), u = b.x.nu.head<2>().norm();
    if (d < radius) inside_speed = std::max(inside_speed, u);
    if (t > 120.0) worst = std::max(worst, d);
    if (t > 180.0) late_speed = std::max(late_speed, u);
  }
  INFO("station keeping: largest distance over the last 120 s "
       << worst << " m; fastest inside the circle " << inside_speed << " m/s (coasts "
       << coast(inside_speed) << " m); speed over the last 60 s " << late_speed
       << " m/s; peak thrust " << peak << " N");
  CHECK(inside_speed > 0.0);  // it did arrive
  CHECK(worst <= radius + coast(inside_speed));
  // It comes to rest: in calm water nothing acts on a coasting boat but its damping, which takes
  // any speed below 3 m/s (its top speed) down by e^{−t X_u/(m + X_u̇)} = e^{−17} within
  // 60 s, and at rest outside the circle the controller would push it, so it rests inside.
  CHECK(late_speed < 1e-6);
  CHECK(b.x.position.head<2>().norm() <= radius);
  CHECK(peak <= 15.0);
  // Follow an AUV 6 m east of the station, 10 m below: the boat ends above it, at rest.
  c.follow_auv();
  const Vector3<double> auv(0, 6, 10);
  double follow_inside_speed = 0;
  for (int k = 0; k < 24000; ++k) {
    const kc::AsvCommand& cmd = c.update(kc::navigation_of(b.x), auv, t);
    kv::step_rk4(b.model, b.ws, env, b.x, {cmd.wrench, Vector6<double>::Zero()}, dt);
    t += dt;
    if ((b.x.position - auv).head<2>().norm() < radius)
      follow_inside_speed = std::max(follow_inside_speed, b.x.nu.head<2>().norm());
  }
  const double off = (b.x.position - auv).head<2>().norm();
  INFO("following: horizontal distance to the AUV after 240 s "
       << off << " m; fastest inside the circle " << follow_inside_speed << " m/s; final speed "
       << b.x.nu.head<2>().norm() << " m/s");
  CHECK(follow_inside_speed > 0.0);
  CHECK(off <= radius + coast(follow_inside_speed));
  CHECK(b.x.nu.head<2>().norm() < 1e-6);
  CHECK(off <= radius);
}

TEST_CASE("ASV controller (pursuit): following, it holds the heading it arrived with",
          "[control][asv]") {
  Boat b;
  kc::AsvController c(b.model, b.thrusters);
  c.follow_auv();
  const Vector3<double> auv(10, 0, 5);
  kc::Navigation nav;
  const auto at = [&](double north, double psi) {
    nav.position = Vector3<double>(north, 0, 0);
    nav.attitude = kelp::quaternion_from_euler(0.0, 0.0, psi);
  };
  at(0.0, 0.0);  // 10 m off: pursuit
  c.update(nav, auv, 0.0);
  at(9.5, 0.2);  // arrives (0.5 m off, inside arrive_radius) heading 0.2 rad
  CHECK(c.update(nav, auv, 0.1).heading_error == Approx(0.0).margin(1e-12));
  at(9.5, 0.5);  // yawed 0.3 rad further (a wave): it turns back to 0.2 rad
  const kc::AsvCommand& cmd = c.update(nav, auv, 0.2);
  CHECK(cmd.heading_error == Approx(-0.3));
  CHECK(cmd.left < cmd.right);  // more thrust to starboard: the bow turns to port
  // Out of the circle and in again: it holds the heading of the new arrival.
  at(0.0, 0.5);
  c.update(nav, auv, 0.3);
  at(9.5, 1.0);
  c.update(nav, auv, 0.4);
  at(9.5, 1.1);
  CHECK(c.update(nav, auv, 0.5).heading_error == Approx(-0.1));
}

TEST_CASE("Controllers in float: the float instantiations follow the double ones",
          "[control][float]") {
  // The same navigation (a ROV and a boat flying under the double controllers) fed to float
  // controllers built on float models: their commands stay within float rounding of the
  // double ones (the PIDs and errors are double in both).
  Rov r;
  r.x.position = Vector3<double>(1.0, -1.0, 4.0);
  const auto preset_f = kv::bluerov2_heavy<float>();
  const kv::VehicleModel<float> model_f(preset_f.parameters);
  const kv::ThrusterAllocation<float> thrusters_f(preset_f.thruster_positions,
                                                  preset_f.thruster_directions);
  kc::AuvControllerSettings s;
  s.compensate = true;
  kc::AuvController c(r.model, r.thrusters, s);
  kc::AuvControllerT<float> cf(model_f, thrusters_f, s);
  c.hold(Vector3<double>(0, 0, 5), 0.5);
  cf.hold(Vector3<float>(0, 0, 5), 0.5f);
  const ke::Environmentd env;
  const auto to_float = [](const kv::VehicleStated& x) {
    kc::NavigationT<float> nav;
    nav.position = x.position.cast<float>();
    nav.attitude = x.attitude.cast<float>();
    nav.nu = x.nu.cast<float>();
    return nav;
  };
  cf.update(to_float(r.x), 0.0);  // fly() runs c's first update at t = 0: the same schedule
  double t = 0, worst = 0, worst_any = 0, largest = 0;
  fly(r, c, env, t, 20.0, [&](double now, const kc::AuvCommand& cmd) {
    // Both controllers on the same input at the same time (fly()'s own call at `now` then finds
    // the update done).
    const kc::AuvCommandT<float>& f = cf.update(to_float(r.x), now);
    const kc::AuvCommand& d = c.update(kc::navigation_of(r.x), now);
    const double diff = (f.wrench.cast<double>() - d.wrench).cwiseAbs().maxCoeff();
    largest = std::max(largest, d.wrench.cwiseAbs().maxCoeff());
    // While the allocation saturates (the first seconds), rounding can flip an anti-windup
    // decision and the integrals part for a while; settled, only rounding remains.
    if (now > 10.0) worst = std::max(worst, diff);
    worst_any = std::max(worst_any, diff);
    (void)cmd;
  });
  CHECK(largest > 1.0);  // the controller did work
  INFO("worst " << worst << " (any time " << worst_any << ") largest " << largest);
  CHECK(worst < 1e-3 * largest);
  CHECK(worst_any < 0.05 * largest);
  CHECK(cf.voltage() == c.voltage());

  // ASV in float, following a moving point with the tracking law.
  const auto boat = kv::blueboat<double>();
  const auto boat_f = kv::blueboat<float>();
  const kv::VehicleModeld bm(boat.parameters);
  const kv::VehicleModel<float> bmf(boat_f.parameters);
  const kv::ThrusterAllocationd bt(boat.thruster_positions, boat.thruster_directions);
  const kv::ThrusterAllocation<float> btf(boat_f.thruster_positions, boat_f.thruster_directions);
  kc::AsvControllerSettings as;
  as.law = kc::AsvLaw::track;
  kc::AsvController a(bm, bt, as);
  kc::AsvControllerT<float> af(bmf, btf, as);
  a.follow_auv();
  af.follow_auv();
  kv::VehicleWorkspaced ws;
  kv::VehicleStated x;
  double worst_left = 0, largest_left = 0;
  for (int k = 0; k < 2000; ++k) {
    const double now = 0.01 * k;
    const Vector3<double> auv(3.0 + 0.2 * now, -2.0, 10.0);
    kc::NavigationT<float> nav;
    nav.position = x.position.cast<float>();
    nav.attitude = x.attitude.cast<float>();
    nav.nu = x.nu.cast<float>();
    const kc::AsvCommandT<float>& f = af.update(nav, auv.cast<float>(), now);
    const kc::AsvCommand& d = a.update(kc::navigation_of(x), auv, now);
    worst_left = std::max({worst_left, std::abs(f.left - d.left), std::abs(f.right - d.right)});
    largest_left = std::max(largest_left, std::abs(d.left));
    kv::step_rk4(bm, ws, env, x, {d.wrench, Vector6<double>::Zero()}, 0.01);
  }
  CHECK(largest_left > 1.0);
  CHECK(worst_left < 1e-2 * largest_left);
  CHECK((x.position.head<2>() - Vector3<double>(3.0 + 0.2 * 20.0, -2.0, 0).head<2>()).norm() < 5.0);
}
