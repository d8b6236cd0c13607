/// \file
/// \brief Hydrostatic restoring forces g(η) (Fossen 2021, Ch. 4).
///
/// Sign convention: g enters the equation of motion on the left-hand side,
/// M ν̇ + C ν + D ν + g(η) = τ, so g is the *negative* of the net hydrostatic force and moment:
/// a heavy vehicle (W > B) at rest and level has g_z = −(W − B) < 0 and sinks. Frames: NED (z down)
/// and body (x fwd, y stbd, z down); lever arms r_g (CG) and r_b (CB) are body-axis positions
/// relative to the CO [m].
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "kelp/core/types.hpp"

namespace kelp::vehicle {

/// \brief Restoring vector of a submerged body in rotation-matrix form (Fossen 2021, §4.1, the
/// form of `gRvect`):
/// \f[ g = -\begin{bmatrix} R^\top (f_g + f_b) \\ r_g \times R^\top f_g + r_b \times R^\top f_b
/// \end{bmatrix}, \quad f_g = (0, 0, W)^n,\; f_b = (0, 0, -B)^n. \f]
/// Valid for every attitude (no Euler singularity), so it works with quaternions and at ±90° pitch.
/// \param[in] weight W = m g [N] \param[in] buoyancy B = ρ g ∇ [N]
/// \param[in] r_g CG [m], body \param[in] r_b CB [m], body
/// \param[in] R rotation matrix body → NED.
/// \return g [N, N m], body axes.
template <typename Scalar, typename DG, typename DB, typename DR>
Vector6<Scalar> restoring_force(const Scalar& weight, const Scalar& buoyancy,
                                const Eigen::MatrixBase<DG>& r_g, const Eigen::MatrixBase<DB>& r_b,
                                const Eigen::MatrixBase<DR>& R) {
  // Rᵀ e_z is the last row of R: the NED down axis expressed in body coordinates.
  const Vector3<Scalar> down = R.template bottomRows<1>().transpose();
  const Vector3<Scalar> fg = weight * down;
  const Vector3<Scalar> fb = -buoyancy * down;
  Vector6<Scalar> g;
  g.template head<3>() = -(fg + fb);
  g.template tail<3>() = -(Vector3<Scalar>(r_g).cross(fg) + Vector3<Scalar>(r_b).cross(fb));
  return g;
}

/// \brief Restoring vector of a submerged body in zyx-Euler form (Fossen 2021, §4.1; `gvect`):
/// \f[ g(\eta) = \begin{bmatrix} (W-B) s\theta \\ -(W-B) c\theta s\phi \\ -(W-B) c\theta c\phi
/// \\   -(y_g W - y_b B) c\theta c\phi + (z_g W - z_b B) c\theta s\phi
/// \\   (z_g W - z_b B) s\theta + (x_g W - x_b B) c\theta c\phi
/// \\   -(x_g W - x_b B) c\theta s\phi - (y_g W - y_b B) s\theta \end{bmatrix}. \f]
/// Independent of yaw; equals restoring_force() for the same attitude.
/// \param[in] weight W [N] \param[in] buoyancy B [N] \param[in] r_g CG [m], body
/// \param[in] r_b CB [m], body \param[in] phi roll [rad] \param[in] theta pitch [rad]
template <typename Scalar, typename DG, typename DB>
Vector6<Scalar> restoring_force_euler(const Scalar& weight, const Scalar& buoyancy,
                                      const Eigen::MatrixBase<DG>& r_g,
                                      const Eigen::MatrixBase<DB>& r_b, const Scalar& phi,
                                      const Scalar& theta) {
  using std::cos;
  using std::sin;
  const Scalar W = weight, B = buoyancy;
  const Scalar sphi = sin(phi), cphi = cos(phi), sth = sin(theta), cth = cos(theta);
  const Scalar xw = r_g(0) * W - r_b(0) * B;
  const Scalar yw = r_g(1) * W - r_b(1) * B;
  const Scalar zw = r_g(2) * W - r_b(2) * B;
  Vector6<Scalar> g;
  g << (W - B) * sth, -(W - B) * cth * sphi, -(W - B) * cth * cphi,
      -yw * cth * cphi + zw * cth * sphi, zw * sth + xw * cth * cphi, -xw * cth * sphi - yw * sth;
  return g;
}

/// \brief Restoring vector of a floating (surface) vessel about its equilibrium draft, written
/// with the rotation matrix so that it needs no Euler angles (Fossen 2021, §4.2: heave stiffness
/// ρ g A_wp, righting moments ρ g ∇ GM_T sin φ cos θ and ρ g ∇ GM_L sin θ):
/// \f[ g = \big(R^\top (0, 0, \rho g A_{wp} z)^n,\; \rho g \nabla GM_T R_{32},\;
///     -\rho g \nabla GM_L R_{31},\; 0\big), \f]
/// where R₃₂ = cos θ sin φ and R₃₁ = −sin θ. Weight and buoyancy balance at z = 0; the model is
/// linear in the heave displacement and in the righting arms (small to moderate angles, hull not
/// emerging nor submerging).
/// \param[in] density ρ [kg/m³] \param[in] gravity g [m/s²] \param[in] displaced_volume ∇ [m³]
/// \param[in] waterplane_area A_wp [m²] \param[in] gm_transverse GM_T [m]
/// \param[in] gm_longitudinal GM_L [m]
/// \param[in] z NED depth of the CO below its equilibrium (still-water) position [m]
/// \param[in] R rotation matrix body → NED.
/// \return g [N, N m], body axes.
template <typename Scalar, typename DR>
Vector6<Scalar> restoring_force_surface(const Scalar& density, const Scalar& gravity,
                                        const Scalar& displaced_volume,
                                        const Scalar& waterplane_area, const Scalar& gm_transverse,
                                        const Scalar& gm_longitudinal, const Scalar& z,
                                        const Eigen::MatrixBase<DR>& R) {
  const Vector3<Scalar> down = R.template bottomRows<1>().transpose();
  const Scalar rho_g = density * gravity;
  Vector6<Scalar> g;
  g.template head<3>() = (rho_g * waterplane_area * z) * down;
  g(3) = rho_g * displaced_volume * gm_transverse * R(2, 1);
  g(4) = -rho_g * displaced_volume * gm_longitudinal * R(2, 0);
  g(5) = Scalar(0);
  return g;
}

}  // namespace kelp::vehicle
