/// \file
/// \brief Blue Robotics T200 thruster from its published bollard data: thrust and supply current
/// as functions of the normalised command and the supply voltage, forward/reverse asymmetric,
/// with the ESC's dead band, and the inverse (command for a thrust).
///
/// Source: Blue Robotics, "T200 Public Performance Data 10-20V (September 2019)", spreadsheet
/// https://cad.bluerobotics.com/T200-Public-Performance-Data-10-20V-September-2019.xlsx (linked
/// from https://bluerobotics.com/store/thrusters/t100-t200-thrusters/t200-thruster-r2-rp/): one
/// T200 with a Basic ESC R3 (BLHeli_S 16.6, stock settings) on a bench supply, bollard (zero inlet
/// velocity), PWM 1100–1900 µs in 4 µs steps at 10, 12, 14, 16, 18 and 20 V; thrust in kgf,
/// supply current in A; rotation below 300 rpm is recorded as zero (the dead band). The sheets
/// at 10, 12, 16, 18 and 20 V (201 points each) and the 14 V full-throttle thrusts (4.53 kgf
/// forward, 3.52 kgf reverse; the 14 V sheet itself was not reachable) are the data fitted here;
/// they are stored with the tests (tests/vehicle/data/t200_performance_2019.csv).
///
/// Model. With the command u ∈ [−1, 1] (u = (pwm − 1500 µs)/400 µs for the 1100–1900 µs ESC
/// range), each direction (forward u > 0, reverse u < 0) has a dead band u₀ and the normalised
/// excursion s = (|u| − u₀)/(1 − u₀) ∈ [0, 1]. Thrust and current are polynomials
/// \f$ F = \sum_{i=1}^{3} s^i \sum_{j=0}^{2} c_{ij} v^j \f$, v = V/16 V, fitted by least squares
/// in relative error (absolute error over 0.3 kgf for smaller thrusts, over 1 A for smaller
/// currents), u₀ by a scan; they vanish at the edge of the dead band and rise monotonically in s
/// on 10–20 V (checked by the tests). Fit error over the data: thrust max 6.8 % (forward) and 6.5 %
/// (reverse), RMS 2.6 % / 2.4 %; thrusts below 0.3 kgf are judged by their absolute error against
/// 0.3 kgf. Forward thrust: the thruster is pushed towards its nose cone (water enters at the
/// front and leaves at the back, through the nozzle); reverse is ~23 % weaker at full command
/// (4.07 vs 5.25 kgf at 16 V).
///
/// Voltage: 10–20 V is the data. Above 20 V (beyond the T200's rated 7–20 V) the functions
/// throw; below 10 V thrust and current are the 10 V values scaled by (V/10 V)², the propeller
/// affinity law with rotation speed proportional to the voltage (thrust ∝ n², shaft power ∝ n³ so
/// supply current ∝ n²); both reach 0 at 0 V. That branch is an extrapolation (the Basic ESC
/// itself stops below about 7 V).
#pragma once

#include <cmath>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"

