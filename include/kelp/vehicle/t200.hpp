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
/// they are stored with the tests (tests/vehicle/test_t200.cpp), which check the fit against
/// every one of them.
///
/// Model. With the command u ∈ [−1, 1] (u = (pwm − 1500 µs)/400 µs for the 1100–1900 µs ESC
/// range), both directions (forward u > 0, reverse u < 0) have the dead band
/// u₀(V) = 0.07 √(16 V / V) (t200_dead_band()) and the normalised excursion
/// s = (|u| − u₀)/(1 − u₀) ∈ [0, 1]. Thrust and current are each a full-throttle value times a
/// shape, \f$ y = M(v)\, s\,(a_1 + a_2 s + (1 - a_1 - a_2) s^2) \f$ with v = V/16 V and M, a₁,
/// a₂ quadratic in v, per direction: y(1, V) = M(V) is the full-throttle value (a quadratic
/// through the six voltages' full-throttle points) and the shape, fitted by least squares in
/// relative error (absolute error against 0.3 kgf for smaller thrusts, against 1 A for smaller
/// currents), lets the curve bend differently at each voltage; u₀'s 0.07 and ½ were chosen by a
/// scan for the smallest largest error. The thrust rises monotonically in s on 0–20 V (checked by
/// the tests: the inverse needs it); at part command it need not rise with the voltage, nor does
/// the data (1660 µs: 1.32 kgf at 18 V, 1.28 kgf at 20 V). Fit error over all 1 005 points of
/// the five sheets (zeros included): thrust max 7.1 % forward and 7.5 % reverse, RMS 2.3 % and
/// 2.1 %, where thrusts below 0.3 kgf are judged by their absolute error against 0.3 kgf (i.e.
/// within 0.03 kgf); supply current max 9.7 % / 9.0 % (below 1 A against 1 A), RMS 3.0 % / 2.6 %.
/// Full throttle at 16 V: 5.27 kgf = 51.6 N forward, 4.06 kgf = 39.8 N reverse (data 5.25 / 4.07),
/// 23.9 / 24.3 A; at 12 V 36.5 N / 28.7 N (data 3.71 / 2.92 kgf).
/// Forward thrust: the thruster is pushed towards its nose cone, the cable side (water enters at
/// the front and leaves at the back, through the nozzle); reverse is ~23 % weaker at full
/// command (forward/reverse 1.29 at 16 V, "~30 % more thrust" from the front, Blue Robotics).
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
/// \brief Half-range of the ESC's pulse width [µs]: the data's command u = (pwm − 1500 µs)/400 µs
/// (Blue Robotics Basic ESC: 1100–1900 µs, full reverse to full forward).
inline constexpr double t200_esc_half_range_us = 400.0;
/// \brief One kilogram-force [N] (the data's thrust unit; standard gravity).
inline constexpr double t200_kgf = 9.80665;

