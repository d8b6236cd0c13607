/// \file
/// \brief Thrusters: the allocation matrix from thruster positions and directions, a thruster
/// model (its static thrust curve, written once: the Blue Robotics T200 from its data by default,
/// the von Benzon polynomial for comparison) and its inverse, a thruster's facing,
/// the PWM ↔ normalised command mapping, and the chain PWM → command → thrust → wrench.
#pragma once

#include <Eigen/Core>
#include <Eigen/QR>
#include <cmath>
#include <string>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/vehicle/t200.hpp"

namespace kelp::vehicle {

/// \brief Thrust-allocation matrix B (6×n): column i is (d_i, r_i × d_i), the wrench about the
/// CO of a unit thrust along d_i applied at r_i (Fossen 2021, control-allocation chapter: τ = T f).
/// \param[in] positions r_i [m], 3×n, body axes relative to the CO.
/// \param[in] directions d_i, 3×n, body axes; normalised here (thrust of a positive command).
/// \throws kelp::invalid_argument naming `thruster_positions` or `thruster_directions` (wrong
/// shape, not finite, a zero direction), or when a moment r_i × d_i overflows.
/// \tparam DP, DD Eigen matrix expressions (3×n) of the same scalar.
/// \return B, 6×n [-, m]: forces in its top three rows, moments about the CO in the bottom three.
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

namespace detail {
/// B⁺ (n×6) of a 6×n allocation matrix by a complete orthogonal decomposition (valid for any
/// rank); returns the rank of B. A function of its own, not inline, so that a program that links
/// an explicit instantiation (KELP_VEHICLE_INSTANCES, kelp/vehicle/instances.hpp) and declares
/// it extern does not compile the decomposition again: it is the heaviest code a vehicle's
/// construction instantiates.
template <typename Scalar>
Eigen::Index pseudo_inverse(const Eigen::Matrix<Scalar, 6, Eigen::Dynamic>& b,
                            Eigen::Matrix<Scalar, Eigen::Dynamic, 6>& b_plus) {
  const Eigen::CompleteOrthogonalDecomposition<Eigen::Matrix<Scalar, 6, Eigen::Dynamic>> cod(b);
  b_plus = cod.pseudoInverse();
  return cod.rank();
}
}  // namespace detail

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
    rank_ = detail::pseudo_inverse(matrix_, pseudo_inverse_);
    check_all_finite(pseudo_inverse_, "thruster_positions: the pseudo-inverse of the allocation");
  }

  /// \brief Number of thrusters n.
  /// \return n ≥ 1.
  Eigen::Index size() const { return matrix_.cols(); }
  /// \brief Rank of B (6 for a fully actuated vehicle).
  /// \return The numerical rank of B, 0 … min(6, n).
  Eigen::Index rank() const { return rank_; }
  /// \brief r_i [m], 3×n, body.
  /// \return The positions, as given.
  const Matrix3X<Scalar>& positions() const { return positions_; }
  /// \brief Unit d_i, 3×n, body.
  /// \return The normalised directions.
  const Matrix3X<Scalar>& directions() const { return directions_; }
  /// \brief B, 6×n.
  /// \return The allocation matrix (see allocation_matrix()).
  const Eigen::Matrix<Scalar, 6, Eigen::Dynamic>& matrix() const { return matrix_; }
  /// \brief B⁺, n×6.
  /// \return The Moore–Penrose pseudo-inverse of B.
  const Eigen::Matrix<Scalar, Eigen::Dynamic, 6>& pseudo_inverse() const { return pseudo_inverse_; }

  /// \brief Body wrench τ = B f [N, N m] of the thruster forces f [N] (n-vector).
  /// \tparam Derived Any Eigen vector expression with n entries.
  /// \param forces Thrust of each thruster along its direction d_i [N].
  /// \return τ [N, N m], body axes about the CO.
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
  /// \tparam DW, DF Eigen vector expressions (6 and n entries).
  /// \param tau Desired wrench [N, N m], body axes about the CO.
  /// \param[out] forces Thrust per thruster along d_i [N] (n entries, not resized).
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

