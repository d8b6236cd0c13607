/// \file
/// \brief A vehicle's propulsion as part of its state: thrusters (T200s, or each on a curve of
/// its own) whose thrust follows their command through a first-order lag, drawing their current
/// from a battery whose voltage sags with the load and falls with the charge drawn, a T200's
/// thrust following that voltage.
///
/// **Thruster lag.** Each thruster's thrust f (along its direction d_i) obeys
/// T ḟ = F*(u, V) − f, with F* the static thrust of its command u at the supply voltage V
/// (t200_thrust; or the thruster's own curve, below). Over a step of length h with u and V held
/// (the zero-order hold of a digital ESC command), the exact solution is
/// f(h) = F* + (f₀ − F*) e^{−h/T}, and the thrust's mean over the step, the impulse per unit time
/// that the step applies, is F* + (f₀ − F*) (T/h)(1 − e^{−h/T}) (both computed here, with expm1
/// for small h/T).
///
/// Time constant: T = 20 ms (t200_time_constant), the first-order fit of the T200 model of von
/// Benzon, Sørensen, Uth, Jouffroy, Liniger, Pedersen 2022, "An Open-Source Benchmark Simulator:
/// Control of a BlueROV2 Underwater Robot", J. Mar. Sci. Eng. 10(12):1898, which writes the
/// thrust response as F/F_ref = (6136 s + 108700)/(s³ + 89 s² + 9258 s + 108700): its unit-step
/// response reaches 1 − e⁻¹ at 19.98 ms and the least-squares first-order fit over 0.5 s has
/// T = 20.1 ms (both computed by integrating that transfer function; tests/vehicle/
/// test_propulsion.cpp re-checks them). The first order misses the model's ~4 % overshoot at
/// 40–60 ms and its slower tail (0.92 at 100 ms, 0.98 at 200 ms): within 0.08 of the step at
/// 50, 100 and 200 ms. Step responses reported by T200 users on the Blue Robotics forum are
/// slower, ~30 to ~110 ms to settle depending on the step's size and the ESC; set
/// `time_constant` to study them; 0 turns the lag off (thrust = F* at once).
///
/// **Current and voltage.** Each T200 draws t200_current(u, V) from the battery at once (an
/// ESC accelerating its propeller draws at least its steady current: the lag is on the thrust,
/// not the current), plus the battery's hotel load. The terminal voltage V of the step solves
/// V = OCV(SoC) − R I(V) within the step (solve_terminal_voltage: the loop gain R dI/dV of eight
/// thrusters at full command is ≈ 0.5–0.8, too large to take the previous step's voltage without
/// ringing; the previous step's voltage is only the solve's starting point, part of the state);
/// thrust and current then use that V; the battery's counters grow by I h and V I h.
///
/// **Mounting.** `facing(i)` = +1 when a positive command spins thruster i in its forward
/// (stronger) direction and thrust along d_i results; −1 when the thruster is mounted the other
/// way round (a positive command still gives thrust along d_i, but from the propeller's reverse,
/// weaker side): f_i = facing_i · t200_thrust(facing_i · u_i, V).
///
/// **Commands.** u ∈ [−1, 1] is the normalised command of the vehicle's PWM mapping (as
/// ThrusterChain and the controllers use it); the T200 data's command is the ESC's,
/// u_esc = (pwm − 1500 µs)/400 µs: u_esc = u · esc_scale_forward (u > 0) or u · esc_scale_reverse,
/// clamped to [−1, 1] (1 for the BlueROV2's 1100–1900 µs outputs, 1.25 for the BlueBoat's
/// 1000–2000 µs: full thrust from 1900 µs on, as ThrusterChain does).
///
/// **A thruster's own curve.** `PropulsionParameters::curves[i]`, when not empty, replaces the
/// T200 model for thruster i by its static curve as measured (a bollard-pull test, a datasheet,
/// the SDF importer's Ct ρ D⁴ |ω| ω): F*(u) = thrust [N] along d_i and, optionally, I(u) = the
/// current [A] it draws from the battery, tabulated at commands −1 = c_0 < c_1 < … < c_{m−1} = 1
/// (2 ≤ m ≤ max_curve_points) and linear in between: for c_k ≤ u ≤ c_{k+1},
/// w = (u − c_k)/(c_{k+1} − c_k) and F*(u) = (1 − w) F_k + w F_{k+1} (so F*(c_k) = F_k exactly).
/// Its command is the vehicle's u itself, clamped to [−1, 1]: the curve was measured against
/// that command, with the thruster as mounted, so the ESC scales do not apply, facing must be +1
/// (validate() says so) and the thrust does not follow the voltage. The lag is the same: thrust
/// f_i follows F*(u_i) through T ḟ = F* − f, integrated exactly as above. The current I(u_i)
/// enters the battery's solve like a T200's (at once, not lagged); a curve without currents
/// draws nothing from the battery (only the hotel load and the other thrusters then do).
///
/// No heap allocation in advance(): per-thruster vectors have a fixed capacity of max_thrusters,
/// a curve's points of max_curve_points.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <string>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/vehicle/battery.hpp"
#include "kelp/vehicle/t200.hpp"
#include "kelp/vehicle/thrusters.hpp"

