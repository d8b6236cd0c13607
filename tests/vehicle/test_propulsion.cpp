// Propulsion: the thrusters' first-order lag against von Benzon et al. 2022's T200 transfer
// function and its exact exponential, the battery's energy balance, voltage sag under load and
// with charge, thrust following the voltage, bad parameters, no heap in a step.
#include <Eigen/Core>
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "kelp/core/error.hpp"
#include "kelp/vehicle/battery.hpp"
#include "kelp/vehicle/presets.hpp"
#include "kelp/vehicle/propulsion.hpp"

using namespace kelp;
using namespace kelp::vehicle;

namespace {

// One thruster along +x at the CO, on a battery without resistance and of a capacity that a test
// does not dent (constant voltage).
PropulsionParametersd single_thruster(double time_constant) {
  PropulsionParametersd p;
  p.positions = Eigen::Matrix<double, 3, 1>::Zero();
  p.directions = Eigen::Matrix<double, 3, 1>(1, 0, 0);
  p.time_constant = time_constant;
  p.battery.internal_resistance = 0.0;
  p.battery.capacity_ah = 1e12;
  return p;
}

// Unit-step response of von Benzon et al. 2022 (J. Mar. Sci. Eng. 10(12):1898), T200 model
// F/F_ref = (6136 s + 108700)/(s^3 + 89 s^2 + 9258 s + 108700), controllable canonical form,
// RK4 at 10 us; returns y(t) at every multiple of `every` steps.
std::vector<double> von_benzon_step(double t_end, double h) {
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  const auto f = [](const Eigen::Vector3d& s) {
    return Eigen::Vector3d(s(1), s(2), 1.0 - 108700.0 * s(0) - 9258.0 * s(1) - 89.0 * s(2));
  };
  std::vector<double> y;
  const long n = std::lround(t_end / h);
  for (long k = 0; k <= n; ++k) {
    y.push_back(108700.0 * x(0) + 6136.0 * x(1));
    const Eigen::Vector3d k1 = f(x), k2 = f(x + 0.5 * h * k1), k3 = f(x + 0.5 * h * k2),
                          k4 = f(x + h * k3);
    x += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }
  return y;
}

}  // namespace

TEST_CASE("Thruster lag: step response against von Benzon et al. 2022's T200 model",
          "[propulsion]") {
  const double h_ref = 1e-5;
  const std::vector<double> ref = von_benzon_step(0.5, h_ref);
  const auto ref_at = [&](double t) { return ref[std::size_t(std::lround(t / h_ref))]; };
  // kelp's lag, stepped at 1 ms under a full forward command, normalised by its static thrust.
  const PropulsionModeld m(single_thruster(t200_time_constant));
  PropulsionStated s = initial_state(m);
  const double v = open_circuit_voltage(m.parameters().battery, 1.0);
  const double f_ref = t200_thrust(1.0, v);
  Eigen::Matrix<double, 1, 1> u(1.0);
  const double dt = 1e-3;
  std::vector<double> lag{0.0};
  for (int k = 0; k < 500; ++k) {
    advance(m, s, u, dt);
    lag.push_back(s.thrust(0) / f_ref);
  }
  // The 63 % rise times agree (the time constant was fitted to it): within 0.5 ms (crossing
  // times interpolated linearly between samples).
  const auto rise = [](const std::vector<double>& y, double h) {
    const double level = 1.0 - std::exp(-1.0);
    std::size_t i = 1;
    while (y[i] < level) ++i;
    return h * (double(i - 1) + (level - y[i - 1]) / (y[i] - y[i - 1]));
  };
  const double t63_ref = rise(ref, h_ref);
  CHECK(t63_ref == Approx(0.0200).margin(0.0005));
  CHECK(rise(lag, dt) == Approx(t63_ref).margin(0.0005));
  // At 50, 100 and 200 ms the first order is within 0.08 of the step of the third-order model
  // (which overshoots by ~4 % at 40-60 ms and dips to 0.92 at 100 ms).
  for (double t : {0.05, 0.1, 0.2}) {
    INFO("t = " << t << " s: von Benzon " << ref_at(t) << ", kelp " << lag[std::size_t(t / dt)]);
    CHECK(lag[std::size_t(std::lround(t / dt))] == Approx(ref_at(t)).margin(0.08));
  }
  // And a lag of 60 ms (a forum figure) would not be: it is at 0.57 at 50 ms, the model at 0.96.
  const PropulsionModeld slow(single_thruster(0.06));
  PropulsionStated ss = initial_state(slow);
  for (int k = 0; k < 50; ++k) advance(slow, ss, u, dt);
  CHECK(std::abs(ss.thrust(0) / f_ref - ref_at(0.05)) > 0.2);
}

