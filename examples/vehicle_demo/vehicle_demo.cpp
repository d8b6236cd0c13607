// kelp vehicle demo: a BlueROV2 Heavy dives to 5 m under a depth PID that drives its eight
// thrusters through the allocation matrix (desired wrench → thrust → T200 command → PWM → ESC
// dead band → thrust), and a BlueBoat accelerates from rest to top speed on two T200 thrusters.
// Runs in a few milliseconds; takes no arguments.
#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "kelp/core/rotation.hpp"
#include "kelp/vehicle/integrators.hpp"
#include "kelp/vehicle/model.hpp"
#include "kelp/vehicle/presets.hpp"
#include "kelp/vehicle/thrusters.hpp"

namespace kv = kelp::vehicle;
using kelp::Vector3;
using kelp::Vector6;

namespace {

// Thrusters as the autopilot drives them: commands → PWM, and PWM → ESC (dead band) → thrust.
Vector6<double> thrust_from_pwm(const kv::ThrusterAllocation<double>& alloc,
                                const kv::PwmMapping<double>& pwm_map, const Eigen::VectorXd& pwm,
                                Eigen::VectorXd& forces) {
  for (Eigen::Index i = 0; i < pwm.size(); ++i)
    forces(i) = kv::t200_thrust(kv::command_from_pwm(pwm(i), pwm_map));
  return alloc.wrench(forces);
}

void dive() {
  const auto rov = kv::bluerov2_heavy<double>();
  const kv::VehicleModel<double> model(rov.parameters);
  const kv::ThrusterAllocation<double> alloc(rov.thruster_positions, rov.thruster_directions);
  kv::VehicleWorkspace<double> ws;
  kv::VehicleState<double> x;  // at the surface, level, at rest
  Eigen::VectorXd f(alloc.size()), pwm(alloc.size()), actual(alloc.size());

  // Depth PID on the NED heave force. Heave inertia m + A_33 = 32.2 kg, linear damping 33 N s/m:
  // Kp = 32 N/m, Kd = 30 N s/m give ω ≈ 1 rad/s, ζ ≈ 1; Ki trims what the feedforward of the net
  // buoyancy misses. The four vertical T200 saturate at ≈ 122 N, so the integrator only runs
  // within 0.5 m of the target and is clamped (anti-windup).
  const double kp = 32, ki = 4, kd = 30, z_ref = 5.0, dt = 0.005, t_end = 30.0;
  const double feedforward = model.buoyancy() - model.weight();  // push down what floats up
  double integral = 0, settled_at = -1;
  std::printf("BlueROV2 Heavy: dive to %.1f m (net buoyancy %+.2f N, RK4 at %.0f Hz)\n", z_ref,
              feedforward, 1 / dt);
  std::printf("%6s %9s %9s %9s %10s %11s\n", "t [s]", "depth [m]", "w [m/s]", "pitch[deg]",
              "PWM5 [us]", "Z_thr [N]");
  const int steps = static_cast<int>(std::lround(t_end / dt));
  for (int k = 0; k <= steps; ++k) {
    const double t = k * dt;
    const Vector3<double> v_ned = x.attitude * Vector3<double>(x.nu.head<3>());
    const double e = z_ref - x.position(2);
    if (std::abs(e) < 0.5) integral = std::clamp(integral + e * dt, -2.0, 2.0);
    const double z_force = kp * e + ki * integral - kd * v_ned(2) + feedforward;
    Vector6<double> desired = Vector6<double>::Zero();
    desired.head<3>() = x.attitude.conjugate() * Vector3<double>(0, 0, z_force);  // NED → body
    alloc.distribute(desired, f);
    for (Eigen::Index i = 0; i < f.size(); ++i)
      pwm(i) = kv::pwm_from_command(kv::t200_command(f(i)), rov.pwm);
    const Vector6<double> tau = thrust_from_pwm(alloc, rov.pwm, pwm, actual);
    if (settled_at < 0 && std::abs(e) < 0.05 && std::abs(v_ned(2)) < 0.02) settled_at = t;
    if (k % static_cast<int>(std::lround(2.0 / dt)) == 0) {
      const Vector3<double> euler = kelp::euler_from_quaternion(x.attitude);
      std::printf("%6.1f %9.3f %9.3f %9.3f %10.0f %11.2f\n", t, x.position(2), v_ned(2),
                  euler(1) * 180 / kelp::pi, pwm(4), (x.attitude * tau.head<3>())(2));
    }
    if (k < steps) kv::step_rk4(model, ws, x, {tau, Vector6<double>::Zero()}, dt);
  }
  std::printf("-> depth %.3f m at t = %.0f s; within 5 cm and at rest from t = %.1f s\n\n",
              x.position(2), t_end, settled_at);
}

void sprint() {
  const auto boat = kv::blueboat<double>();
  const kv::VehicleModel<double> model(boat.parameters);
  const kv::ThrusterAllocation<double> alloc(boat.thruster_positions, boat.thruster_directions);
  kv::VehicleWorkspace<double> ws;
  kv::VehicleState<double> x;
  Eigen::VectorXd pwm(2), forces(2);
  pwm.setConstant(boat.pwm.max_us);  // full throttle on both (ThrottleLeft, ThrottleRight)
  const Vector6<double> tau = thrust_from_pwm(alloc, boat.pwm, pwm, forces);
  const double dt = 0.01, t_end = 20.0;
  double t95 = -1, u_final = 0;
  std::printf("BlueBoat: full throttle from rest (2 x T200 = %.1f N)\n", tau(0));
  std::printf("%6s %9s %9s %10s %10s\n", "t [s]", "u [m/s]", "x [m]", "pitch[deg]", "heave[cm]");
  const int steps = static_cast<int>(std::lround(t_end / dt));
  // First pass finds the top speed, the second prints the run and the 95 % rise time.
  for (int pass = 0; pass < 2; ++pass) {
    x = kv::VehicleState<double>();
    for (int k = 0; k <= steps; ++k) {
      const double t = k * dt;
      if (pass == 1 && t95 < 0 && x.nu(0) >= 0.95 * u_final) t95 = t;
      if (pass == 1 && k % static_cast<int>(std::lround(2.0 / dt)) == 0) {
        const Vector3<double> euler = kelp::euler_from_quaternion(x.attitude);
        std::printf("%6.1f %9.3f %9.2f %10.3f %10.2f\n", t, x.nu(0), x.position(0),
                    euler(1) * 180 / kelp::pi, x.position(2) * 100);
      }
      if (k < steps) kv::step_rk4(model, ws, x, {tau, Vector6<double>::Zero()}, dt);
    }
    u_final = x.nu(0);
  }
  std::printf("-> top speed %.2f m/s (Blue Robotics quote ~3 m/s); 95 %% of it after %.1f s\n",
              u_final, t95);
}

}  // namespace

int main() {
  const auto start = std::chrono::steady_clock::now();
  dive();
  sprint();
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::printf("\n(simulated 30 s + 2 x 20 s in %.1f ms of CPU time)\n", ms);
  return 0;
}
