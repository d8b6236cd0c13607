/// \file
/// \brief Thrusters: the allocation matrix from thruster positions and directions, the Blue
/// Robotics T200 static thrust curve and its inverse, and the PWM ↔ normalised command mapping.
#pragma once

#include <Eigen/Core>
#include <Eigen/QR>
#include <cmath>
#include <string>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"

namespace kelp::vehicle {

/// \brief Thrust-allocation matrix B (6×n): column i is (d_i, r_i × d_i), the wrench about the
/// CO of a unit thrust along d_i applied at r_i (Fossen 2021, control-allocation chapter: τ = T f).
/// \param[in] positions r_i [m], 3×n, body axes relative to the CO.
/// \param[in] directions d_i, 3×n, body axes; normalised here (thrust of a positive command).
/// \throws kelp::invalid_argument naming `thruster_positions` or `thruster_directions` (wrong
/// shape, not finite, a zero direction), or when a moment r_i × d_i overflows.
template <typename DP, typename DD>
Eigen::Matrix<typename DP::Scalar, 6, Eigen::Dynamic> allocation_matrix(
    const Eigen::MatrixBase<DP>& positions, const Eigen::MatrixBase<DD>& directions) {
  using S = typename DP::Scalar;
  KELP_CHECK(positions.rows() == 3 && positions.cols() >= 1,
             "thruster_positions must be 3 x n with n >= 1");
  KELP_CHECK(directions.rows() == 3 && directions.cols() == positions.cols(),
             "thruster_directions must be 3 x n, one column per thruster position");
  check_all_finite(positions, "thruster_positions");
  check_all_finite(directions, "thruster_directions");
  Eigen::Matrix<S, 6, Eigen::Dynamic> B(6, positions.cols());
  for (Eigen::Index i = 0; i < positions.cols(); ++i) {
    const Vector3<S> d(directions.col(i));
    using std::sqrt;
    const S n = sqrt(d.squaredNorm());
    KELP_CHECK(value_of(n) > 1e-12, "thruster_directions must be non-zero vectors");
    const Vector3<S> u = d / n;
    const Vector3<S> r(positions.col(i));
    B.col(i).template head<3>() = u;
    B.col(i).template tail<3>() = r.cross(u);
  }
  check_all_finite(B, "thruster_positions: the allocation matrix (moments r x d)");
  return B;
}

/// \brief A fixed set of thrusters: allocation matrix B and its Moore–Penrose pseudo-inverse B⁺,
/// both computed once at construction. wrench() and distribute() are allocation-free.
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
class ThrusterAllocation {
 public:
  /// \brief Builds B from positions and directions (see allocation_matrix()) and B⁺ by a complete
  /// orthogonal decomposition (valid for any rank).
  /// \param[in] positions r_i [m], 3×n, body. \param[in] directions d_i, 3×n, body.
  /// \throws kelp::invalid_argument as allocation_matrix(), or when B⁺ is not finite.
  template <typename DP, typename DD>
  ThrusterAllocation(const Eigen::MatrixBase<DP>& positions,
                     const Eigen::MatrixBase<DD>& directions)
      : matrix_(allocation_matrix(positions, directions)) {
    // positions_ is assigned only after allocation_matrix() has checked the shapes.
    positions_ = positions;
    directions_ = matrix_.template topRows<3>();
    Eigen::CompleteOrthogonalDecomposition<Eigen::Matrix<Scalar, 6, Eigen::Dynamic>> cod(matrix_);
    pseudo_inverse_ = cod.pseudoInverse();
    rank_ = cod.rank();
    check_all_finite(pseudo_inverse_, "thruster_positions: the pseudo-inverse of the allocation");
  }

  /// \brief Number of thrusters n.
  Eigen::Index size() const { return matrix_.cols(); }
  /// \brief Rank of B (6 for a fully actuated vehicle).
  Eigen::Index rank() const { return rank_; }
  /// \brief r_i [m], 3×n, body.
  const Matrix3X<Scalar>& positions() const { return positions_; }
  /// \brief Unit d_i, 3×n, body.
  const Matrix3X<Scalar>& directions() const { return directions_; }
  /// \brief B, 6×n.
  const Eigen::Matrix<Scalar, 6, Eigen::Dynamic>& matrix() const { return matrix_; }
  /// \brief B⁺, n×6.
  const Eigen::Matrix<Scalar, Eigen::Dynamic, 6>& pseudo_inverse() const { return pseudo_inverse_; }

  /// \brief Body wrench τ = B f [N, N m] of the thruster forces f [N] (n-vector).
  /// \throws kelp::invalid_argument when `forces` has not one entry per thruster or an entry
  /// is not finite.
  template <typename Derived>
  Vector6<Scalar> wrench(const Eigen::MatrixBase<Derived>& forces) const {
    KELP_CHECK(forces.size() == size(), "forces must have one entry per thruster");
    check_all_finite(forces, "thruster forces");
    Vector6<Scalar> tau;
    tau.noalias() = matrix_ * forces;
    return tau;
  }

