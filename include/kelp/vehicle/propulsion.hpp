/// \file
/// \brief A vehicle's propulsion as part of its state: T200 thrusters whose thrust follows
/// their command through a first-order lag, drawing their current from a battery whose voltage
/// sags with the load and falls with the charge drawn, the thrust following that voltage.
///
/// **Thruster lag.** Each thruster's thrust f (along its direction d_i) obeys
/// T ḟ = F*(u, V) − f, with F* the static thrust of its command u at the supply voltage V
/// (t200_thrust). Over a step of length h with u and V held (the zero-order hold of a digital
/// ESC command), the exact solution is f(h) = F* + (f₀ − F*) e^{−h/T}, and the thrust's mean
/// over the step, the impulse per unit time that the step applies, is
/// F* + (f₀ − F*) (T/h)(1 − e^{−h/T}) (both computed here, with expm1 for small h/T).
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
/// **Current and voltage.** Each thruster draws t200_current(u, V) from the battery at once (an
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
/// No heap allocation in advance(): per-thruster vectors have a fixed capacity of max_thrusters.
#pragma once

#include <Eigen/Core>
#include <cmath>

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
  /// ±1 per thruster (see the file comment); empty: all +1.
  ThrusterVector<int> facing;
  /// u_esc / u for positive commands ((max_us − neutral_us)/400 µs of the PWM mapping), > 0.
  double esc_scale_forward = 1.0;
  /// u_esc / u for negative commands ((neutral_us − min_us)/400 µs), > 0.
  double esc_scale_reverse = 1.0;
  /// First-order lag of the thrust [s]; 0: no lag.
  double time_constant = t200_time_constant;
  /// The battery the thrusters draw from.
  BatteryParameters battery;
};

/// \brief Checks propulsion parameters. \throws kelp::invalid_argument naming the field
/// (`propulsion.<field>`): shapes (1 … max_thrusters thrusters), facing ±1, a finite
/// non-negative time constant, the battery's fields.
template <typename Scalar>
void validate(const PropulsionParameters<Scalar>& p) {
  KELP_CHECK(p.positions.cols() >= 1 && p.positions.cols() <= max_thrusters,
             "propulsion.positions must have 1 to 8 columns (one per thruster)");
  KELP_CHECK(p.facing.size() == 0 || p.facing.size() == p.positions.cols(),
             "propulsion.facing must be empty or have one entry per thruster");
  for (Eigen::Index i = 0; i < p.facing.size(); ++i)
    KELP_CHECK(p.facing(i) == 1 || p.facing(i) == -1, "propulsion.facing entries must be +1 or -1");
  check_positive(p.esc_scale_forward, "propulsion.esc_scale_forward");
  check_positive(p.esc_scale_reverse, "propulsion.esc_scale_reverse");
  KELP_CHECK(std::isfinite(p.time_constant) && p.time_constant >= 0.0,
             "propulsion.time_constant must be finite and >= 0");
  validate(p.battery);
}

/// \brief A propulsion built once: the parameters and the allocation B (6×n).
template <typename Scalar>
class PropulsionModel {
 public:
  /// \throws kelp::invalid_argument (validate(), allocation_matrix()).
  explicit PropulsionModel(const PropulsionParameters<Scalar>& p)
      : parameters_((validate(p), p)), allocation_(p.positions, p.directions) {
    facing_ = ThrusterVector<int>::Ones(allocation_.size());
    if (p.facing.size() > 0) facing_ = p.facing;
  }
  /// \brief The parameters.
  const PropulsionParameters<Scalar>& parameters() const { return parameters_; }
  /// \brief The allocation (B = allocation().matrix()).
  const ThrusterAllocation<Scalar>& allocation() const { return allocation_; }
  /// \brief Number of thrusters.
  Eigen::Index size() const { return allocation_.size(); }
  /// \brief ±1 per thruster.
  const ThrusterVector<int>& facing() const { return facing_; }

 private:
  PropulsionParameters<Scalar> parameters_;
  ThrusterAllocation<Scalar> allocation_;
  ThrusterVector<int> facing_;
};

/// \brief Everything of a propulsion that determines its next step (part of the system state).
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
template <typename Scalar>
PropulsionState<Scalar> initial_state(const PropulsionModel<Scalar>& m) {
  PropulsionState<Scalar> s;
  s.thrust = ThrusterVector<Scalar>::Zero(m.size());
  s.current = ThrusterVector<double>::Zero(m.size());
  return s;
}

/// \brief Throws kelp::invalid_argument naming `field` unless `s` fits `m` (one entry per
/// thruster, finite thrust, finite non-negative counters).
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
/// integrates the lag exactly, drains the battery. Allocation-free.
/// \param[in,out] s advanced by dt (only once every check has passed).
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
  const BatteryParameters& bp = m.parameters().battery;
  const ThrusterVector<int>& facing = m.facing();
  // The step's terminal voltage: the thrusters' current at V, in double (warm-started from the
  // last step's voltage); the currents of the last evaluation, at the returned V, are kept.
  ThrusterVector<double> currents(n);
  const double v = solve_terminal_voltage(
      bp, s.battery,
      [&](double volts) {
        double sum = 0.0;
        for (Eigen::Index i = 0; i < n; ++i) {
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
    const Scalar sign(facing(i));
    const Scalar target = sign * t200_thrust(sign * command(i), Scalar(v));
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