TEST_CASE("Thruster lag: exact exponential over a step, its mean is the impulse", "[propulsion]") {
  const double tc = 0.05, dt = 0.01;
  const PropulsionModeld m(single_thruster(tc));
  PropulsionStated s = initial_state(m);
  const double v = open_circuit_voltage(m.parameters().battery, 1.0);
  const double target = t200_thrust(0.7, v);
  Eigen::Matrix<double, 1, 1> u(0.7);
  double impulse = 0.0;
  for (int k = 1; k <= 30; ++k) {
    const PropulsionStep<double> r = advance(m, s, u, dt);
    impulse += r.wrench(0) * dt;
    const double t = k * dt;
    CHECK(s.thrust(0) == Approx(target * (1.0 - std::exp(-t / tc))).epsilon(1e-12));
    // ∫₀ᵗ F*(1 − e^{−τ/T}) dτ = F* (t − T (1 − e^{−t/T}))
    CHECK(impulse == Approx(target * (t - tc * (1.0 - std::exp(-t / tc)))).epsilon(1e-12));
  }
  // Time constant 0: the thrust follows the command at once.
  const PropulsionModeld instant(single_thruster(0.0));
  PropulsionStated si = initial_state(instant);
  const PropulsionStep<double> r = advance(instant, si, u, dt);
  CHECK(si.thrust(0) == target);
  CHECK(r.wrench(0) == target);
  // Reversed mounting: a positive command gives thrust along d from the propeller's reverse side.
  PropulsionParametersd rp = single_thruster(0.0);
  rp.facing = ThrusterVector<int>::Constant(1, -1);
  const PropulsionModeld reversed(rp);
  PropulsionStated sr = initial_state(reversed);
  advance(reversed, sr, u, dt);
  CHECK(sr.thrust(0) == Approx(-t200_thrust(-0.7, v)));
  CHECK(sr.thrust(0) > 0.0);
}

TEST_CASE("Battery: energy balance over a constant-current discharge", "[battery]") {
  const BatteryParameters p = battery_presets::bluerov2_battery();
  BatteryState s;
  const double current = 15.6, dt = 0.5;  // 1 C for 50 min: SoC 1 → 1/6
  double v_sum = 0.0, e_check = 0.0;
  long n = 0;
  for (; n < 6000; ++n) {
    const double v = solve_terminal_voltage(p, s, [&](double) { return current; });
    CHECK(v == Approx(terminal_voltage(p, s, current)).margin(1e-8));
    e_check += v * current * dt;
    v_sum += v;
    drain(s, current, v, dt);
  }
  CHECK(s.charge_drawn == Approx(current * dt * n).epsilon(1e-12));
  CHECK(state_of_charge(p, s) == Approx(1.0 - 50.0 / 60.0).epsilon(1e-9));
  // The counter is ∫ V I dt of the steps.
  CHECK(s.energy_drawn == Approx(e_check).epsilon(1e-12));
  // ∫ V I dt = charge drawn × mean terminal voltage (I constant), within 1 %.
  CHECK(s.energy_drawn == Approx(s.charge_drawn * v_sum / double(n)).epsilon(0.01));
  // And the exact ∫ (OCV(SoC(t)) − R I) I dt by a 100x finer quadrature, within 1 %.
  double exact = 0.0;
  const double h = dt / 100.0;
  for (long k = 0; k < 100 * n; ++k) {
    const double soc = 1.0 - current * (k + 0.5) * h / (3600.0 * p.capacity_ah);
    exact += (open_circuit_voltage(p, soc) - p.internal_resistance * current) * current * h;
  }
  CHECK(s.energy_drawn == Approx(exact).epsilon(0.01));
  // Order of magnitude: 5/6 of a 15.6 Ah pack at ~14.9 V mean ≈ 190 Wh.
  CHECK(s.energy_drawn / 3600.0 == Approx(190).epsilon(0.05));
}