/// \brief Which static curve a ThrusterModel stands for.
enum class ThrusterCurve {
  /// Blue Robotics T200 from its published data, asymmetric and voltage dependent
  /// (kelp/vehicle/t200.hpp: t200_thrust(), t200_command()); the polynomial fields are unused.
  t200_datasheet,
  /// The odd polynomial of ThrusterModel's coefficients (symmetric, no voltage).
  odd_polynomial,
};

/// \brief The static thrust curve of one thruster model, written once: either the T200
/// datasheet fit (the default, t200_model) or an odd polynomial F(u) = Σₖ cₖ u^(2k+1) of the
/// normalised command u ∈ [−1, 1] (clamped), with the command at which it peaks on [0, 1] and
/// that peak (von_benzon_t200_model). The thrust, its slope and its inverse (thrust(),
/// thrust_slope(), command_for_thrust()) and the chain PWM → command → thrust → wrench
/// (ThrusterChain) all read it.
struct ThrusterModel {
  /// Number of odd coefficients.
  static constexpr int order = 5;
  /// The curve.
  ThrusterCurve curve = ThrusterCurve::odd_polynomial;
  /// c₀ … c₄ [N]: the coefficients of u, u³, u⁵, u⁷, u⁹ (odd_polynomial only).
  double odd_coefficients[order] = {0, 0, 0, 0, 0};
  /// u_peak ∈ (0, 1]: F rises monotonically on [0, u_peak] (the inverse's branch; polynomial).
  double peak_command = 1.0;
  /// F(u_peak) [N], rounded down (the largest thrust the inverse delivers; polynomial).
  double max_thrust = 0.0;
};

/// \brief Blue Robotics T200 from its published performance data, forward/reverse asymmetric
/// and voltage dependent (t200_thrust(), kelp/vehicle/t200.hpp): the default thruster model.
inline constexpr ThrusterModel t200_model{ThrusterCurve::t200_datasheet};

/// \brief The T200 curve of von Benzon et al. 2022 (J. Mar. Sci. Eng. 10(12):1898), kept for
/// comparison: F(u) = −140.3u⁹ + 389.9u⁷ − 404.1u⁵ + 176.0u³ + 8.9u, F(1) ≈ 30.4 N, odd (reverse
/// = forward) and independent of the voltage. It rises monotonically on [0, 0.971656] to
/// 30.62 N and then falls slightly to 30.40 N at u = 1 (root of dF/du at 0.97165617, found by
/// bisection in double and rounded down; F(u_peak) = 30.621753 N rounded down; the unit test
/// re-checks both). The datasheet fit gives 51.6 N forward and 39.8 N reverse at 16 V
/// (t200_model).
inline constexpr ThrusterModel von_benzon_t200_model{
    ThrusterCurve::odd_polynomial, {8.9, 176.0, -404.1, 389.9, -140.3}, 0.971656, 30.62175};

/// \brief Command at which the von Benzon curve peaks (`von_benzon_t200_model.peak_command`).
inline constexpr double von_benzon_t200_peak_command = von_benzon_t200_model.peak_command;
/// \brief Largest thrust of the von Benzon curve [N] (`von_benzon_t200_model.max_thrust`).
inline constexpr double von_benzon_t200_max_thrust = von_benzon_t200_model.max_thrust;

/// \brief Checks a thruster model: its curve is a ThrusterCurve value and, for the odd polynomial
/// (the datasheet curve does not read the polynomial's fields), peak_command in (0, 1],
/// max_thrust finite and > 0 and every coefficient finite. The free functions that take a model
/// (thrust(), thrust_slope(), max_forward_thrust(), max_reverse_thrust(),
/// command_for_thrust(), thrust_from_pwm()) call it; ThrusterChain calls it once, when built.
/// \param m the model.
/// \throws kelp::invalid_argument naming the field.
inline void validate(const ThrusterModel& m) {
  KELP_CHECK(m.curve == ThrusterCurve::t200_datasheet || m.curve == ThrusterCurve::odd_polynomial,
             "ThrusterModel: curve must be ThrusterCurve::t200_datasheet or "
             "ThrusterCurve::odd_polynomial");
  if (m.curve != ThrusterCurve::odd_polynomial) return;
  KELP_CHECK(m.peak_command > 0.0 && m.peak_command <= 1.0,
             "ThrusterModel: peak_command must be in (0, 1]");
  check_positive(m.max_thrust, "ThrusterModel: max_thrust");
  for (double c : m.odd_coefficients) check_finite(c, "ThrusterModel: odd_coefficients");
}

