/// \file
/// \brief Input checks shared by the vehicle models: symmetry and (semi-)definiteness of the
/// matrices a user supplies (inertia, added mass, linear damping).
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <string>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"

namespace kelp::vehicle {

/// \brief Throws `kelp::invalid_argument` naming `field` unless the square matrix `m` is finite,
/// symmetric (to 1e-9 relative to its largest entry) and positive definite (`semi = false`, every
/// eigenvalue > 0) or positive semi-definite (`semi = true`, every eigenvalue ≥ −1e-12·‖m‖).
///
/// Only the value part of each coefficient is inspected (so the check also runs for
/// `ceres::Jet`); the factorisation runs once, at parameter-set construction, never per step.
/// \tparam Derived an Eigen square matrix expression.
/// \param[in] m the matrix. \param[in] field its name for the message.
/// \param[in] semi accept a singular (positive semi-definite) matrix.
template <typename Derived>
void check_symmetric_definite(const Eigen::MatrixBase<Derived>& m, const char* field, bool semi) {
  check_all_finite(m, field);
  KELP_CHECK(m.rows() == m.cols(), std::string(field) + " must be square");
  const Eigen::Index n = m.rows();
  // Same compile-time size as the input (3×3 inertia, 6×6 added mass / damping): fixed-size
  // factorisations, which also keep g++ 12's -Wmaybe-uninitialized false positives in Eigen's
  // dynamic-size kernels out of users' -O2 -Werror builds.
  using Mat = Eigen::Matrix<double, Derived::RowsAtCompileTime, Derived::ColsAtCompileTime>;
  Mat v(n, n);
  for (Eigen::Index j = 0; j < n; ++j)
    for (Eigen::Index i = 0; i < n; ++i) v(i, j) = value_of(m(i, j));
  const double scale = v.cwiseAbs().maxCoeff();
  KELP_CHECK((v - v.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * scale,
             std::string(field) + " must be symmetric");
  if (n == 0) return;
  // Definiteness from a pivoted LDLᵀ factorisation (Eigen::LDLT): by Sylvester's law of inertia
  // D has as many positive entries as the matrix has positive eigenvalues, so the matrix is
  // positive definite when every D_i > 0 (for such a matrix the factorisation is backward stable,
  // its error ~n·ε·‖m‖ far below the semi-definite tolerance; an indefinite one gives a D_i ≤ 0
  // or a failed factorisation). Semi-definite: m + 1e-12·‖m‖·I must be positive
  // definite, i.e. λ_min(m) > −1e-12·‖m‖ (the zero matrix passes). A factorisation instead of an
  // eigen-solver: the same answer, and far less for the compiler to instantiate in every
  // translation unit that builds a vehicle model (the 6×6 one is VehicleModel's own).
  if (semi) {
    if (scale == 0.0) return;
    v.diagonal().array() += 1e-12 * scale;
  }
  const Eigen::LDLT<Mat> ldlt(v);
  const bool definite = ldlt.info() == Eigen::Success && ldlt.vectorD().minCoeff() > 0.0;
  if (semi) {
    KELP_CHECK(definite, std::string(field) + " must be positive semi-definite");
  } else {
    KELP_CHECK(definite, std::string(field) + " must be positive definite");
  }
}

}  // namespace kelp::vehicle
