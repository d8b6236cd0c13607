/// \file
/// \brief Hydrodynamic added mass M_A and its Coriolis matrix C_A(ν_r).
///
/// kelp stores added mass as positive magnitudes: M_A = −[X_u̇ X_v̇ …; …] in SNAME notation
/// (Fossen 2021, §6.3), a symmetric positive semi-definite 6×6 matrix in body axes about the CO.
/// It lives in the mass matrix M = M_RB + M_A, never as a force computed from a previous step's
/// acceleration.
#pragma once

#include <Eigen/Core>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/vehicle/checks.hpp"
#include "kelp/vehicle/coriolis.hpp"

namespace kelp::vehicle {

/// \brief Diagonal added-mass matrix diag(−X_u̇, −Y_v̇, −Z_ẇ, −K_ṗ, −M_q̇, −N_ṙ).
/// \param[in] magnitudes the six positive magnitudes [kg, kg, kg, kg m², kg m², kg m²].
/// \throws kelp::invalid_argument naming `added_mass` if there are not 6 magnitudes or a
/// magnitude is negative or not finite.
/// \return M_A (body axes), diagonal, with the magnitudes on its diagonal.
template <typename Derived>
Matrix6<typename Derived::Scalar> diagonal_added_mass(
    const Eigen::MatrixBase<Derived>& magnitudes) {
  using S = typename Derived::Scalar;
  KELP_CHECK(magnitudes.size() == 6, "added_mass needs 6 magnitudes");
  for (Eigen::Index i = 0; i < 6; ++i) check_non_negative(magnitudes(i), "added_mass");
  return Vector6<S>(magnitudes).asDiagonal();
}

/// \brief Checks a full added-mass matrix: finite, symmetric, positive semi-definite.
/// \param M_a the 6×6 added-mass matrix (body axes; kg, kg m, kg m²).
/// \throws kelp::invalid_argument naming `added_mass`.
template <typename Derived>
void check_added_mass(const Eigen::MatrixBase<Derived>& M_a) {
  check_symmetric_definite(M_a, "added_mass", true);
}

/// \brief Added-mass Coriolis–centripetal matrix C_A(ν_r) = m2c(M_A, ν_r) (Fossen 2021,
/// Theorem 3.2 applied to M_A; §6.3), evaluated at the velocity relative to the current.
/// \param[in] M_a added-mass matrix (positive magnitudes), body axes.
/// \param[in] nu_r ν_r = ν − ν_c [m/s, rad/s], body axes.
/// \return C_A(ν_r), body axes (skew-symmetric; no check, no throw).
template <typename DerivedM, typename DerivedNu>
Matrix6<typename DerivedM::Scalar> added_mass_coriolis_matrix(
    const Eigen::MatrixBase<DerivedM>& M_a, const Eigen::MatrixBase<DerivedNu>& nu_r) {
  return coriolis_matrix(M_a, nu_r);
}

}  // namespace kelp::vehicle
