// Every public vehicle class template instantiated with ceres::Jet<double, 6>, and the Jet
// derivatives of the forward dynamics checked against central finite differences.
#include <ceres/jet.h>

#include <catch2/catch.hpp>
#include <cmath>

#include "kelp/vehicle/damping.hpp"
#include "kelp/vehicle/integrators.hpp"
#include "kelp/vehicle/kinematics.hpp"
#include "kelp/vehicle/model.hpp"
#include "kelp/vehicle/presets.hpp"
#include "kelp/vehicle/propulsion.hpp"
#include "kelp/vehicle/state.hpp"
#include "kelp/vehicle/thrusters.hpp"

using Jet = ceres::Jet<double, 6>;

namespace kelp::vehicle {
template struct VehicleState<Jet>;
template struct DampingParameters<Jet>;
template struct VehicleParameters<Jet>;
template class VehicleModel<Jet>;
template struct VehicleWorkspace<Jet>;
template struct PoseRate<Jet>;
template struct StateDerivative<Jet>;
template class ThrusterAllocation<Jet>;
template class ThrusterChain<Jet>;
template struct PwmMapping<Jet>;
template struct VehiclePreset<Jet>;
template struct PropulsionParameters<Jet>;
template class PropulsionModel<Jet>;
template struct PropulsionState<Jet>;
template struct PropulsionStep<Jet>;
}  // namespace kelp::vehicle

namespace kv = kelp::vehicle;
using kelp::Vector3;
using kelp::Vector6;

namespace {

// ν̇(ν) for a fixed pose, thrust and current; the point is away from ν_i = 0 where |ν| has a kink.
template <typename S>
Vector6<S> accel(const kv::VehicleModel<S>& model, const Vector6<S>& nu) {
  kv::VehicleWorkspace<S> ws;
  kv::VehicleState<S> x;
  x.position = Vector3<S>(S(1), S(2), S(5));
  x.attitude = kelp::quaternion_from_euler(S(0.2), S(-0.3), S(0.8));
  x.nu = nu;
  Vector6<S> tau;
  tau << S(10), S(-4), S(6), S(0.3), S(-0.2), S(0.5);
  const Vector3<S> current(S(0.4), S(-0.2), S(0.05));
  return kv::forward_dynamics(model, ws, x, tau, Vector6<S>::Zero(), current);
}

}  // namespace

TEST_CASE("Jet derivatives of the forward dynamics match central differences", "[vehicle][jet]") {
  for (const auto& preset : {kv::bluerov2_heavy<double>(), kv::blueboat<double>()}) {
    auto p = preset.parameters;
    p.r_g << 0.01, -0.005, 0.02;  // exercise the r_g couplings of M_RB and C_RB
    p.added_mass(0, 4) = p.added_mass(4, 0) = 0.3;
    const kv::VehicleModel<double> model_d(p);
    const kv::VehicleModel<Jet> model_j(p.cast<Jet>());
    Vector6<double> nu0;
    nu0 << 0.6, -0.3, 0.25, 0.2, -0.15, 0.35;
    Vector6<Jet> nu_j;
    for (int i = 0; i < 6; ++i) nu_j(i) = Jet(nu0(i), i);
    const Vector6<Jet> a_j = accel(model_j, nu_j);
    const double h = 1e-6;
    for (int i = 0; i < 6; ++i) {
      Vector6<double> np = nu0, nm = nu0;
      np(i) += h;
      nm(i) -= h;
      const Vector6<double> fd = (accel(model_d, np) - accel(model_d, nm)) / (2 * h);
      for (int r = 0; r < 6; ++r) {
        INFO(preset.name << " d nu_dot(" << r << ") / d nu(" << i << ")");
        CHECK(a_j(r).v(i) == Approx(fd(r)).epsilon(1e-6).margin(1e-7));
      }
      // The value part is the double computation.
      CHECK(a_j(i).a == Approx(accel(model_d, nu0)(i)).epsilon(1e-14));
    }
  }
}