namespace detail {
/// F(u) and dF/du of an odd polynomial, u unclamped: with P(x) = Σ cₖ xᵏ and x = u², F = u P(x)
/// and F' = P(x) + 2x P'(x); P and P' by one Horner pass (the coefficients are written once).
template <typename Scalar>
void thrust_polynomial(const ThrusterModel& m, const Scalar& u, Scalar& f, Scalar* slope) {
  const Scalar x = u * u;
  Scalar p(m.odd_coefficients[ThrusterModel::order - 1]);
  Scalar dp(0);
  for (int k = ThrusterModel::order - 2; k >= 0; --k) {
    if (slope != nullptr) dp = dp * x + p;
    p = p * x + Scalar(m.odd_coefficients[k]);
  }
  f = u * p;
  if (slope != nullptr) *slope = p + Scalar(2) * x * dp;
}

/// thrust() of a model already validated (ThrusterChain's, checked once when it was built).
template <typename Scalar>
Scalar model_thrust(const ThrusterModel& m, const Scalar& u_in, const Scalar& voltage) {
  if (m.curve == ThrusterCurve::t200_datasheet) return t200_thrust(u_in, voltage);
  check_finite(u_in, "thruster command u");
  Scalar u = u_in;
  if (value_of(u) > 1.0) u = Scalar(1);
  if (value_of(u) < -1.0) u = Scalar(-1);
  // The value alone (the hot path of every thruster evaluation): Horner in u².
  const Scalar x = u * u;
  Scalar p(m.odd_coefficients[ThrusterModel::order - 1]);
  for (int k = ThrusterModel::order - 2; k >= 0; --k) p = p * x + Scalar(m.odd_coefficients[k]);
  return u * p;
}

/// thrust_slope() of a model already validated.
template <typename Scalar>
Scalar model_thrust_slope(const ThrusterModel& m, const Scalar& u, const Scalar& voltage) {
  if (m.curve == ThrusterCurve::t200_datasheet) return t200_thrust_slope(u, voltage);
  check_finite(u, "thruster command u");
  if (value_of(u) > 1.0 || value_of(u) < -1.0) return Scalar(0);
  Scalar f, d;
  thrust_polynomial<Scalar>(m, u, f, &d);
  return d;
}
}  // namespace detail

/// \brief Static thrust F(u) [N] of thruster model `m` for a normalised command u (clamped to
/// [−1, 1]) at a supply voltage [V] (used by the datasheet curve only; positive: thrust along
/// the thruster's forward axis).
/// \throws kelp::invalid_argument when `m` is invalid (`validate(const ThrusterModel&)`), naming
/// the command when u is not finite, or (datasheet) the voltage when it is not finite or outside
/// [0, 20] V.
/// \tparam Scalar double, float or ceres::Jet.
/// \param m Thruster model.
/// \param u_in Normalised command u [-].
/// \param voltage Supply voltage [V] (default t200_nominal_voltage, 16 V).
/// \return F(u) [N].
template <typename Scalar>
Scalar thrust(const ThrusterModel& m, const Scalar& u_in,
              const Scalar& voltage = Scalar(t200_nominal_voltage)) {
  validate(m);
  return detail::model_thrust(m, u_in, voltage);
}

/// \brief dF/du [N] of thrust() (same clamping: 0 outside [−1, 1]).
/// \tparam Scalar double, float or ceres::Jet.
/// \param m Thruster model.
/// \param u Normalised command u [-].
/// \param voltage Supply voltage [V] (datasheet curve only; default 16 V).
/// \return dF/du [N per unit command].
/// \throws kelp::invalid_argument as thrust().
template <typename Scalar>
Scalar thrust_slope(const ThrusterModel& m, const Scalar& u,
                    const Scalar& voltage = Scalar(t200_nominal_voltage)) {
  validate(m);
  return detail::model_thrust_slope(m, u, voltage);
}

