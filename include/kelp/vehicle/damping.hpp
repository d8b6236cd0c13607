/// \file
/// \brief Hydrodynamic damping D(ν_r) = D_L + D_NL(|ν_r|) (Fossen 2021, §6.4).
///
/// Parameters are positive magnitudes: D_L = −[X_u …] (linear, full 6×6 allowed, symmetric part
/// positive semi-definite) and the diagonal quadratic terms d_i = −X_{u|u|}, … ≥ 0, so that
/// D_NL(ν_r) = diag(d ∘ |ν_r|) and the damping force D(ν_r) ν_r opposes the motion for every
/// speed, including sub-unit ones (νᵀ D ν = νᵀ D_L ν + Σ d_i |ν_i|³ ≥ 0).
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/vehicle/checks.hpp"

namespace kelp::vehicle {

/// \brief Damping coefficients, positive magnitudes, body axes about the CO.
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
struct DampingParameters {
  /// D_L [N s/m, N s, N m s]: linear damping (−X_u, −Y_v, …; off-diagonal terms allowed).
  Matrix6<Scalar> linear = Matrix6<Scalar>::Zero();
  /// d [N s²/m², N m s²]: quadratic damping magnitudes (−X_{u|u|}, −Y_{v|v|}, …, −N_{r|r|}).
  Vector6<Scalar> quadratic = Vector6<Scalar>::Zero();

  /// \brief The same coefficients in another scalar type.
  /// \tparam T the new scalar (float, double, ceres::Jet). \return the converted coefficients.
  template <typename T>
  DampingParameters<T> cast() const {
    DampingParameters<T> out;
    out.linear = linear.template cast<T>();
    out.quadratic = quadratic.template cast<T>();
    return out;
  }
};

/// \brief Throws kelp::invalid_argument naming `linear_damping` or `quadratic_damping` unless
/// the coefficients are finite, the quadratic ones ≥ 0 and ½(D_L + D_Lᵀ) is positive
/// semi-definite.
/// \param d Linear D_L [N s/m, N m s/rad] and quadratic d coefficients, body axes.
template <typename Scalar>
void validate(const DampingParameters<Scalar>& d) {
  const Matrix6<Scalar> sym = Scalar(0.5) * (d.linear + d.linear.transpose());
  check_all_finite(d.linear, "linear_damping");
  check_symmetric_definite(sym, "linear_damping", true);
  for (int i = 0; i < 6; ++i) check_non_negative(d.quadratic(i), "quadratic_damping");
}

/// \brief Damping matrix D(ν_r) = D_L + diag(d ∘ |ν_r|) (Fossen 2021, §6.4:
/// linear plus quadratic "|ν|ν" drag).
/// \param[in] p coefficients. \param[in] nu_r velocity relative to the current [m/s, rad/s], body.
/// \return D(ν_r), body axes (no check, no throw).
template <typename Scalar, typename Derived>
Matrix6<Scalar> damping_matrix(const DampingParameters<Scalar>& p,
                               const Eigen::MatrixBase<Derived>& nu_r) {
  using std::abs;
  Matrix6<Scalar> D = p.linear;
  for (int i = 0; i < 6; ++i) D(i, i) += p.quadratic(i) * abs(nu_r(i));
  return D;
}

/// \brief Damping force D(ν_r) ν_r [N, N m], body axes, computed without forming D. It enters the
/// equation of motion on the left-hand side (it resists motion relative to the water).
/// \param[in] p coefficients. \param[in] nu_r velocity relative to the current [m/s, rad/s], body.
/// \return D(ν_r) ν_r [N, N m], body axes (no check, no throw).
template <typename Scalar, typename Derived>
Vector6<Scalar> damping_force(const DampingParameters<Scalar>& p,
                              const Eigen::MatrixBase<Derived>& nu_r) {
  using std::abs;
  const Vector6<Scalar> n(nu_r);
  Vector6<Scalar> f = p.linear * n;
  for (int i = 0; i < 6; ++i) f(i) += p.quadratic(i) * abs(n(i)) * n(i);
  return f;
}

/// \brief Damping coefficients in double precision.
using DampingParametersd = DampingParameters<double>;
/// \brief Damping coefficients in single precision.
using DampingParametersf = DampingParameters<float>;

}  // namespace kelp::vehicle