namespace kelp::vehicle {

/// \brief Most thrusters a propulsion model holds (the BlueROV2 Heavy has 8).
inline constexpr int max_thrusters = 8;

/// \brief A per-thruster vector of fixed capacity (max_thrusters; no heap).
template <typename Scalar>
using ThrusterVector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1, 0, max_thrusters, 1>;

/// \brief Most points a thruster's curve holds.
inline constexpr int max_curve_points = 64;

/// \brief A per-point vector of a thruster's curve, of fixed capacity max_curve_points (no heap).
using CurveVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, max_curve_points, 1>;

/// \brief A thruster's static curve as measured: thrust and, optionally, current against the
/// normalised command u ∈ [−1, 1], linear between the points (see the file comment). Empty (no
/// points, the default): the thruster is a T200.
struct ThrustCurve {
  /// u at each point: strictly ascending from −1 to 1, 2 to max_curve_points points.
  CurveVector command;
  /// Thrust [N] along the thruster's direction d_i at each point (negative: against it), finite.
  CurveVector thrust;
  /// Current [A] drawn from the battery at each point, finite and >= 0; empty: none drawn.
  CurveVector current;
  /// \brief True without points: the thruster is a T200.
  /// \return command.size() == 0.
  bool empty() const { return command.size() == 0; }
};

namespace detail {
// (1 − w) y_k + w y_{k+1} on the segment c_k ≤ x ≤ c_{k+1} of a checked curve `c` (bisection;
// x within [c_0, c_{m−1}]): y_k exactly at x = c_k.
template <typename Scalar>
Scalar curve_interpolate(const CurveVector& c, const CurveVector& y, const Scalar& x) {
  Eigen::Index lo = 0, hi = c.size() - 1;
  while (hi - lo > 1) {
    const Eigen::Index mid = (lo + hi) / 2;
    (c(mid) <= value_of(x) ? lo : hi) = mid;
  }
  const Scalar w = (x - Scalar(c(lo))) / Scalar(c(hi) - c(lo));
  return (Scalar(1) - w) * Scalar(y(lo)) + w * Scalar(y(hi));
}
template <typename Scalar>
Scalar clamp_command(Scalar u) {
  if (value_of(u) > 1.0) u = Scalar(1);
  if (value_of(u) < -1.0) u = Scalar(-1);
  return u;
}
}  // namespace detail

/// \brief Thrust [N] of a thruster's curve at command u (clamped to [−1, 1]), linear between its
/// points. \throws kelp::invalid_argument for an empty curve (the T200: t200_thrust).
/// \tparam Scalar double, float or ceres::Jet.
/// \param c The thruster's curve (validated: commands ascending from −1 to 1).
/// \param command Command u [-].
/// \return Thrust [N] along the thruster's direction.
template <typename Scalar>
Scalar curve_thrust(const ThrustCurve& c, const Scalar& command) {
  KELP_CHECK(c.command.size() >= 2 && c.thrust.size() == c.command.size(),
             "curve_thrust: the curve has no points (a T200: t200_thrust)");
  return detail::curve_interpolate(c.command, c.thrust, detail::clamp_command(command));
}

/// \brief Current [A] a thruster on its curve draws at command u (clamped to [−1, 1]), linear
/// between its points; 0 for a curve without currents. \throws kelp::invalid_argument for an
/// empty curve (the T200: t200_current).
/// \tparam Scalar double, float or ceres::Jet.
/// \param c The thruster's curve (validated).
/// \param command Command u [-].
/// \return Current [A] (≥ 0 for a valid curve).
template <typename Scalar>
Scalar curve_current(const ThrustCurve& c, const Scalar& command) {
  KELP_CHECK(c.command.size() >= 2,
             "curve_current: the curve has no points (a T200: "
             "t200_current)");
  if (c.current.size() != c.command.size()) return Scalar(0);
  return detail::curve_interpolate(c.command, c.current, detail::clamp_command(command));
}

/// \brief T200 thrust time constant [s]: the first-order fit of von Benzon et al. 2022's T200
/// model (see the file comment).
inline constexpr double t200_time_constant = 0.02;

/// \brief A vehicle's propulsion: thruster geometry and mounting, lag, battery.
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
struct PropulsionParameters {
  /// r_i [m], 3×n (1 ≤ n ≤ max_thrusters), body axes relative to the CO.
  Matrix3X<Scalar> positions;
  /// d_i, 3×n, body axes: thrust direction of a positive command (normalised when built).
  Matrix3X<Scalar> directions;
  /// ±1 per thruster (see the file comment); empty: all +1. +1 for a thruster with a curve.
  ThrusterVector<int> facing;
  /// Per thruster i < n: its own curve (see the file comment), or empty (the default): the T200
  /// model. Entries from n on must be empty.
  std::array<ThrustCurve, max_thrusters> curves;
  /// u_esc / u for positive commands ((max_us − neutral_us)/400 µs of the PWM mapping), > 0.
  /// T200s only (a curve takes u itself).
  double esc_scale_forward = 1.0;
  /// u_esc / u for negative commands ((neutral_us − min_us)/400 µs), > 0. T200s only.
  double esc_scale_reverse = 1.0;
  /// First-order lag of the thrust [s]; 0: no lag.
  double time_constant = t200_time_constant;
  /// The battery the thrusters draw from.
  BatteryParameters battery;
};

/// \brief Checks propulsion parameters. \throws kelp::invalid_argument naming the field
/// (`propulsion.<field>`, e.g. `propulsion.curves[3].thrust must be finite`): shapes (1 …
/// max_thrusters thrusters), facing ±1, each curve (none from n on; else empty, with no thrusts
/// and no currents, or 2 to max_curve_points commands strictly ascending from −1 to 1, one finite
/// thrust per command, no currents or one finite non-negative current per command; facing +1),
/// a finite non-negative time constant, the battery's fields.
/// Also: ESC scales finite > 0. The directions are checked when the model is built
/// (allocation_matrix()).
/// \tparam Scalar double, float or ceres::Jet.
/// \param p The parameters to check.
template <typename Scalar>
void validate(const PropulsionParameters<Scalar>& p) {
  KELP_CHECK(p.positions.cols() >= 1 && p.positions.cols() <= max_thrusters,
             "propulsion.positions must have 1 to 8 columns (one per thruster)");
  KELP_CHECK(p.facing.size() == 0 || p.facing.size() == p.positions.cols(),
             "propulsion.facing must be empty or have one entry per thruster");
  for (Eigen::Index i = 0; i < p.facing.size(); ++i)
    KELP_CHECK(p.facing(i) == 1 || p.facing(i) == -1, "propulsion.facing entries must be +1 or -1");
  for (Eigen::Index i = 0; i < max_thrusters; ++i) {
    const ThrustCurve& c = p.curves[std::size_t(i)];
    const Eigen::Index m = c.command.size();
    const std::string field = "propulsion.curves[" + std::to_string(i) + "]";
    KELP_CHECK(
        i < p.positions.cols() || c.empty(),
        field + " must be empty: there are " + std::to_string(p.positions.cols()) + " thrusters");
    KELP_CHECK(m > 0 || (c.thrust.size() == 0 && c.current.size() == 0),
               field + ": thrusts or currents without commands (an empty curve is the T200)");
    if (m == 0) continue;
    KELP_CHECK(m >= 2,
               field + ".command must have 2 to " + std::to_string(max_curve_points) + " points");
    KELP_CHECK(c.command(0) == -1.0 && c.command(m - 1) == 1.0,
               field + ".command must run from -1 to 1");
    for (Eigen::Index k = 1; k < m; ++k)
      KELP_CHECK(c.command(k) > c.command(k - 1),
                 field + ".command must be strictly ascending (point " + std::to_string(k) + ")");
    KELP_CHECK(c.thrust.size() == m, field + ".thrust must have one entry per command");
    KELP_CHECK(c.thrust.allFinite(), field + ".thrust must be finite");
    KELP_CHECK(c.current.size() == 0 || c.current.size() == m,
               field + ".current must be empty or have one entry per command");
    KELP_CHECK(c.current.allFinite() && (c.current.array() >= 0.0).all(),
               field + ".current must be finite and >= 0");
    KELP_CHECK(p.facing.size() == 0 || p.facing(i) == 1,
               "propulsion.facing[" + std::to_string(i) + "] must be +1: thruster " +
                   std::to_string(i) + " has a curve (measured as mounted, both directions)");
  }
  check_positive(p.esc_scale_forward, "propulsion.esc_scale_forward");
  check_positive(p.esc_scale_reverse, "propulsion.esc_scale_reverse");
  KELP_CHECK(std::isfinite(p.time_constant) && p.time_constant >= 0.0,
             "propulsion.time_constant must be finite and >= 0");
  validate(p.battery);
}

/// \brief A propulsion built once: the parameters and the allocation B (6×n).
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
class PropulsionModel {
 public:
  /// \brief Validates `p` and builds the allocation (directions normalised).
  /// \param p The propulsion's parameters (copied).
  /// \throws kelp::invalid_argument (validate(), allocation_matrix()).
  explicit PropulsionModel(const PropulsionParameters<Scalar>& p)
      : parameters_((validate(p), p)), allocation_(p.positions, p.directions) {
    facing_ = ThrusterVector<int>::Ones(allocation_.size());
    if (p.facing.size() > 0) facing_ = p.facing;
  }
  /// \brief The parameters.
  /// \return The parameters, as given.
  const PropulsionParameters<Scalar>& parameters() const { return parameters_; }
  /// \brief The allocation (B = allocation().matrix()).
  /// \return The thruster allocation, body axes about the CO.
  const ThrusterAllocation<Scalar>& allocation() const { return allocation_; }
  /// \brief Number of thrusters.
  /// \return n, 1 ≤ n ≤ max_thrusters.
  Eigen::Index size() const { return allocation_.size(); }
  /// \brief ±1 per thruster.
  /// \return n entries (all +1 when the parameters' facing was empty).
  const ThrusterVector<int>& facing() const { return facing_; }