namespace detail {

/// One direction of the fit: for thrust [kgf] and supply current [A], the coefficients
/// {m₀, m₁, m₂, a₁₀, a₁₁, a₁₂, a₂₀, a₂₁, a₂₂} of
/// y = M(v) s (a₁ + s (a₂ + s (1 − a₁ − a₂))), M = m₀ + m₁ v + m₂ v², a_k = a_k0 + a_k1 v + a_k2
/// v².
struct T200Branch {
  double thrust[9];
  double current[9];
};

/// Forward (u > 0).
inline constexpr T200Branch t200_forward{
    {-1.37305143, 7.27798656, -0.638378194, 0.228226737, 0.415050477, -0.221636759, -0.304033322,
     3.49086856, -2.39246248},
    {-1.34383939, 21.7426023, 3.46383643, -0.0658617668, 0.111602377, -0.0366614579, 0.618634209,
     1.20536548, -1.09218925}};
/// Reverse (u < 0), magnitudes.
inline constexpr T200Branch t200_reverse{
    {-1.32822855, 6.51093898, -1.12239596, 0.168289237, 0.587368001, -0.300158307, 0.144924027,
     2.2245853, -1.5720405},
    {-1.21727037, 20.7440124, 4.78793131, -0.0749788809, 0.129206368, -0.0417571132, 0.868831398,
     0.494748018, -0.697111847}};

/// Checks the voltage: finite, ≥ 0, ≤ t200_max_voltage.
template <typename Scalar>
void t200_check_voltage(const Scalar& voltage) {
  check_finite(voltage, "thruster supply voltage [V]");
  check_at_least(voltage, 0.0, "thruster supply voltage [V]");
  check_at_most(voltage, t200_max_voltage, "thruster supply voltage [V]");
}

/// The fit y(s, V) and, if asked, dy/ds, with v from the voltage (at 10 V below it) and the
/// (V/10)² scale below 10 V applied to both.
template <typename Scalar>
Scalar t200_poly(const double* c, const Scalar& s, const Scalar& voltage, Scalar* ds) {
  const bool low = value_of(voltage) < t200_data_min_voltage;
  const Scalar v = low ? Scalar(t200_data_min_voltage / 16.0) : voltage / Scalar(16.0);
  const auto quadratic = [&v](const double* k) {
    return Scalar(k[0]) + v * (Scalar(k[1]) + v * Scalar(k[2]));
  };
  Scalar m = quadratic(c), a1 = quadratic(c + 3), a2 = quadratic(c + 6);
  const Scalar a3 = Scalar(1) - a1 - a2;
  if (low) {
    const Scalar r = voltage / Scalar(t200_data_min_voltage);
    m = m * r * r;
  }
  if (ds != nullptr) *ds = m * (a1 + s * (Scalar(2) * a2 + Scalar(3) * s * a3));
  return m * s * (a1 + s * (a2 + s * a3));
}

/// Dead band u₀(V) = 0.07 √(16 V / V), V clamped below at 10 V.
template <typename Scalar>
Scalar t200_dead_band(const Scalar& voltage) {
  using std::sqrt;
  const Scalar v =
      value_of(voltage) < t200_data_min_voltage ? Scalar(t200_data_min_voltage) : voltage;
  return Scalar(0.07) * sqrt(Scalar(16.0) / v);
}

/// Clamped |u| and the branch of the sign of u.
template <typename Scalar>
const T200Branch& t200_branch(const Scalar& command, Scalar& magnitude, double& sign) {
  check_finite(command, "thruster command u");
  const double u = value_of(command);
  sign = u < 0.0 ? -1.0 : 1.0;
  magnitude = u < 0.0 ? Scalar(-command) : command;
  if (value_of(magnitude) > 1.0) magnitude = Scalar(1);
  return u < 0.0 ? t200_reverse : t200_forward;
}

/// The operating point of a command at a supply voltage (both checked): the branch of u's sign,
/// the sign, and s = (|u| − u₀(V)) / (1 − u₀(V)) past the dead band with its span 1 − u₀(V).
/// \returns false inside the dead band (|u| ≤ u₀: no thrust, no current; s is then unset).
template <typename Scalar>
bool t200_point(const Scalar& command, const Scalar& voltage, const T200Branch*& branch,
                double& sign, Scalar& s, Scalar& span) {
  t200_check_voltage(voltage);
  Scalar m;
  branch = &t200_branch(command, m, sign);
  const Scalar u0 = t200_dead_band(voltage);
  if (value_of(m) <= value_of(u0)) return false;
  span = Scalar(1) - u0;
  s = (m - u0) / span;
  return true;
}

}  // namespace detail

/// \brief The ESC's dead band [normalised command] at a supply voltage: |u| ≤ u₀(V) gives no
/// thrust and no current; u₀ = 0.07 √(16 V / V) (±28 µs at 16 V, ±35 µs at 10 V, ±25 µs at
/// 20 V; fitted with the curves: the data read zero within ±24 to ±28 µs at 16–20 V and ±40 µs at
/// 10 V, where rotation stays under the 300 rpm the data cut to zero); the 10 V value below
/// 10 V.
/// \tparam Scalar double, float or ceres::Jet.
/// \param voltage Supply voltage at the ESC [V], in [0, 20].
/// \return u₀(V) [-] (0.07 at 16 V).
/// \throws kelp::invalid_argument for a voltage not finite or outside [0, 20] V.
template <typename Scalar>
Scalar t200_dead_band(const Scalar& voltage) {
  detail::t200_check_voltage(voltage);
  return detail::t200_dead_band(voltage);
}

/// \brief Static (bollard) thrust of one T200 [N] along its forward axis: positive for u > 0
/// (pushes the thruster towards its nose cone), negative for u < 0 (reverse, weaker), 0 in the
/// ESC's dead band (|u| ≤ t200_dead_band(V), 0.07 at 16 V).
/// \tparam Scalar double, float or ceres::Jet.
/// \param[in] command normalised command u (clamped to [−1, 1]; ±1 = 1900 / 1100 µs).
/// \param[in] voltage supply voltage at the ESC [V], in [0, 20] (see the file's notes).
/// \return Thrust [N] (51.6 N at u = 1 and 16 V).
/// \throws kelp::invalid_argument when a value is not finite or the voltage is outside [0, 20] V.
template <typename Scalar>
Scalar t200_thrust(const Scalar& command, const Scalar& voltage) {
  const detail::T200Branch* b = nullptr;
  double sign = 1.0;
  Scalar s, span;
  if (!detail::t200_point(command, voltage, b, sign, s, span)) return Scalar(0);
  return Scalar(sign * t200_kgf) * detail::t200_poly<Scalar>(b->thrust, s, voltage, nullptr);
}

