/// \file
/// \brief A PID controller with output saturation and anti-windup, sampled at its own rate.
///
/// u = kp e + ki ∫e dt + kd ė, clamped to ±output_limit. The derivative is taken from a rate the
/// caller measures (e.g. minus the velocity for a position error: derivative on measurement, no
/// kick when the setpoint jumps); without one it is the backward difference of e. Anti-windup by
/// conditional integration (Åström & Hägglund 2006, Advanced PID Control, §3.5): the integral is
/// frozen while the output is saturated and the error would drive it further into saturation, and
/// it is clamped to ±integral_limit. Controllers run in double.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "kelp/core/error.hpp"
#include "kelp/core/memory.hpp"
#include "kelp/core/scalar.hpp"

namespace kelp::control {

/// \brief Gains and limits of a PID.
struct PidGains {
  double kp = 0.0;  ///< proportional gain
  double ki = 0.0;  ///< integral gain [1/s]
  double kd = 0.0;  ///< derivative gain [s]
  /// |u| ≤ output_limit (+∞: no saturation).
  double output_limit = std::numeric_limits<double>::infinity();
  /// |∫e dt| ≤ integral_limit (+∞: none; the conditional integration still applies).
  double integral_limit = std::numeric_limits<double>::infinity();
};

/// \brief Checks PID gains: finite, non-negative, positive limits.
/// \param g the gains: kp, ki, kd finite and ≥ 0; output_limit and integral_limit > 0 (+∞
/// allowed).
/// \param what the name the message gives the gains (e.g. "auv.surge").
/// \throws kelp::invalid_argument naming `what`.field.
inline void validate(const PidGains& g, const char* what = "pid") {
  const std::string w(what);
  check_non_negative(g.kp, (w + ".kp").c_str());
  check_non_negative(g.ki, (w + ".ki").c_str());
  check_non_negative(g.kd, (w + ".kd").c_str());
  KELP_CHECK(g.output_limit > 0.0, w + ".output_limit must be > 0");
  KELP_CHECK(g.integral_limit > 0.0, w + ".integral_limit must be > 0");
}

/// \brief A PID controller (see the file comment). Allocation-free.
class Pid {
 public:
  Pid() = default;
  /// \brief A controller with gains `g`, integral and memory cleared.
  /// \param g the gains, checked by validate(const PidGains&, const char*).
  /// \param what the name the error message gives the gains.
  /// \throws kelp::invalid_argument for bad gains.
  explicit Pid(const PidGains& g, const char* what = "pid") : gains_((validate(g, what), g)) {}

  /// \brief One update with error e and time step dt [s] (> 0); `rate` is ė if measured (else
  /// NaN: the backward difference of e, zero on the first update). Returns the clamped output.
  /// \param e the error, setpoint − measurement, in the controlled quantity's unit; finite.
  /// \param dt the time since the last update [s], > 0.
  /// \param rate ė [unit of e per s] when measured (for a position error, minus the velocity);
  /// NaN or any non-finite value for the backward difference.
  /// \return u, clamped to ±output_limit (the unit of e times kp's).
  /// \throws kelp::invalid_argument when e is not finite or dt is not finite and > 0 (the state
  /// is then unchanged).
  double update(double e, double dt, double rate = std::numeric_limits<double>::quiet_NaN()) {
    check_finite(e, "pid error");
    check_positive(dt, "pid dt");
    double d = 0.0;
    if (std::isfinite(rate))
      d = rate;
    else if (has_last_)
      d = (e - last_error_) / dt;
    last_error_ = e;
    has_last_ = true;
    const double unclamped_without_i = gains_.kp * e + gains_.kd * d;
    const double trial = integral_ + e * dt;
    const double u_trial = unclamped_without_i + gains_.ki * trial;
    const double lim = gains_.output_limit;
    // Integrate unless saturated with the error pushing further out.
    const bool winding = (u_trial > lim && e > 0.0) || (u_trial < -lim && e < 0.0);
    if (!winding) integral_ = std::clamp(trial, -gains_.integral_limit, gains_.integral_limit);
    saturated_ = std::abs(unclamped_without_i + gains_.ki * integral_) > lim;
    output_ = std::clamp(unclamped_without_i + gains_.ki * integral_, -lim, lim);
    return output_;
  }
  /// \brief Sets the integral back (e.g. to its value before an update whose output an actuator
  /// downstream could not deliver: anti-windup for saturation after allocation). A value within
  /// ±integral_limit is kept exactly; one beyond it is clamped to the limit, as update() clamps.
  /// \param value the new ∫e dt [unit of e × s], finite.
  /// \throws kelp::invalid_argument when `value` is not finite (the integral is then unchanged).
  void set_integral(double value) {
    check_finite(value, "pid integral");
    integral_ = std::clamp(value, -gains_.integral_limit, gains_.integral_limit);
  }
  /// \brief The integral ∫e dt.
  /// \return ∫e dt [unit of e × s], within ±integral_limit.
  double integral() const { return integral_; }
  /// \brief The last output.
  /// \return the value update() last returned (0 before the first update and after reset()).
  double output() const { return output_; }
  /// \brief True when the last output was clamped.
  /// \return whether |u| before clamping exceeded output_limit at the last update.
  bool saturated() const { return saturated_; }
  /// \brief Clears the integral and the derivative memory.
  void reset() {
    integral_ = output_ = last_error_ = 0.0;
    has_last_ = saturated_ = false;
  }
  /// \brief The gains.
  /// \return the gains given to the constructor (all zero and unlimited when default-constructed).
  const PidGains& gains() const { return gains_; }
  /// \brief visit_memory(v): the integral, the last output and error and their flags, for a
  /// run's checkpoint (kelp/core/memory.hpp).
  /// \tparam V a memory visitor \param v the visitor
  KELP_MEMORY(integral_, output_, last_error_, has_last_, saturated_)

 private:
  PidGains gains_;
  double integral_ = 0.0, output_ = 0.0, last_error_ = 0.0;
  bool has_last_ = false, saturated_ = false;
};

}  // namespace kelp::control