TEST_CASE("Jet: an RK4 step, the T200 inverse and the allocation run with derivatives",
          "[vehicle][jet]") {
  const auto preset = kv::bluerov2_heavy<Jet>();
  const kv::VehicleModel<Jet> model(preset.parameters);
  const kv::ThrusterAllocation<Jet> alloc(preset.thruster_positions, preset.thruster_directions);
  CHECK(alloc.rank() == 6);
  kv::VehicleWorkspace<Jet> ws;
  kv::VehicleState<Jet> x;
  x.nu(0) = Jet(0.3, 0);  // derivative w.r.t. the initial surge speed
  kv::step_rk4(model, ws, x, {Vector6<Jet>::Zero(), Vector6<Jet>::Zero()}, Jet(0.01));
  // Surge only decays: d u(dt) / d u(0) is a little below 1.
  CHECK(x.nu(0).v(0) < 1.0);
  CHECK(x.nu(0).v(0) > 0.9);
  // du/dF of the T200 inverse is 1 / F'(u) (implicit-function theorem).
  const Jet u = kv::t200_command(Jet(12.0, 1));
  CHECK(u.v(1) == Approx(1.0 / kv::t200_thrust_slope(u.a)).epsilon(1e-9));
  CHECK(kv::t200_thrust(u).a == Approx(12.0).epsilon(1e-12));
}

TEST_CASE(
    "Jet: T200 thrust and current derivatives in the command and the voltage, and of "
    "the inverse",
    "[vehicle][jet][t200]") {
  for (double v : {8.0, 12.0, 14.8, 16.0, 19.0}) {
    for (double u0 : {-0.9, -0.4, -0.1, 0.1, 0.45, 0.95}) {
      INFO(u0 << " at " << v << " V");
      const Jet f = kv::t200_thrust(Jet(u0, 0), Jet(v, 1));
      const double h = 1e-6;
      CHECK(f.a == Approx(kv::t200_thrust(u0, v)).epsilon(1e-14));
      CHECK(f.v(0) == Approx(kv::t200_thrust_slope(u0, v)).epsilon(1e-12));
      const double dv = (kv::t200_thrust(u0, v + h) - kv::t200_thrust(u0, v - h)) / (2 * h);
      CHECK(f.v(1) == Approx(dv).epsilon(1e-6));
      const Jet i = kv::t200_current(Jet(u0, 0), Jet(v, 1));
      const double di = (kv::t200_current(u0 + h, v) - kv::t200_current(u0 - h, v)) / (2 * h);
      CHECK(i.v(0) == Approx(di).epsilon(1e-6));
      // The inverse: ∂u/∂F = 1/F_u and ∂u/∂V = −F_V/F_u at the same point.
      const double force = f.a;
      const Jet c = kv::t200_command(Jet(force, 0), Jet(v, 1));
      CHECK(c.a == Approx(u0).epsilon(1e-12));
      CHECK(c.v(0) == Approx(1.0 / f.v(0)).epsilon(1e-9));
      CHECK(c.v(1) == Approx(-f.v(1) / f.v(0)).epsilon(1e-9));
    }
  }
}

TEST_CASE("Jet: a propulsion step on a thruster's curve and a T200, derivatives in the commands",
          "[vehicle][jet][propulsion]") {
  // Thruster 0 on a curve (slope 34/0.6 N between u = 0.4 and 1), thruster 1 a T200; no lag, a
  // pack without resistance (the voltage does not depend on the commands).
  kv::PropulsionParameters<Jet> p;
  p.positions = kelp::Matrix3X<Jet>::Zero(3, 2);
  p.directions = kelp::Matrix3X<Jet>::Zero(3, 2);
  p.directions(0, 0) = p.directions(0, 1) = Jet(1.0);
  p.time_constant = 0.0;
  p.battery.internal_resistance = 0.0;
  kv::ThrustCurve& c = p.curves[0];
  c.command = kv::CurveVector::LinSpaced(3, -1.0, 1.0);
  c.thrust.resize(3);
  c.thrust << -30.0, 0.0, 40.0;
  const kv::PropulsionModel<Jet> m(p);
  kv::PropulsionState<Jet> s = kv::initial_state(m);
  Eigen::Matrix<Jet, 2, 1> u(Jet(0.7, 0), Jet(0.6, 1));
  const kv::PropulsionStep<Jet> r = kv::advance(m, s, u, 0.01);
  CHECK(s.thrust(0).a == Approx(28.0).epsilon(1e-14));
  CHECK(s.thrust(0).v(0) == Approx(40.0).epsilon(1e-14));  // dF/du of the segment
  CHECK(s.thrust(0).v(1) == 0.0);
  CHECK(s.thrust(1).v(1) == Approx(kv::t200_thrust_slope(0.6, r.voltage)).epsilon(1e-12));
  CHECK(r.wrench(0).v(0) == Approx(40.0).epsilon(1e-14));
  CHECK(kv::curve_thrust(c, Jet(-0.5, 2)).v(2) == Approx(30.0).epsilon(1e-14));
}