TEST_CASE("Battery: the voltage sags with current and falls with the charge drawn", "[battery]") {
  const BatteryParameters p = battery_presets::bluerov2_battery();
  BatteryState full;
  CHECK(open_circuit_voltage(p, 1.0) == Approx(16.70));  // 4 × 4.175 V
  CHECK(open_circuit_voltage(p, 0.0) == Approx(10.14));
  CHECK(terminal_voltage(p, full, 0.0) - terminal_voltage(p, full, 50.0) ==
        Approx(50.0 * p.internal_resistance));
  BatteryState half = full;
  half.charge_drawn = 0.5 * 3600.0 * p.capacity_ah;
  CHECK(state_of_charge(p, half) == Approx(0.5));
  CHECK(open_circuit_voltage(p, state_of_charge(p, half)) == Approx(4 * 3.753));
  CHECK(terminal_voltage(p, half, 10.0) < terminal_voltage(p, full, 10.0) - 1.5);
  // The BlueBoat's two packs in parallel: half the sag for the same current, twice the charge.
  const BatteryParameters b = battery_presets::blueboat_battery();
  CHECK(b.capacity_ah == Approx(31.2));
  CHECK(terminal_voltage(b, full, 0.0) - terminal_voltage(b, full, 50.0) ==
        Approx(25.0 * p.internal_resistance));
}

TEST_CASE("Propulsion: the voltage solves V = OCV - R I(V); thrust falls as the pack drains",
          "[propulsion]") {
  PropulsionParametersd p;
  const auto rov = bluerov2_heavy<double>();
  p.positions = rov.thruster_positions;
  p.directions = rov.thruster_directions;
  p.time_constant = 0.0;
  p.battery = battery_presets::bluerov2_battery();
  const PropulsionModeld m(p);
  PropulsionStated s = initial_state(m);
  ThrusterVector<double> u = ThrusterVector<double>::Constant(8, 1.0);
  const PropulsionStep<double> r0 = advance(m, s, u, 0.01);
  double i_sum = 0.0;
  for (int i = 0; i < 8; ++i) i_sum += t200_current(1.0, r0.voltage);
  CHECK(r0.current == Approx(i_sum).epsilon(1e-12));
  CHECK(r0.voltage ==
        Approx(open_circuit_voltage(p.battery, 1.0) - p.battery.internal_resistance * i_sum)
            .margin(1e-6));
  CHECK(r0.voltage < open_circuit_voltage(p.battery, 1.0) - 1.0);  // sags by > 1 V at full load
  CHECK(s.thrust(0) == Approx(t200_thrust(1.0, r0.voltage)));
  CHECK(s.current(0) == Approx(t200_current(1.0, r0.voltage)));
  const double thrust_full = s.thrust(0);
  // 80 % of the charge drawn: lower voltage, lower thrust and lower current.
  s.battery.charge_drawn = 0.8 * 3600.0 * p.battery.capacity_ah;
  const PropulsionStep<double> r1 = advance(m, s, u, 0.01);
  CHECK(r1.voltage < r0.voltage - 1.0);
  CHECK(s.thrust(0) < 0.9 * thrust_full);
  CHECK(r1.current < r0.current);
  // Idle thrusters draw no current: the terminal voltage is the OCV.
  PropulsionStated idle = initial_state(m);
  const PropulsionStep<double> r2 = advance(m, idle, ThrusterVector<double>(), 0.01);
  CHECK(r2.current == 0.0);
  CHECK(r2.voltage == Approx(open_circuit_voltage(p.battery, 1.0)).epsilon(1e-9));
  CHECK(r2.wrench.isZero());
}