/// \brief Largest thrust [N] along the thruster's forward axis that model `m` delivers at a
/// voltage [V] (datasheet: t200_max_thrust(); polynomial: max_thrust).
/// \tparam Scalar double, float or ceres::Jet.
/// \param m Thruster model.
/// \param voltage Supply voltage [V] (datasheet curve only; default 16 V).
/// \return The thrust [N].
/// \throws kelp::invalid_argument when `m` is invalid (`validate(const ThrusterModel&)`), or
/// (datasheet) for a voltage outside [0, 20] V.
template <typename Scalar>
Scalar max_forward_thrust(const ThrusterModel& m,
                          const Scalar& voltage = Scalar(t200_nominal_voltage)) {
  validate(m);
  if (m.curve == ThrusterCurve::t200_datasheet) return t200_max_thrust(voltage);
  return Scalar(m.max_thrust);
}

/// \brief Largest reverse thrust [N] (a positive magnitude) of model `m` at a voltage [V]
/// (datasheet: t200_max_reverse_thrust(); polynomial: max_thrust, the curve being odd).
/// \tparam Scalar double, float or ceres::Jet.
/// \param m Thruster model.
/// \param voltage Supply voltage [V] (datasheet curve only; default 16 V).
/// \return The magnitude [N].
/// \throws kelp::invalid_argument when `m` is invalid (`validate(const ThrusterModel&)`), or
/// (datasheet) for a voltage outside [0, 20] V.
template <typename Scalar>
Scalar max_reverse_thrust(const ThrusterModel& m,
                          const Scalar& voltage = Scalar(t200_nominal_voltage)) {
  validate(m);
  if (m.curve == ThrusterCurve::t200_datasheet) return t200_max_reverse_thrust(voltage);
  return Scalar(m.max_thrust);
}

namespace detail {
/// command_for_thrust() of a model already validated (ThrusterChain's).
template <typename Scalar>
Scalar model_command(const ThrusterModel& m, const Scalar& force, const Scalar& voltage) {
  if (m.curve == ThrusterCurve::t200_datasheet) return t200_command(force, voltage);
  check_finite(force, "thruster force");
  const double f = value_of(force);
  if (f >= m.max_thrust) return Scalar(m.peak_command);
  if (f <= -m.max_thrust) return Scalar(-m.peak_command);
  const double target = f < 0 ? -f : f;
  double lo = 0.0, hi = m.peak_command;
  double x = m.peak_command * target / m.max_thrust;  // chord of the curve
  for (int i = 0; i < 100 && hi - lo > 1e-15; ++i) {
    double value = 0.0, d = 0.0;  // x stays in [0, u_peak]: no clamping, no checks
    detail::thrust_polynomial<double>(m, x, value, &d);
    const double r = value - target;
    if (r == 0.0) break;
    (r < 0.0 ? lo : hi) = x;
    double next = d > 0.0 ? x - r / d : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    const bool done = std::abs(next - x) <= 1e-16;
    x = next;
    if (done) break;
  }
  const double u0 = f < 0 ? -x : x;  // x stays inside the bracket
  const Scalar u(u0);
  const Scalar v(t200_nominal_voltage);  // unused by the polynomial
  return u + (force - model_thrust(m, u, v)) / model_thrust_slope(m, u, v);
}
}  // namespace detail

/// \brief Inverse of the curve on its monotone branch: the command u with
/// thrust(m, u, V) = force. Datasheet: t200_command() (saturates at u = ±1 beyond the largest
/// forward / reverse thrust at that voltage). Polynomial: u ∈ [−u_peak, u_peak], forces beyond
/// ±max_thrust saturate at ±u_peak; Newton's method safeguarded by bisection on the value (the
/// bracket shrinks at every step; a Newton step that leaves it is replaced by the midpoint; 5–8
/// iterations instead of 60 bisections), then one Newton correction in Scalar so that
/// ceres::Jet derivatives follow the implicit-function theorem (du/dF = 1/F'(u)).
/// \param[in] m thruster model \param[in] force desired thrust [N] along the forward axis.
/// \param[in] voltage supply voltage [V] (datasheet only).
/// \tparam Scalar double, float or ceres::Jet.
/// \return u [-] (|u| ≤ u_peak for the polynomial, ≤ 1 for the datasheet curve).
/// \throws kelp::invalid_argument when `m` is invalid (`validate(const ThrusterModel&)`), naming
/// the force when it is not finite, or (datasheet) the voltage.
template <typename Scalar>
Scalar command_for_thrust(const ThrusterModel& m, const Scalar& force,
                          const Scalar& voltage = Scalar(t200_nominal_voltage)) {
  validate(m);
  return detail::model_command(m, force, voltage);
}