/// \brief dF/du of t200_thrust() [N] (≥ 0; 0 in the dead band and for |u| > 1).
/// \tparam Scalar double, float or ceres::Jet.
/// \param[in] command normalised command u [-]. \param[in] voltage [V], in [0, 20].
/// \return dF/du [N per unit command].
/// \throws kelp::invalid_argument as t200_thrust().
template <typename Scalar>
Scalar t200_thrust_slope(const Scalar& command, const Scalar& voltage) {
  const detail::T200Branch* b = nullptr;
  double sign = 1.0;
  Scalar s, span;
  const double u = value_of(command);
  if (!detail::t200_point(command, voltage, b, sign, s, span) || u > 1.0 || u < -1.0)
    return Scalar(0);
  Scalar ds;
  detail::t200_poly<Scalar>(b->thrust, s, voltage, &ds);
  return Scalar(t200_kgf) * ds / span;
}

/// \brief Supply current drawn by one T200 and its ESC [A] (≥ 0; 0 in the dead band).
/// Fit error over the data: ≤ 9.6 % of the reading, or ≤ 0.096 A below 1 A.
/// \param[in] command u (clamped to [−1, 1]). \param[in] voltage [V], in [0, 20].
/// \tparam Scalar double, float or ceres::Jet.
/// \return Current [A], ≥ 0.
/// \throws kelp::invalid_argument as t200_thrust().
template <typename Scalar>
Scalar t200_current(const Scalar& command, const Scalar& voltage) {
  const detail::T200Branch* b = nullptr;
  double sign = 1.0;
  Scalar s, span;
  if (!detail::t200_point(command, voltage, b, sign, s, span)) return Scalar(0);
  const Scalar i = detail::t200_poly<Scalar>(b->current, s, voltage, nullptr);
  return value_of(i) > 0.0 ? i : Scalar(0);
}

/// \brief Largest forward thrust [N] at a supply voltage: t200_thrust(1, V) (51.6 N at 16 V).
/// \tparam Scalar double, float or ceres::Jet.
/// \param voltage Supply voltage [V], in [0, 20].
/// \return The thrust [N], ≥ 0.
/// \throws kelp::invalid_argument for a voltage outside [0, 20] V or not finite.
template <typename Scalar>
Scalar t200_max_thrust(const Scalar& voltage) {
  return t200_thrust(Scalar(1), voltage);
}

/// \brief Largest reverse thrust [N], as a positive magnitude: −t200_thrust(−1, V).
/// \tparam Scalar double, float or ceres::Jet.
/// \param voltage Supply voltage [V], in [0, 20].
/// \return The magnitude [N], ≥ 0.
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
/// \tparam Scalar double, float or ceres::Jet.
/// \return u ∈ [−1, 1] (outside the dead band unless the force is 0).
/// \throws kelp::invalid_argument when a value is not finite or the voltage is out of range.
template <typename Scalar>
Scalar t200_command(const Scalar& force, const Scalar& voltage) {
  check_finite(force, "thruster force");
  detail::t200_check_voltage(voltage);
  const double f = value_of(force);
  if (f == 0.0) return Scalar(0);
  const double sign = f < 0.0 ? -1.0 : 1.0;
  const double target = sign * f;
  const double v = value_of(voltage);
  const double fmax = sign > 0 ? t200_max_thrust(v) : t200_max_reverse_thrust(v);
  if (target >= fmax) return Scalar(sign);
  const detail::T200Branch& b = sign > 0 ? detail::t200_forward : detail::t200_reverse;
  // Solve y(s) = target / kgf for s in (0, 1) (y rises monotonically from y(0) = 0).
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
  // One Newton step in Scalar on F(u, V) = sign kgf y((|u| − u₀(V))/(1 − u₀(V)), V) at the
  // solution (its residual is ~0; it carries the derivatives through u₀(V) and y).
  const Scalar one(1);
  const Scalar u0 = detail::t200_dead_band(voltage);
  const Scalar ss(s);
  Scalar ds;
  const Scalar y = detail::t200_poly<Scalar>(b.thrust, ss, voltage, &ds);
  const Scalar u = Scalar(sign) * (u0 + ss * (one - u0));
  const Scalar slope = Scalar(t200_kgf) * ds / (one - u0);  // dF/du > 0 on both branches
  return u + (force - Scalar(sign * t200_kgf) * y) / slope;
}

}  // namespace kelp::vehicle
