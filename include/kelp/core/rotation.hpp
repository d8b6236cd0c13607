/// \file
/// \brief Skew-symmetric matrices, rotations (zyx Euler angles and unit quaternions) and the
/// kinematic transformations J(η) of Fossen (2021), §2.2.
///
/// Frames: world NED (x north, y east, z down); body (x forward, y starboard, z down).
/// Quaternions are Eigen's, unit, rotating body vectors into NED: v_ned = q * v_body; constructed
/// as Quaternion(w, x, y, z), stored (and their rates returned) in `coeffs()` order (x, y, z, w).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "kelp/core/types.hpp"

namespace kelp {

/// \brief Skew-symmetric matrix S(a) with S(a) b = a × b (Fossen 2021, eq. 2.9).
/// \tparam Derived an Eigen 3-vector expression.
/// \param a the vector (any frame; S(a) acts in the same frame).
/// \return S(a) = −S(a)ᵀ.
template <typename Derived>
Matrix3<typename Derived::Scalar> skew(const Eigen::MatrixBase<Derived>& a) {
  using S = typename Derived::Scalar;
  Matrix3<S> m;
  m << S(0), -a(2), a(1),  //
      a(2), S(0), -a(0),   //
      -a(1), a(0), S(0);
  return m;
}

/// \brief Rotation matrix R_zyx(φ, θ, ψ) from body to NED (Fossen 2021, eq. 2.18).
/// \param[in] phi roll [rad] \param[in] theta pitch [rad] \param[in] psi yaw [rad]
/// \return R with v_NED = R v_body (orthonormal, det 1).
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
Matrix3<Scalar> rotation_zyx(const Scalar& phi, const Scalar& theta, const Scalar& psi) {
  using std::cos;
  using std::sin;
  const Scalar cphi = cos(phi), sphi = sin(phi), cth = cos(theta), sth = sin(theta),
               cpsi = cos(psi), spsi = sin(psi);
  Matrix3<Scalar> R;
  R << cpsi * cth, -spsi * cphi + cpsi * sth * sphi, spsi * sphi + cpsi * cphi * sth,  //
      spsi * cth, cpsi * cphi + sphi * sth * spsi, -cpsi * sphi + sth * spsi * cphi,   //
      -sth, cth * sphi, cth * cphi;
  return R;
}

/// \brief Euler-angle rate transformation T_zyx(φ, θ): Θ̇ = T ω (Fossen 2021, eq. 2.41).
/// Singular at θ = ±90°; use the quaternion form there.
/// \param phi roll φ [rad] \param theta pitch θ [rad]
/// \return T_zyx, mapping body rates ω = (p, q, r) [rad/s] to Euler rates (φ̇, θ̇, ψ̇) [rad/s];
/// its entries are infinite or NaN at θ = ±90° (no check, no throw).
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
Matrix3<Scalar> euler_rate_matrix(const Scalar& phi, const Scalar& theta) {
  using std::cos;
  using std::sin;
  using std::tan;
  const Scalar cphi = cos(phi), sphi = sin(phi), cth = cos(theta), tth = tan(theta);
  Matrix3<Scalar> T;
  T << Scalar(1), sphi * tth, cphi * tth,  //
      Scalar(0), cphi, -sphi,              //
      Scalar(0), sphi / cth, cphi / cth;
  return T;
}

/// \brief Unit quaternion for zyx Euler angles (φ, θ, ψ): q = q_z(ψ) q_y(θ) q_x(φ).
/// \param phi roll [rad] \param theta pitch [rad] \param psi yaw [rad]
/// \return the unit quaternion rotating body vectors into NED (the rotation of rotation_zyx).
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
Quaternion<Scalar> quaternion_from_euler(const Scalar& phi, const Scalar& theta,
                                         const Scalar& psi) {
  using std::cos;
  using std::sin;
  const Scalar h(0.5);
  const Scalar cr = cos(h * phi), sr = sin(h * phi), cp = cos(h * theta), sp = sin(h * theta),
               cy = cos(h * psi), sy = sin(h * psi);
  return Quaternion<Scalar>(cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
                            cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy);
}

/// \brief zyx Euler angles (φ, θ, ψ) [rad] of a unit quaternion; θ ∈ [−π/2, π/2].
/// \param q a unit quaternion rotating body vectors into NED (not checked).
/// \return (φ, θ, ψ) [rad]: φ and ψ in [−π, π], θ in [−π/2, π/2].
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
Vector3<Scalar> euler_from_quaternion(const Quaternion<Scalar>& q) {
  using std::asin;
  using std::atan2;
  const Scalar w = q.w(), x = q.x(), y = q.y(), z = q.z();
  Scalar s = Scalar(2) * (w * y - x * z);
  if (s > Scalar(1)) s = Scalar(1);
  if (s < Scalar(-1)) s = Scalar(-1);
  return Vector3<Scalar>(
      atan2(Scalar(2) * (w * x + y * z), Scalar(1) - Scalar(2) * (x * x + y * y)), asin(s),
      atan2(Scalar(2) * (w * z + x * y), Scalar(1) - Scalar(2) * (y * y + z * z)));
}

/// \brief Quaternion rate q̇ = ½ q ⊗ (0, ω) for body angular velocity ω [rad/s]
/// (Fossen 2021, eq. 2.75), returned in Eigen's `coeffs()` order (ẋ, ẏ, ż, ẇ), the order of
/// `Quaternion::coeffs()` and of `vehicle::PoseRate::attitude_dot` (kelp's one quaternion order
/// for rates: `q.coeffs() += h * quaternion_rate(q, omega)` is an Euler step).
/// \tparam Derived an Eigen 3-vector expression.
/// \param q the attitude, a unit quaternion (body → NED).
/// \param omega body angular velocity (p, q, r) [rad/s], body frame.
/// \return q̇ [1/s] as (ẋ, ẏ, ż, ẇ).
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar, typename Derived>
Eigen::Matrix<Scalar, 4, 1> quaternion_rate(const Quaternion<Scalar>& q,
                                            const Eigen::MatrixBase<Derived>& omega) {
  const Scalar h(0.5);
  const Scalar w = q.w(), x = q.x(), y = q.y(), z = q.z();
  const Scalar p = omega(0), qq = omega(1), r = omega(2);
  return Eigen::Matrix<Scalar, 4, 1>(h * (w * p - z * qq + y * r), h * (z * p + w * qq - x * r),
                                     h * (-y * p + x * qq + w * r), h * (-x * p - y * qq - z * r));
}

/// \brief 6×6 kinematic transformation J_Θ(η) for zyx Euler angles: η̇ = J ν with
/// η = (x, y, z, φ, θ, ψ) NED and ν = (u, v, w, p, q, r) body (Fossen 2021, eq. 2.53).
/// \param phi roll [rad] \param theta pitch [rad] \param psi yaw [rad]
/// \return J = diag(R_zyx, T_zyx); singular at θ = ±90°, like euler_rate_matrix.
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
Matrix6<Scalar> kinematics_euler(const Scalar& phi, const Scalar& theta, const Scalar& psi) {
  Matrix6<Scalar> J = Matrix6<Scalar>::Zero();
  J.template topLeftCorner<3, 3>() = rotation_zyx(phi, theta, psi);
  J.template bottomRightCorner<3, 3>() = euler_rate_matrix(phi, theta);
  return J;
}

}  // namespace kelp