namespace kelp::vehicle {

/// \brief Nominal supply voltage [V] of the chain and the controllers when none is given: 16 V,
/// the voltage at which Blue Robotics states the T200's headline thrust (5.25 / 4.1 kgf). A 4S
/// battery is 14.8 V nominal and 16.8 V full; pass its voltage where it is known.
inline constexpr double t200_nominal_voltage = 16.0;
/// \brief Lowest voltage of the published data [V]; below it the curves are scaled (see file).
inline constexpr double t200_data_min_voltage = 10.0;
/// \brief Highest supported voltage [V] (the data's and the T200's rated maximum).
inline constexpr double t200_max_voltage = 20.0;
/// \brief One kilogram-force [N] (the data's thrust unit; standard gravity).
inline constexpr double t200_kgf = 9.80665;

namespace detail {

/// One direction of the fit: dead band u₀ and coefficients c_ij of s^(i+1) v^j (i, j = 0..2) for
/// thrust [kgf] and supply current [A].
struct T200Branch {
  double dead_band;
  double thrust[9];
  double current[9];
};

/// Forward (u > 0).
inline constexpr T200Branch t200_forward{
    0.0625,
    {-1.31427897, 3.23012931, 0.0690568312, -11.645331, 38.7289442, -22.6286992, 12.5632062,
     -37.3164154, 23.6561461},
    {-0.828369588, 0.0105479117, 1.03964908, -25.3877237, 87.319434, -46.3816623, 26.7061162,
     -68.4572853, 50.6543902}};
/// Reverse (u < 0), magnitudes.
inline constexpr T200Branch t200_reverse{
    0.06,
    {-1.44913116, 3.59945057, -0.534902509, -5.49670305, 20.950092, -11.9255976, 5.85348947,
     -18.7943499, 11.94221},
    {-0.777219673, -0.115347289, 1.10127912, -18.2798708, 67.9989624, -35.2516126, 18.3024037,
     -46.3910014, 38.5058134}};

/// Checks the voltage: finite, ≥ 0, ≤ t200_max_voltage.
template <typename Scalar>
void t200_check_voltage(const Scalar& voltage) {
  check_finite(voltage, "T200 supply voltage [V]");
  check_at_least(voltage, 0.0, "T200 supply voltage [V]");
  check_at_most(voltage, t200_max_voltage, "T200 supply voltage [V]");
}

/// The polynomial Σ s^(i+1) Σ c_ij v^j and, if asked, its s-derivative, with v from the voltage
/// (at 10 V below it) and the (V/10)² scale below 10 V applied to both.
template <typename Scalar>
Scalar t200_poly(const double* c, const Scalar& s, const Scalar& voltage, Scalar* ds) {
  const bool low = value_of(voltage) < t200_data_min_voltage;
  const Scalar v = low ? Scalar(t200_data_min_voltage / 16.0) : voltage / Scalar(16.0);
  Scalar a[3];
  for (int i = 0; i < 3; ++i)
    a[i] = Scalar(c[3 * i]) + v * (Scalar(c[3 * i + 1]) + v * Scalar(c[3 * i + 2]));
  Scalar value = s * (a[0] + s * (a[1] + s * a[2]));
  Scalar slope = a[0] + s * (Scalar(2) * a[1] + Scalar(3) * s * a[2]);
  if (low) {
    const Scalar r = voltage / Scalar(t200_data_min_voltage);
    value = value * r * r;
    slope = slope * r * r;
  }
  if (ds != nullptr) *ds = slope;
  return value;
}

/// Clamped |u| and the branch of the sign of u.
template <typename Scalar>
const T200Branch& t200_branch(const Scalar& command, Scalar& magnitude, double& sign) {
  check_finite(command, "T200 command u");
  const double u = value_of(command);
  sign = u < 0.0 ? -1.0 : 1.0;
  magnitude = u < 0.0 ? Scalar(-command) : command;
  if (value_of(magnitude) > 1.0) magnitude = Scalar(1);
  return u < 0.0 ? t200_reverse : t200_forward;
}

}  // namespace detail

/// \brief Static (bollard) thrust of one T200 [N] along its forward axis: positive for u > 0
/// (pushes the thruster towards its nose cone), negative for u < 0 (reverse, weaker), 0 in the
/// ESC's dead band (|u| ≤ 0.0625 forward, 0.06 reverse).
/// \tparam Scalar double, float or ceres::Jet.
/// \param[in] command normalised command u (clamped to [−1, 1]; ±1 = 1900 / 1100 µs).
/// \param[in] voltage supply voltage at the ESC [V], in [0, 20] (see the file's notes).
/// \throws kelp::invalid_argument when a value is not finite or the voltage is outside [0, 20] V.
template <typename Scalar>
Scalar t200_thrust(const Scalar& command, const Scalar& voltage) {
  detail::t200_check_voltage(voltage);
  Scalar m;
  double sign;
  const detail::T200Branch& b = detail::t200_branch(command, m, sign);
  if (value_of(m) <= b.dead_band) return Scalar(0);
  const Scalar s = (m - Scalar(b.dead_band)) / Scalar(1.0 - b.dead_band);
  return Scalar(sign * t200_kgf) * detail::t200_poly<Scalar>(b.thrust, s, voltage, nullptr);
}

/// \brief dF/du of t200_thrust() [N] (≥ 0; 0 in the dead band and for |u| > 1).
/// \throws kelp::invalid_argument as t200_thrust().
template <typename Scalar>
Scalar t200_thrust_slope(const Scalar& command, const Scalar& voltage) {
  detail::t200_check_voltage(voltage);
  Scalar m;
  double sign;
  const detail::T200Branch& b = detail::t200_branch(command, m, sign);
  const double u = value_of(command);
  if (value_of(m) <= b.dead_band || u > 1.0 || u < -1.0) return Scalar(0);
  const Scalar s = (m - Scalar(b.dead_band)) / Scalar(1.0 - b.dead_band);
  Scalar ds;
  detail::t200_poly<Scalar>(b.thrust, s, voltage, &ds);
  return Scalar(t200_kgf / (1.0 - b.dead_band)) * ds;
}

/// \brief Supply current drawn by one T200 and its ESC [A] (≥ 0; 0 in the dead band).
/// Fit error over the data: ≤ 10 % of the reading, or ≤ 0.1 A below 1 A.
/// \param[in] command u (clamped to [−1, 1]). \param[in] voltage [V], in [0, 20].
/// \throws kelp::invalid_argument as t200_thrust().
template <typename Scalar>
Scalar t200_current(const Scalar& command, const Scalar& voltage) {
  detail::t200_check_voltage(voltage);
  Scalar m;
  double sign;
  const detail::T200Branch& b = detail::t200_branch(command, m, sign);
  if (value_of(m) <= b.dead_band) return Scalar(0);
  const Scalar s = (m - Scalar(b.dead_band)) / Scalar(1.0 - b.dead_band);
  const Scalar i = detail::t200_poly<Scalar>(b.current, s, voltage, nullptr);
  return value_of(i) > 0.0 ? i : Scalar(0);
}

/// \brief Largest forward thrust [N] at a supply voltage: t200_thrust(1, V) (51.5 N at 16 V).
/// \throws kelp::invalid_argument for a voltage outside [0, 20] V or not finite.
template <typename Scalar>
Scalar t200_max_thrust(const Scalar& voltage) {
  return t200_thrust(Scalar(1), voltage);
}

/// \brief Largest reverse thrust [N], as a positive magnitude: −t200_thrust(−1, V).
/// \throws kelp::invalid_argument for a voltage outside [0, 20] V or not finite.
template <typename Scalar>
Scalar t200_max_reverse_thrust(const Scalar& voltage) {
  return -t200_thrust(Scalar(-1), voltage);
}

/// \brief Inverse of t200_thrust() on its monotone branches: the command u with
/// t200_thrust(u, V) = force; 0 for a zero force, saturated at u = +1 beyond the largest forward
/// thrust and at −1 beyond the largest reverse thrust at that voltage. Safeguarded Newton in
/// double (bisection when a step leaves the bracket), then one Newton step in Scalar so that
/// ceres::Jet derivatives follow the implicit-function theorem (∂u/∂F = 1/F_u, ∂u/∂V = −F_V/F_u).
/// \param[in] force desired thrust [N] along the thruster's forward axis (negative: reverse).
/// \param[in] voltage supply voltage [V], in [0, 20].
/// \throws kelp::invalid_argument when a value is not finite or the voltage is out of range.
template <typename Scalar>
Scalar t200_command(const Scalar& force, const Scalar& voltage) {
  check_finite(force, "T200 force");
  detail::t200_check_voltage(voltage);
  const double f = value_of(force);
  if (f == 0.0) return Scalar(0);
  const double sign = f < 0.0 ? -1.0 : 1.0;
  const double target = sign * f;
  const double v = value_of(voltage);
  const double fmax = sign > 0 ? t200_max_thrust(v) : t200_max_reverse_thrust(v);
  if (target >= fmax) return Scalar(sign);
  const detail::T200Branch& b = sign > 0 ? detail::t200_forward : detail::t200_reverse;
  // Solve P(s) = target / kgf for s in (0, 1) (P rises monotonically from P(0) = 0).
  const double goal = target / t200_kgf;
  double lo = 0.0, hi = 1.0, s = target / fmax;
  for (int i = 0; i < 100 && hi - lo > 1e-15; ++i) {
    double d = 0.0;
    const double r = detail::t200_poly<double>(b.thrust, s, v, &d) - goal;
    if (r == 0.0) break;
    (r < 0.0 ? lo : hi) = s;
    double next = d > 0.0 ? s - r / d : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    const bool done = std::abs(next - s) <= 1e-16;
    s = next;
    if (done) break;
  }
  const Scalar u(sign * (b.dead_band + s * (1.0 - b.dead_band)));
  return u + (force - t200_thrust(u, voltage)) / t200_thrust_slope(u, voltage);
}

}  // namespace kelp::vehicle
