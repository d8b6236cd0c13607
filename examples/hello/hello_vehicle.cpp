// The "hello vehicle" of README.md and docs/getting-started.md: a BlueROV2 Heavy driven forward
// by its thrusters in a current.
#include <cstdio>

#include "kelp/vehicle/integrators.hpp"
#include "kelp/vehicle/presets.hpp"

int main() {
  namespace kv = kelp::vehicle;
  const auto rov = kv::bluerov2_heavy<double>();  // parameters + 8 thrusters
  const kv::VehicleModeld model(rov.parameters);  // M and its LDLT, built once
  const kv::ThrusterAllocationd thrusters(rov.thruster_positions, rov.thruster_directions);
  kv::VehicleWorkspaced ws;               // per-simulation buffers
  kv::VehicleStated x;                    // NED pose, body velocity
  x.position.z() = 10.0;                  // start 10 m deep
  Eigen::VectorXd u(8);                   // normalised thruster commands
  u << -0.5, -0.5, 0.5, 0.5, 0, 0, 0, 0;  // ArduSub "forward" pattern
  const Eigen::VectorXd f = u.unaryExpr([](double c) { return kv::t200_thrust(c); });
  const kelp::Vector6<double> tau = thrusters.wrench(f);  // body wrench [N, N m]
  const kelp::Vector3<double> current(0.2, 0.0, 0.0);     // NED current [m/s]
  for (int k = 0; k < 10000; ++k)                         // 10 s at 1 ms
    kv::step_rk4(model, ws, x, {tau, kelp::Vector6<double>::Zero()}, 1e-3, current);
  std::printf("surge %.3f m/s, position N %.2f m, depth %.3f m\n", x.nu(0), x.position(0),
              x.position(2));
  return x.nu(0) > 0.0 ? 0 : 1;
}
