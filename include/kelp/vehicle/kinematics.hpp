/// \file
/// \brief Vehicle kinematics η̇ = J(η) ν with a unit quaternion (Fossen 2021, §2.2.2) or
/// with zyx Euler angles (Fossen 2021, eq. 2.53).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include "kelp/core/rotation.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/vehicle/state.hpp"

namespace kelp::vehicle {

/// \brief Time derivative of a VehicleState's pose: NED velocity ṗ = R(q) ν₁ [m/s] and quaternion
/// rate q̇ = ½ q ⊗ (0, ν₂) stored in Eigen's coefficient order (x, y, z, w).
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
struct PoseRate {
  /// ṗ: NED velocity of the CO [m/s].
  Vector3<Scalar> position_dot = Vector3<Scalar>::Zero();
  /// q̇ in Eigen's `coeffs()` order (x, y, z, w) [1/s].
  Eigen::Matrix<Scalar, 4, 1> attitude_dot = Eigen::Matrix<Scalar, 4, 1>::Zero();
};

/// \brief Quaternion kinematics: ṗ = R(q) ν₁, q̇ = ½ q ⊗ (0, ν₂) (Fossen 2021, §2.2.2).
/// \param[in] attitude unit quaternion body → NED. \param[in] nu ν = (u, v, w, p, q, r)
/// [m/s, rad/s], body axes.
/// \return ṗ (NED [m/s]) and q̇ (coeffs() order [1/s]).
template <typename Scalar, typename Derived>
PoseRate<Scalar> pose_rate(const Quaternion<Scalar>& attitude,
                           const Eigen::MatrixBase<Derived>& nu) {
  PoseRate<Scalar> out;
  out.position_dot = attitude * Vector3<Scalar>(nu.template head<3>());
  out.attitude_dot = quaternion_rate(attitude, nu.template tail<3>());
  return out;
}

/// \brief Renormalises a quaternion to unit length in place (integrators call this after every
/// step; the quaternion ODE preserves the norm only in exact arithmetic).
///
/// q / √(q·q), with q·q taken on q / max|q_i| when q·q itself leaves the normal range of the
/// scalar (overflows to +Inf for coefficients beyond ~1e154 in double, ~1e19 in float, or
/// underflows below ~1e-154 / ~1e-19): q / √(q·q) would then give the zero quaternion or leave q
/// as it is (the fuzz finding `vehicle_step_non_unit_attitude`). The rescaling divides by a
/// constant, so for `ceres::Jet` the derivatives are those of q / ‖q‖ too; a quaternion whose
/// squared norm is normal is divided by √(q·q) exactly as before.
/// \throws nothing; a zero or non-finite quaternion is left as it is (the integrators refuse a
/// step that ends with one: kelp::numerical_error, state unchanged).
/// \param q the quaternion, normalised in place.
template <typename Scalar>
void renormalize(Quaternion<Scalar>& q) {
  using std::sqrt;
  using Value = std::conditional_t<std::is_same_v<Scalar, float>, float, double>;
  Scalar n2 = q.coeffs().squaredNorm();
  const double v = value_of(n2);
  if (!(v >= static_cast<double>(std::numeric_limits<Value>::min()) &&
        v <= static_cast<double>(std::numeric_limits<Value>::max()))) {
    double largest = 0.0;
    for (int i = 0; i < 4; ++i) largest = std::max(largest, std::abs(value_of(q.coeffs()(i))));
    if (!(largest > 0.0 && largest <= static_cast<double>(std::numeric_limits<Value>::max())))
      return;  // zero, NaN or Inf: nothing to scale
    q.coeffs() /= Scalar(static_cast<Value>(largest));
    n2 = q.coeffs().squaredNorm();  // in [1, 4]
  }
  q.coeffs() /= sqrt(n2);
}

/// \brief Euler-angle kinematics η̇ = J_Θ(η) ν with η = (x, y, z, φ, θ, ψ) (Fossen 2021, eq. 2.53).
/// Singular at θ = ±90°; use pose_rate() with a quaternion there.
/// \param[in] eta η: NED position [m] and zyx Euler angles [rad].
/// \param[in] nu ν [m/s, rad/s], body axes.
/// \return η̇ [m/s, rad/s].
template <typename DerivedEta, typename DerivedNu>
Vector6<typename DerivedEta::Scalar> eta_rate_euler(const Eigen::MatrixBase<DerivedEta>& eta,
                                                    const Eigen::MatrixBase<DerivedNu>& nu) {
  using S = typename DerivedEta::Scalar;
  return kinematics_euler<S>(eta(3), eta(4), eta(5)) * Vector6<S>(nu);
}

}  // namespace kelp::vehicle
