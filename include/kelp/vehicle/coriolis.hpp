/// \file
/// \brief Coriolis–centripetal matrix from a 6×6 mass matrix (Fossen's `m2c`).
///
/// For a symmetric mass matrix M = [M11 M12; M21 M22] (3×3 blocks) and ν = (ν1, ν2) with
/// ν1 = (u, v, w) [m/s] and ν2 = (p, q, r) [rad/s] in body axes, Fossen (2021, Theorem 3.2, the
/// "C from M" parametrisation) gives
/// \f[ C(\nu) = \begin{bmatrix} 0_{3} & -S(M_{11}\nu_1 + M_{12}\nu_2)
/// \\     -S(M_{11}\nu_1 + M_{12}\nu_2) & -S(M_{21}\nu_1 + M_{22}\nu_2) \end{bmatrix}, \f]
/// which is skew-symmetric, so that νᵀ C(ν) ν = 0 (no work is done by Coriolis forces). Applied to
/// M_RB it gives C_RB(ν); applied to M_A with the relative velocity it gives C_A(ν_r).
#pragma once

#include <Eigen/Core>

#include "kelp/core/rotation.hpp"
#include "kelp/core/types.hpp"

namespace kelp::vehicle {

/// \brief Coriolis–centripetal matrix C(ν) of a mass matrix (Fossen 2021, Theorem 3.2; `m2c`).
///
/// Only the symmetric part ½(M + Mᵀ) of `M` is used, as in Fossen's reference implementation.
/// \tparam DerivedM 6×6 Eigen expression. \tparam DerivedNu 6-vector Eigen expression.
/// \param[in] M mass matrix (M_RB [kg, kg m, kg m²] or M_A), body axes about the CO.
/// \param[in] nu ν = (u, v, w, p, q, r) [m/s, rad/s], body axes (use ν_r for C_A).
/// \return the 6×6 skew-symmetric C(ν).
template <typename DerivedM, typename DerivedNu>
Matrix6<typename DerivedM::Scalar> coriolis_matrix(const Eigen::MatrixBase<DerivedM>& M,
                                                   const Eigen::MatrixBase<DerivedNu>& nu) {
  using S = typename DerivedM::Scalar;
  const S h(0.5);
  const Vector6<S> n(nu);
  const Matrix6<S> Ms = h * (M + M.transpose());
  const Vector3<S> a = Ms.template topRows<3>() * n;
  const Vector3<S> b = Ms.template bottomRows<3>() * n;
  Matrix6<S> C = Matrix6<S>::Zero();
  C.template topRightCorner<3, 3>() = -skew(a);
  C.template bottomLeftCorner<3, 3>() = -skew(a);
  C.template bottomRightCorner<3, 3>() = -skew(b);
  return C;
}

/// \brief The Coriolis–centripetal force C(ν) ν without forming the matrix:
/// \f$ C(\nu)\nu = (\nu_2 \times a,\; \nu_1 \times a + \nu_2 \times b) \f$ with
/// \f$ a = M_{11}\nu_1 + M_{12}\nu_2 \f$, \f$ b = M_{21}\nu_1 + M_{22}\nu_2 \f$ (Fossen 2021,
/// Theorem 3.2). `M` must already be symmetric (kelp's models store symmetric matrices).
/// \param[in] M symmetric 6×6 mass matrix, body axes. \param[in] nu ν [m/s, rad/s], body axes.
/// \return C(ν) ν [N, N m], body axes; it enters the equation of motion on the left-hand side.
template <typename DerivedM, typename DerivedNu>
Vector6<typename DerivedM::Scalar> coriolis_force(const Eigen::MatrixBase<DerivedM>& M,
                                                  const Eigen::MatrixBase<DerivedNu>& nu) {
  using S = typename DerivedM::Scalar;
  const Vector6<S> n(nu);
  const Vector3<S> a = M.template topRows<3>() * n;
  const Vector3<S> b = M.template bottomRows<3>() * n;
  const Vector3<S> v = n.template head<3>();
  const Vector3<S> w = n.template tail<3>();
  Vector6<S> f;
  f.template head<3>() = w.cross(a);
  f.template tail<3>() = v.cross(a) + w.cross(b);
  return f;
}

}  // namespace kelp::vehicle
