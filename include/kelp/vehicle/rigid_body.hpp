/// \file
/// \brief Rigid-body mass matrix M_RB about the body origin (CO) and its Coriolis matrix C_RB(ν).
#pragma once

#include <Eigen/Core>

#include "kelp/core/rotation.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/vehicle/checks.hpp"
#include "kelp/vehicle/coriolis.hpp"

namespace kelp::vehicle {

/// \brief The system transformation matrix H(r) = [I₃ Sᵀ(r); 0 I₃] that moves a 6-DOF quantity
/// from a point at `r` (body axes, relative to the CO) to the CO (Fossen 2021, §3.3, `Hmtrx`).
/// \param[in] r lever arm [m], body axes.
/// \return H(r), 6×6.
template <typename Derived>
Matrix6<typename Derived::Scalar> transformation_h(const Eigen::MatrixBase<Derived>& r) {
  using S = typename Derived::Scalar;
  Matrix6<S> H = Matrix6<S>::Identity();
  H.template topRightCorner<3, 3>() = skew(r).transpose();
  return H;
}

/// \brief Rigid-body mass matrix about the CO, M_RB = Hᵀ(r_g) M_CG H(r_g) with
/// M_CG = diag(m I₃, I_g) (Fossen 2021, §3.3):
/// \f[ M_{RB} = \begin{bmatrix} m I_3 & -m S(r_g) \\ m S(r_g) & I_g - m S^2(r_g) \end{bmatrix}. \f]
/// \param[in] mass m [kg], > 0.
/// \param[in] inertia_cg I_g [kg m²]: inertia tensor about the CG, body axes, symmetric positive
///   definite.
/// \param[in] r_g CG position [m] relative to the CO, body axes (x fwd, y stbd, z down).
/// \return symmetric positive definite 6×6 M_RB [kg, kg m, kg m²].
/// \throws kelp::invalid_argument naming `mass`, `inertia` or `r_g` on bad input, or when
/// M_RB overflows (e.g. m |r_g|² beyond the largest double).
template <typename Scalar, typename DerivedI, typename DerivedR>
Matrix6<Scalar> rigid_body_mass_matrix(const Scalar& mass,
                                       const Eigen::MatrixBase<DerivedI>& inertia_cg,
                                       const Eigen::MatrixBase<DerivedR>& r_g) {
  check_positive(mass, "mass");
  check_symmetric_definite(inertia_cg, "inertia", false);
  check_all_finite(r_g, "r_g");
  Matrix6<Scalar> M_cg = Matrix6<Scalar>::Zero();
  M_cg.template topLeftCorner<3, 3>() = mass * Matrix3<Scalar>::Identity();
  M_cg.template bottomRightCorner<3, 3>() = Matrix3<Scalar>(inertia_cg);
  const Matrix6<Scalar> H = transformation_h(Vector3<Scalar>(r_g));
  const Matrix6<Scalar> M_rb = H.transpose() * M_cg * H;
  check_all_finite(M_rb, "rigid-body mass matrix M_RB (mass, inertia, r_g)");
  return M_rb;
}

/// \brief Rigid-body Coriolis–centripetal matrix C_RB(ν) = m2c(M_RB, ν) (Fossen 2021,
/// Theorem 3.2). Uses the absolute velocity ν, not the relative one.
/// \param[in] M_rb rigid-body mass matrix about the CO. \param[in] nu ν [m/s, rad/s], body axes.
/// \return C_RB(ν), body axes (no check, no throw).
template <typename DerivedM, typename DerivedNu>
Matrix6<typename DerivedM::Scalar> rigid_body_coriolis_matrix(
    const Eigen::MatrixBase<DerivedM>& M_rb, const Eigen::MatrixBase<DerivedNu>& nu) {
  return coriolis_matrix(M_rb, nu);
}

}  // namespace kelp::vehicle