TEST_CASE("Propulsion: no heap allocation in a step", "[propulsion]") {
  PropulsionParametersd p;
  const auto rov = bluerov2_heavy<double>();
  p.positions = rov.thruster_positions;
  p.directions = rov.thruster_directions;
  const PropulsionModeld m(p);
  PropulsionStated s = initial_state(m);
  ThrusterVector<double> u = ThrusterVector<double>::LinSpaced(8, -1.0, 1.0);
  Eigen::internal::set_is_malloc_allowed(false);
  for (int k = 0; k < 10; ++k) advance(m, s, u, 0.01);
  PropulsionStated copy = s;
  Eigen::internal::set_is_malloc_allowed(true);
  CHECK(copy.thrust == s.thrust);
}

TEST_CASE("Propulsion and battery: bad parameters and inputs throw", "[propulsion][battery]") {
  BatteryParameters b;
  b.capacity_ah = 0.0;
  CHECK_THROWS_AS(validate(b), kelp::invalid_argument);
  b = BatteryParameters{};
  b.initial_soc = 1.5;
  CHECK_THROWS_AS(validate(b), kelp::invalid_argument);
  b = BatteryParameters{};
  b.internal_resistance = -0.1;
  CHECK_THROWS_AS(validate(b), kelp::invalid_argument);
  b = BatteryParameters{};
  b.ocv.soc[3] = b.ocv.soc[2];
  CHECK_THROWS_AS(validate(b), kelp::invalid_argument);
  b = BatteryParameters{};
  b.cells_in_series = 0;
  CHECK_THROWS_AS(validate(b), kelp::invalid_argument);

  PropulsionParametersd p = single_thruster(0.02);
  p.time_constant = -1.0;
  CHECK_THROWS_AS(PropulsionModeld(p), kelp::invalid_argument);
  p = single_thruster(0.02);
  p.facing = ThrusterVector<int>::Constant(1, 2);
  CHECK_THROWS_AS(PropulsionModeld(p), kelp::invalid_argument);
  p = single_thruster(std::nan(""));
  CHECK_THROWS_AS(PropulsionModeld(p), kelp::invalid_argument);
  p = single_thruster(0.02);
  p.positions = Eigen::Matrix<double, 3, 9>::Zero();
  p.directions = Eigen::Matrix<double, 3, 9>::Ones();
  CHECK_THROWS_AS(PropulsionModeld(p), kelp::invalid_argument);

  const PropulsionModeld m(single_thruster(0.02));
  PropulsionStated s = initial_state(m);
  const PropulsionStated before = s;
  CHECK_THROWS_AS(advance(m, s, Eigen::Vector2d(0.1, 0.2), 0.01), kelp::invalid_argument);
  CHECK_THROWS_AS(advance(m, s, Eigen::Matrix<double, 1, 1>(std::nan("")), 0.01),
                  kelp::invalid_argument);
  CHECK_THROWS_AS(advance(m, s, Eigen::Matrix<double, 1, 1>(0.5), 0.0), kelp::invalid_argument);
  PropulsionStated wrong;
  CHECK_THROWS_AS(advance(m, wrong, Eigen::Matrix<double, 1, 1>(0.5), 0.01),
                  kelp::invalid_argument);
  CHECK(s.thrust == before.thrust);
  CHECK(s.battery.charge_drawn == before.battery.charge_drawn);
}

TEST_CASE("Propulsion: float instantiation", "[propulsion]") {
  PropulsionParametersf p;
  p.positions = Eigen::Matrix<float, 3, 1>::Zero();
  p.directions = Eigen::Matrix<float, 3, 1>(1, 0, 0);
  const PropulsionModelf m(p);
  PropulsionStatef s = initial_state(m);
  for (int k = 0; k < 100; ++k) advance(m, s, Eigen::Matrix<float, 1, 1>(0.5f), 0.01);
  CHECK(s.thrust(0) == Approx(t200_thrust(0.5f, float(s.battery.voltage))).epsilon(1e-4));
}

// Every public propulsion class template for both floating-point scalars.
template struct kelp::vehicle::PropulsionParameters<double>;
template struct kelp::vehicle::PropulsionParameters<float>;
template class kelp::vehicle::PropulsionModel<double>;
template class kelp::vehicle::PropulsionModel<float>;
template struct kelp::vehicle::PropulsionState<double>;
template struct kelp::vehicle::PropulsionState<float>;
template struct kelp::vehicle::PropulsionStep<double>;
template struct kelp::vehicle::PropulsionStep<float>;