 private:
  PropulsionParameters<Scalar> parameters_;
  ThrusterAllocation<Scalar> allocation_;
  ThrusterVector<int> facing_;
};

/// \brief Everything of a propulsion that determines its next step (part of the system state).
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
struct PropulsionState {
  /// Each thruster's thrust along its direction now [N] (the lag's state).
  ThrusterVector<Scalar> thrust;
  /// Each thruster's current over the last step [A] (recorded, not an input of the next step).
  ThrusterVector<double> current;
  /// The battery's counters and its last load.
  BatteryState battery;
};

/// \brief The state of `m` at rest with a fresh battery (at its initial_soc): zero thrust.
/// \tparam Scalar double, float or ceres::Jet.
/// \param m The propulsion.
/// \return n zero thrusts and currents, a default BatteryState.
template <typename Scalar>
PropulsionState<Scalar> initial_state(const PropulsionModel<Scalar>& m) {
  PropulsionState<Scalar> s;
  s.thrust = ThrusterVector<Scalar>::Zero(m.size());
  s.current = ThrusterVector<double>::Zero(m.size());
  return s;
}

/// \brief Throws kelp::invalid_argument naming `field` unless `s` fits `m` (one thrust and one
/// current per thruster, finite thrusts, finite battery counters).
/// \tparam Scalar double, float or ceres::Jet.
/// \param m The propulsion.
/// \param s The state to check.
/// \param field Name of the state in the message (e.g. "propulsion state").
template <typename Scalar>
void check_state(const PropulsionModel<Scalar>& m, const PropulsionState<Scalar>& s,
                 const char* field) {
  KELP_CHECK(s.thrust.size() == m.size() && s.current.size() == m.size(),
             std::string(field) +
                 ": one thrust and one current per thruster are needed (start from "
                 "initial_state)");
  check_all_finite(s.thrust, field);
  KELP_CHECK(std::isfinite(s.battery.charge_drawn) && std::isfinite(s.battery.energy_drawn),
             std::string(field) + ": the battery's counters must be finite");
}

/// \brief What one propulsion step delivered.
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
struct PropulsionStep {
  /// Body wrench of the thrust's mean over the step, B f̄ [N, N m].
  Vector6<Scalar> wrench = Vector6<Scalar>::Zero();
  /// Terminal voltage over the step [V].
  double voltage = 0.0;
  /// Total current over the step (thrusters + hotel) [A].
  double current = 0.0;
};

/// \brief Advances a propulsion by `dt` [s] under per-thruster commands u ∈ [−1, 1] (clamped;
/// empty: all 0) held over the step (see the file comment): solves the terminal voltage,
/// integrates the lag exactly towards each thruster's static thrust (T200 or its curve), drains
/// the battery. Allocation-free.
/// \tparam Derived Any Eigen vector expression (n entries, or 0).
/// \param[in] m the propulsion.
/// \param[in,out] s advanced by dt (only once every check has passed).
/// \param[in] commands u per thruster [-], clamped to [−1, 1] after the ESC scale; empty: all 0.
/// \param[in] dt step [s], > 0.
/// \returns the mean thrust's wrench and the step's voltage and current.
/// \throws kelp::invalid_argument for a bad dt, a command vector of the wrong size or with a
/// non-finite entry, or a state that does not fit the model (`s` unchanged).
template <typename Scalar, typename Derived>
PropulsionStep<Scalar> advance(const PropulsionModel<Scalar>& m, PropulsionState<Scalar>& s,
                               const Eigen::MatrixBase<Derived>& commands, double dt) {
  check_positive(dt, "dt");
  const Eigen::Index n = m.size();
  KELP_CHECK(commands.size() == 0 || commands.size() == n,
             "thruster commands must be empty or have one entry per thruster");
  check_all_finite(commands, "thruster commands");
  check_state(m, s, "propulsion state");
  const double up = m.parameters().esc_scale_forward, down = m.parameters().esc_scale_reverse;
  const auto command = [&](Eigen::Index i) {  // the ESC's command
    if (commands.size() == 0) return Scalar(0);
    Scalar u = Scalar(commands(i));
    u = value_of(u) > 0.0 ? Scalar(u * Scalar(up)) : Scalar(u * Scalar(down));
    if (value_of(u) > 1.0) u = Scalar(1);
    if (value_of(u) < -1.0) u = Scalar(-1);
    return u;
  };
  // A curve's command: the vehicle's u itself (see the file comment).
  const auto curve_command = [&](Eigen::Index i) {
    return commands.size() == 0 ? Scalar(0) : detail::clamp_command(Scalar(commands(i)));
  };
  const BatteryParameters& bp = m.parameters().battery;
  const ThrusterVector<int>& facing = m.facing();
  const std::array<ThrustCurve, max_thrusters>& curves = m.parameters().curves;
  // The step's terminal voltage: the thrusters' current at V, in double (warm-started from the
  // last step's voltage); the currents of the last evaluation, at the returned V, are kept. A
  // curve's current does not depend on V: set once, before the solve.
  ThrusterVector<double> currents(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const ThrustCurve& c = curves[std::size_t(i)];
    if (!c.empty())
      currents(i) = c.current.size() == 0 ? 0.0
                                          : detail::curve_interpolate(c.command, c.current,
                                                                      value_of(curve_command(i)));
  }
  const double v = solve_terminal_voltage(
      bp, s.battery,
      [&](double volts) {
        double sum = 0.0;
        for (Eigen::Index i = 0; i < n; ++i) {
          if (curves[std::size_t(i)].empty())
            currents(i) = t200_current(double(facing(i)) * value_of(command(i)), volts);
          sum += currents(i);
        }
        return sum;
      },
      s.battery.voltage);
  PropulsionStep<Scalar> out;
  // Zeroed although the loop sets every entry: GCC 12 at -O3 otherwise warns that entries past
  // a one-thruster command may be read uninitialised in the allocation product below.
  ThrusterVector<Scalar> mean = ThrusterVector<Scalar>::Zero(n);
  double total = bp.hotel_current;
  const double tc = m.parameters().time_constant;
  // What is left of f₀ − F* at the end of the step, e^{−h/T}, and on average over it,
  // (T/h)(1 − e^{−h/T}); both 0 without a lag. In double (they do not depend on Scalar).
  const double decay = tc > 0.0 ? std::exp(-dt / tc) : 0.0;
  const double average = tc > 0.0 ? -std::expm1(-dt / tc) * (tc / dt) : 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const ThrustCurve& c = curves[std::size_t(i)];
    Scalar target;
    if (c.empty()) {
      const Scalar sign(facing(i));
      target = sign * t200_thrust(sign * command(i), Scalar(v));
    } else {
      target = detail::curve_interpolate(c.command, c.thrust, curve_command(i));
    }
    const Scalar f0 = s.thrust(i);
    mean(i) = target + (f0 - target) * Scalar(average);
    s.thrust(i) = target + (f0 - target) * Scalar(decay);
    s.current(i) = currents(i);
    total += currents(i);
  }
  drain(s.battery, total, v, dt);
  out.wrench.noalias() = m.allocation().matrix() * mean;
  out.voltage = v;
  out.current = total;
  return out;
}

using PropulsionParametersd = PropulsionParameters<double>;  ///< PropulsionParameters<double>
using PropulsionParametersf = PropulsionParameters<float>;   ///< PropulsionParameters<float>
using PropulsionModeld = PropulsionModel<double>;            ///< PropulsionModel<double>
using PropulsionModelf = PropulsionModel<float>;             ///< PropulsionModel<float>
using PropulsionStated = PropulsionState<double>;            ///< PropulsionState<double>
using PropulsionStatef = PropulsionState<float>;             ///< PropulsionState<float>

}  // namespace kelp::vehicle