  /// \brief Minimum-norm thruster forces f = B⁺ τ [N] for a desired body wrench τ [N, N m]
  /// (least-squares when τ is not reachable). `forces` must already have n rows.
  /// \throws kelp::invalid_argument when `tau` has not 6 entries or an entry is not finite, or
  /// `forces` has not one entry per thruster (`forces` is left unchanged).
  template <typename DW, typename DF>
  void distribute(const Eigen::MatrixBase<DW>& tau, Eigen::MatrixBase<DF>& forces) const {
    KELP_CHECK(forces.size() == size(), "forces must have one entry per thruster");
    KELP_CHECK(tau.size() == 6, "tau (desired wrench) must have 6 entries");
    check_all_finite(tau, "tau (desired wrench)");
    forces.noalias() = pseudo_inverse_ * tau;
  }

 private:
  Eigen::Matrix<Scalar, 6, Eigen::Dynamic> matrix_;
  Matrix3X<Scalar> positions_;
  Matrix3X<Scalar> directions_;
  Eigen::Matrix<Scalar, Eigen::Dynamic, 6> pseudo_inverse_;
  Eigen::Index rank_ = 0;
};

/// \brief Blue Robotics T200 static thrust [N] for a normalised command u ∈ [−1, 1] (clamped):
/// F(u) = −140.3u⁹ + 389.9u⁷ − 404.1u⁵ + 176.0u³ + 8.9u, F(1) ≈ 30.4 N (von Benzon et al. 2022,
/// J. Mar. Sci. Eng. 10(12):1898, fit to the Blue Robotics T200 data; odd, so reverse = forward).
/// \param[in] u normalised command (positive: thrust along the thruster direction).
template <typename Scalar>
Scalar t200_thrust(const Scalar& u_in) {
  check_finite(u_in, "thruster command u");
  Scalar u = u_in;
  if (value_of(u) > 1.0) u = Scalar(1);
  if (value_of(u) < -1.0) u = Scalar(-1);
  const Scalar u2 = u * u;
  return u *
         (Scalar(8.9) + u2 * (Scalar(176.0) +
                              u2 * (Scalar(-404.1) + u2 * (Scalar(389.9) + u2 * Scalar(-140.3)))));
}

/// \brief dF/du of t200_thrust() [N] (same clamping: 0 outside [−1, 1]).
/// \throws kelp::invalid_argument naming `thruster command u` when u is not finite.
template <typename Scalar>
Scalar t200_thrust_slope(const Scalar& u) {
  check_finite(u, "thruster command u");
  if (value_of(u) > 1.0 || value_of(u) < -1.0) return Scalar(0);
  const Scalar u2 = u * u;
  return Scalar(8.9) +
         u2 * (Scalar(3 * 176.0) +
               u2 * (Scalar(-5 * 404.1) + u2 * (Scalar(7 * 389.9) + u2 * Scalar(-9 * 140.3))));
}

/// \brief Command at which the T200 curve peaks: the polynomial rises monotonically on
/// [0, 0.971656] to 30.62 N and then falls slightly to 30.40 N at u = 1 (root of dF/du at
/// 0.97165617, found by bisection in double and rounded down; the unit test re-checks it).
inline constexpr double t200_peak_command = 0.971656;
/// \brief Largest T200 thrust the curve gives, F(t200_peak_command) = 30.621753 N, rounded down
/// [N].
inline constexpr double t200_max_thrust = 30.62175;

/// \brief Inverse of the T200 curve on its monotone branch: the command u ∈ [−u_peak, u_peak]
/// with t200_thrust(u) = force; forces beyond ±t200_max_thrust saturate at ±u_peak.
/// Newton's method safeguarded by bisection on the value (the bracket shrinks at every step; a
/// Newton step that leaves it is replaced by the midpoint; 5–8 iterations instead of 60
/// bisections), then one Newton correction in Scalar so that ceres::Jet derivatives follow the
/// implicit-function theorem (du/dF = 1/F'(u)).
/// \param[in] force desired thrust [N] along the thruster direction.
template <typename Scalar>
Scalar t200_command(const Scalar& force) {
  check_finite(force, "thruster force");
  const double f = value_of(force);
  if (f >= t200_max_thrust) return Scalar(t200_peak_command);
  if (f <= -t200_max_thrust) return Scalar(-t200_peak_command);
  const double target = f < 0 ? -f : f;
  // The curve and its slope as plain polynomials (no checks: x stays in [0, u_peak]).
  const auto curve = [](double u) {
    const double u2 = u * u;
    return u * (8.9 + u2 * (176.0 + u2 * (-404.1 + u2 * (389.9 + u2 * -140.3))));
  };
  const auto slope = [](double u) {
    const double u2 = u * u;
    return 8.9 + u2 * (3 * 176.0 + u2 * (-5 * 404.1 + u2 * (7 * 389.9 + u2 * -9 * 140.3)));
  };
  double lo = 0.0, hi = t200_peak_command;
  double x = t200_peak_command * target / t200_max_thrust;  // chord of the curve
  for (int i = 0; i < 100 && hi - lo > 1e-15; ++i) {
    const double r = curve(x) - target;
    if (r == 0.0) break;
    (r < 0.0 ? lo : hi) = x;
    const double d = slope(x);
    double next = d > 0.0 ? x - r / d : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    const bool done = std::abs(next - x) <= 1e-16;
    x = next;
    if (done) break;
  }
  const double u0 = f < 0 ? -x : x;  // x stays inside the bracket
  const Scalar u(u0);
  return u + (force - t200_thrust(u)) / t200_thrust_slope(u);
}

/// \brief PWM pulse-width ↔ normalised command mapping of a bidirectional ESC.
///
/// Defaults: 1100–1500–1900 µs (ArduSub `MOT_PWM_MIN`/`MOT_PWM_MAX`, ArduPilot
/// Tools/autotest/default_params/sub-6dof.parm) and a ±25 µs
/// deadband around neutral (1475…1525 µs, ArduPilot's SITL submarine, SIM_Submarine.cpp).
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
struct PwmMapping {
  /// Full reverse [µs].
  Scalar min_us = Scalar(1100);
  /// Neutral (stop) [µs].
  Scalar neutral_us = Scalar(1500);
  /// Full forward [µs].
  Scalar max_us = Scalar(1900);
  /// Half-width of the dead band around neutral [µs]; |pwm − neutral| ≤ deadband gives 0.
  Scalar deadband_us = Scalar(25);
};

/// \brief Throws kelp::invalid_argument naming the field unless min < neutral < max and
/// 0 ≤ deadband < min(max − neutral, neutral − min).
template <typename Scalar>
void validate(const PwmMapping<Scalar>& m) {
  check_finite(m.min_us, "min_us");
  check_finite(m.neutral_us, "neutral_us");
  check_finite(m.max_us, "max_us");
  check_non_negative(m.deadband_us, "deadband_us");
  KELP_CHECK(value_of(m.min_us) < value_of(m.neutral_us), "min_us must be < neutral_us");
  KELP_CHECK(value_of(m.neutral_us) < value_of(m.max_us), "max_us must be > neutral_us");
  KELP_CHECK(value_of(m.deadband_us) < value_of(m.max_us) - value_of(m.neutral_us) &&
                 value_of(m.deadband_us) < value_of(m.neutral_us) - value_of(m.min_us),
             "deadband_us must be smaller than both PWM half-ranges");
}

/// \brief Normalised command u ∈ [−1, 1] of a pulse width [µs]: 0 inside the dead band, else
/// (pwm − neutral)/(max − neutral) above neutral and (pwm − neutral)/(neutral − min) below,
/// clamped (as ArduPilot's SITL submarine does: no rescaling of the dead band).
/// \throws kelp::invalid_argument when the pulse width is not finite or `m` is invalid (see
/// `validate(const PwmMapping&)`).
template <typename Scalar>
Scalar command_from_pwm(const Scalar& pwm_us, const PwmMapping<Scalar>& m = PwmMapping<Scalar>()) {
  check_finite(pwm_us, "pwm");
  validate(m);
  const Scalar d = pwm_us - m.neutral_us;
  const double dv = value_of(d);
  if (dv <= value_of(m.deadband_us) && dv >= -value_of(m.deadband_us)) return Scalar(0);
  Scalar u = dv > 0 ? d / (m.max_us - m.neutral_us) : d / (m.neutral_us - m.min_us);
  if (value_of(u) > 1.0) u = Scalar(1);
  if (value_of(u) < -1.0) u = Scalar(-1);
  return u;
}

/// \brief Pulse width [µs] for a normalised command u (clamped to [−1, 1]):
/// neutral + u (max − neutral) for u > 0, neutral + u (neutral − min) otherwise (ArduSub's
/// `AP_Motors6DOF::calc_thrust_to_pwm`, ArduPilot libraries/AP_Motors/AP_Motors6DOF.cpp). The dead
/// band is not skipped.
/// \throws kelp::invalid_argument when u is not finite or `m` is invalid (see
/// `validate(const PwmMapping&)`).
template <typename Scalar>
Scalar pwm_from_command(const Scalar& u_in, const PwmMapping<Scalar>& m = PwmMapping<Scalar>()) {
  check_finite(u_in, "thruster command u");
  validate(m);
  Scalar u = u_in;
  if (value_of(u) > 1.0) u = Scalar(1);
  if (value_of(u) < -1.0) u = Scalar(-1);
  return value_of(u) > 0 ? m.neutral_us + u * (m.max_us - m.neutral_us)
                         : m.neutral_us + u * (m.neutral_us - m.min_us);
}

/// \brief Thruster allocation in double precision.
using ThrusterAllocationd = ThrusterAllocation<double>;
/// \brief Thruster allocation in single precision.
using ThrusterAllocationf = ThrusterAllocation<float>;
/// \brief PWM mapping in double precision.
using PwmMappingd = PwmMapping<double>;
/// \brief PWM mapping in single precision.
using PwmMappingf = PwmMapping<float>;

}  // namespace kelp::vehicle