/// \brief T200 thrust [N] at the nominal supply voltage (t200_nominal_voltage, 16 V):
/// t200_thrust(u, 16 V).
/// \param[in] u normalised command (clamped to [−1, 1]).
/// \tparam Scalar double, float or ceres::Jet.
/// \return Thrust [N] at 16 V.
/// \throws kelp::invalid_argument naming the command when u is not finite.
template <typename Scalar>
Scalar t200_thrust(const Scalar& u) {
  return t200_thrust(u, Scalar(t200_nominal_voltage));
}

/// \brief dF/du of t200_thrust(u) [N] at the nominal voltage (0 outside [−1, 1] and in the
/// dead band).
/// \tparam Scalar double, float or ceres::Jet.
/// \param u Normalised command u [-].
/// \return dF/du [N per unit command] at 16 V.
/// \throws kelp::invalid_argument naming the command when u is not finite.
template <typename Scalar>
Scalar t200_thrust_slope(const Scalar& u) {
  return t200_thrust_slope(u, Scalar(t200_nominal_voltage));
}

/// \brief Inverse of t200_thrust(u) at the nominal voltage: t200_command(force, 16 V).
/// \param[in] force desired thrust [N] along the thruster's forward axis.
/// \tparam Scalar double, float or ceres::Jet.
/// \return u ∈ [−1, 1] [-].
/// \throws kelp::invalid_argument naming the force when it is not finite.
template <typename Scalar>
Scalar t200_command(const Scalar& force) {
  return t200_command(force, Scalar(t200_nominal_voltage));
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
/// \param m PWM mapping [µs] (all values finite).
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
/// \tparam Scalar double, float or ceres::Jet.
/// \param pwm_us Pulse width [µs].
/// \param m PWM mapping (default 1100–1500–1900 µs, ±25 µs dead band).
/// \return u ∈ [−1, 1] [-].
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
/// \tparam Scalar double, float or ceres::Jet.
/// \param u_in Normalised command u [-].
/// \param m PWM mapping (default 1100–1500–1900 µs).
/// \return Pulse width [µs], in [min_us, max_us].
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

/// \brief Thrust [N] of a pulse width [µs] through the chain's first two links: the command
/// u = command_from_pwm(pwm, pwm_map) (dead band, clamped) and the curve thrust(m, u, V).
/// \param[in] m thruster model \param[in] pwm_us pulse width [µs]
/// \param[in] pwm_map the ESC's PWM mapping
/// \param[out] command u, if not null. \param[in] voltage supply voltage [V] (datasheet curve).
/// \tparam Scalar double, float or ceres::Jet.
/// \return Thrust [N] along the thruster's forward axis.
/// \throws kelp::invalid_argument when the pulse width is not finite, `pwm_map` is invalid or
/// the voltage is out of range.
template <typename Scalar>
Scalar thrust_from_pwm(const ThrusterModel& m, const Scalar& pwm_us,
                       const PwmMapping<Scalar>& pwm_map, Scalar* command = nullptr,
                       const Scalar& voltage = Scalar(t200_nominal_voltage)) {
  const Scalar u = command_from_pwm(pwm_us, pwm_map);
  if (command != nullptr) *command = u;
  return thrust(m, u, voltage);
}

/// \brief The whole thruster chain of a vehicle, in one place: PWM pulse width → normalised
/// command (PwmMapping, dead band) → thrust (ThrusterModel's curve at the supply voltage, with
/// each thruster's facing) → body wrench (the ThrusterAllocation). Controllers go the other way
/// for their output (desired force → command → the thrust it really delivers) and the SITL
/// bridge goes the whole way from the autopilot's PWM: both call it, so a new thruster curve is
/// one ThrusterModel. Allocation-free after construction.
///
/// Facing: thruster i's thrust along its direction d_i for a command u is
/// sᵢ F(sᵢ u, V) with sᵢ = facing(i) = ±1: +1 when a positive command gives the thruster's
/// forward (stronger) thrust along d_i, −1 when it gives its reverse thrust (a thruster mounted
/// the other way round, e.g. with the opposite propeller and its output reversed).
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
class ThrusterChain {
 public:
  /// \brief Builds the chain (copies its parts) and sets the voltage.
  /// \param[in] allocation the thruster set \param[in] model the thrusters' curve (all alike)
  /// \param[in] pwm the ESCs' PWM mapping
  /// \param[in] facing ±1 per thruster (see the class); empty: all +1.
  /// \param[in] voltage supply voltage [V] (set_voltage()).
  /// \throws kelp::invalid_argument when `pwm` is invalid (see `validate(const PwmMapping&)`),
  /// `model` is invalid (see `validate(const ThrusterModel&)`: the chain's thrusts and commands
  /// then need no further check of it), `facing` has a wrong size or an entry other than ±1, or
  /// the voltage is invalid.
  explicit ThrusterChain(const ThrusterAllocation<Scalar>& allocation,
                         const ThrusterModel& model = t200_model,
                         const PwmMapping<Scalar>& pwm = PwmMapping<Scalar>(),
                         const Eigen::VectorXd& facing = Eigen::VectorXd(),
                         double voltage = t200_nominal_voltage)
      : allocation_(allocation), model_(model), pwm_(pwm) {
    validate(pwm_);
    validate(model);
    if (facing.size() == 0) {
      facing_ = Eigen::VectorXd::Ones(allocation_.size());
    } else {
      KELP_CHECK(facing.size() == allocation_.size(),
                 "thruster_facing must have one entry per thruster");
      for (Eigen::Index i = 0; i < facing.size(); ++i)
        KELP_CHECK(facing(i) == 1.0 || facing(i) == -1.0,
                   "thruster_facing entries must be +1 or -1");
      facing_ = facing;
    }
    if (model.curve == ThrusterCurve::t200_datasheet) {
      // The datasheet's command is the ESC's: u = (pwm − 1500 µs)/400 µs, full at 1100 / 1900.
      esc_up_ = value_of(pwm_.max_us - pwm_.neutral_us) / t200_esc_half_range_us;
      esc_down_ = value_of(pwm_.neutral_us - pwm_.min_us) / t200_esc_half_range_us;
    }
    set_voltage(voltage);
  }

  /// \brief Number of thrusters.
  /// \return n.
  Eigen::Index size() const { return allocation_.size(); }
  /// \brief The allocation.
  /// \return The thruster set (a copy held by the chain).
  const ThrusterAllocation<Scalar>& allocation() const { return allocation_; }
  /// \brief The thruster model.
  /// \return The curve every thruster uses.
  const ThrusterModel& model() const { return model_; }
  /// \brief The PWM mapping.
  /// \return The ESCs' mapping.
  const PwmMapping<Scalar>& pwm() const { return pwm_; }
  /// \brief ±1 per thruster (see the class).
  /// \return n entries, each +1 or −1.
  const Eigen::VectorXd& facing() const { return facing_; }

  /// \brief Sets the supply voltage [V] at the ESCs that every thrust and command of the chain
  /// uses from now on (the datasheet curve; the polynomial ignores it). Default
  /// t200_nominal_voltage (16 V).
  /// \throws kelp::invalid_argument when it is not finite or outside [0, 20] V (the chain is
  /// left unchanged).
  /// \param volts Supply voltage [V], in [0, 20].
  void set_voltage(double volts) {
    detail::t200_check_voltage(volts);
    voltage_ = volts;
    const Scalar v(volts);
    max_forward_ = value_of(max_forward_thrust(model_, v));
    max_reverse_ = value_of(max_reverse_thrust(model_, v));
  }
  /// \brief The supply voltage [V].
  /// \return The voltage set last [V].
  double voltage() const { return voltage_; }

  /// \brief Largest thrust [N] thruster i delivers along +d_i at the current voltage.
  /// \param i Thruster index in [0, n) (not checked).
  /// \return The thrust [N] (forward or reverse maximum, by its facing).
  double max_positive_thrust(Eigen::Index i) const {
    return facing_(i) > 0 ? max_forward_ : max_reverse_;
  }
  /// \brief Largest thrust [N] (a magnitude) thruster i delivers along −d_i.
  /// \param i Thruster index in [0, n) (not checked).
  /// \return The magnitude [N].
  double max_negative_thrust(Eigen::Index i) const {
    return facing_(i) > 0 ? max_reverse_ : max_forward_;
  }

  /// \brief Normalised command of a pulse width [µs] (command_from_pwm()).
  /// \param pwm_us Pulse width [µs].
  /// \return u ∈ [−1, 1] [-] of this chain's PWM mapping.
  /// \throws kelp::invalid_argument when the pulse width is not finite.
  Scalar command_from_pwm(const Scalar& pwm_us) const {
    return vehicle::command_from_pwm(pwm_us, pwm_);
  }
  /// \brief Thrust [N] of thruster i along d_i for a normalised command u (of this chain's PWM
  /// mapping): facing · thrust(facing · u_esc, V). For the datasheet curve u_esc is the ESC's
  /// command, u scaled to the ESC's 1100–1900 µs and clamped (e.g. the BlueBoat's 1000–2000 µs
  /// mapping: u_esc = 1.25 u, full thrust from 1900 µs on); for a polynomial u_esc = u.
  /// \param i Thruster index in [0, n) (not checked).
  /// \param u Normalised command [-].
  /// \return Thrust along d_i [N].
  /// \throws kelp::invalid_argument when u is not finite.
  Scalar thrust_of_command(Eigen::Index i, const Scalar& u) const {
    const Scalar s(facing_(i));
    return s * detail::model_thrust(model_, Scalar(s * esc_command(u)), Scalar(voltage_));
  }
  /// \brief Thrust [N] of thruster i along d_i for a pulse width [µs].
  /// \param[in] i thruster index in [0, n) (not checked) \param[in] pwm_us pulse width [µs]
  /// \param[out] command the normalised command, if not null.
  /// \return Thrust along d_i [N].
  /// \throws kelp::invalid_argument when the pulse width is not finite.
  Scalar thrust_of_pwm(Eigen::Index i, const Scalar& pwm_us, Scalar* command = nullptr) const {
    const Scalar u = command_from_pwm(pwm_us);
    if (command != nullptr) *command = u;
    return thrust_of_command(i, u);
  }
  /// \brief Command of thruster i for a desired thrust [N] along d_i: the inverse of
  /// thrust_of_command(), facing · command_for_thrust(facing · force, V) taken back from the
  /// ESC's command to the chain's (saturates at the largest thrust that way, |u| ≤ 1).
  /// \param i Thruster index in [0, n) (not checked).
  /// \param force Desired thrust along d_i [N].
  /// \return u ∈ [−1, 1] [-].
  /// \throws kelp::invalid_argument when the force is not finite.
  Scalar command_for(Eigen::Index i, const Scalar& force) const {
    const Scalar s(facing_(i));
    const Scalar ue = s * detail::model_command(model_, Scalar(s * force), Scalar(voltage_));
    Scalar u = value_of(ue) > 0.0 ? Scalar(ue / Scalar(esc_up_)) : Scalar(ue / Scalar(esc_down_));
    if (value_of(u) > 1.0) u = Scalar(1);
    if (value_of(u) < -1.0) u = Scalar(-1);
    return u;
  }

  /// \brief For desired per-thruster forces [N]: the commands and the thrust they deliver
  /// (saturated on the curve's monotone branch). All three have one entry per thruster.
  /// \throws kelp::invalid_argument for a wrong size or a non-finite force.
  /// \param[in] forces desired thrust per thruster along d_i [N]
  /// \param[out] commands u per thruster [-] \param[out] delivered thrust per thruster [N]
  template <typename DF, typename DC, typename DT>
  void commands_for(const Eigen::MatrixBase<DF>& forces, Eigen::MatrixBase<DC>& commands,
                    Eigen::MatrixBase<DT>& delivered) const {
    KELP_CHECK(forces.size() == size() && commands.size() == size() && delivered.size() == size(),
               "ThrusterChain: forces, commands and thrust need one entry per thruster");
    for (Eigen::Index i = 0; i < size(); ++i) {
      commands(i) = command_for(i, forces(i));
      delivered(i) = thrust_of_command(i, commands(i));
    }
  }

  /// \brief Body wrench [N, N m] of normalised commands: B F(u); `thrusts` receives F(u) [N].
  /// \throws kelp::invalid_argument for a wrong size or a non-finite command.
  /// \param[in] commands u per thruster [-] \param[out] thrusts F(u) per thruster [N]
  /// \return B F(u) [N, N m], body axes about the CO.
  template <typename DC, typename DT>
  Vector6<Scalar> wrench_from_commands(const Eigen::MatrixBase<DC>& commands,
                                       Eigen::MatrixBase<DT>& thrusts) const {
    KELP_CHECK(commands.size() == size() && thrusts.size() == size(),
               "ThrusterChain: commands and thrust need one entry per thruster");
    for (Eigen::Index i = 0; i < size(); ++i) thrusts(i) = thrust_of_command(i, commands(i));
    return allocation_.wrench(thrusts);
  }

  /// \brief Body wrench [N, N m] of pulse widths [µs]: B F(u(pwm)); `commands` and `thrusts`
  /// receive u and F(u).
  /// \throws kelp::invalid_argument for a wrong size or a non-finite pulse width.
  /// \param[in] pwm_us pulse width per thruster [µs] \param[out] commands u per thruster [-]
  /// \param[out] thrusts F(u) per thruster [N]
  /// \return B F(u) [N, N m], body axes about the CO.
  template <typename DP, typename DC, typename DT>
  Vector6<Scalar> wrench_from_pwm(const Eigen::MatrixBase<DP>& pwm_us,
                                  Eigen::MatrixBase<DC>& commands,
                                  Eigen::MatrixBase<DT>& thrusts) const {
    KELP_CHECK(pwm_us.size() == size() && commands.size() == size() && thrusts.size() == size(),
               "ThrusterChain: pwm, commands and thrust need one entry per thruster");
    for (Eigen::Index i = 0; i < size(); ++i) commands(i) = command_from_pwm(pwm_us(i));
    return wrench_from_commands(commands, thrusts);
  }

  /// \brief Body wrench [N, N m] of thrusts [N] (the allocation's wrench()).
  /// \param thrusts Thrust per thruster along d_i [N].
  /// \return B f [N, N m], body axes about the CO.
  /// \throws kelp::invalid_argument as ThrusterAllocation::wrench().
  template <typename DT>
  Vector6<Scalar> wrench(const Eigen::MatrixBase<DT>& thrusts) const {
    return allocation_.wrench(thrusts);
  }

 private:
  ThrusterAllocation<Scalar> allocation_;
  ThrusterModel model_;
  PwmMapping<Scalar> pwm_;
  /// The ESC's command of the chain's: u_esc = u · esc_up_ (u > 0) or u · esc_down_, clamped.
  Scalar esc_command(const Scalar& u) const {
    check_finite(u, "thruster command u");
    Scalar ue = value_of(u) > 0.0 ? Scalar(u * Scalar(esc_up_)) : Scalar(u * Scalar(esc_down_));
    if (value_of(ue) > 1.0) ue = Scalar(1);
    if (value_of(ue) < -1.0) ue = Scalar(-1);
    return ue;
  }

  Eigen::VectorXd facing_;
  double esc_up_ = 1.0, esc_down_ = 1.0;
  double voltage_ = t200_nominal_voltage;
  double max_forward_ = 0.0, max_reverse_ = 0.0;
};

/// \brief Thruster allocation in double precision.
using ThrusterAllocationd = ThrusterAllocation<double>;
/// \brief Thruster allocation in single precision.
using ThrusterAllocationf = ThrusterAllocation<float>;
/// \brief PWM mapping in double precision.
using PwmMappingd = PwmMapping<double>;
/// \brief PWM mapping in single precision.
using PwmMappingf = PwmMapping<float>;
/// \brief Thruster chain in double precision.
using ThrusterChaind = ThrusterChain<double>;
/// \brief Thruster chain in single precision.
using ThrusterChainf = ThrusterChain<float>;

}  // namespace kelp::vehicle
