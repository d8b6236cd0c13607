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

#include "kelp/core/scalar.hpp"
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
/// \return g(η) [N, N m], body axes.
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

/// \brief Submerged fraction φ ∈ [0, 1] of a hull modelled as a box of vertical extent h centred
/// on its centre of buoyancy: φ = clamp((z_CB + ζ)/h + ½, 0, 1), where z_CB is the NED depth of
/// the CB and the free surface lies at z = −ζ. The box stays vertical whatever the attitude (the
/// hull's vertical extent is taken as h at every roll and pitch).
/// \param[in] z_cb NED z of the CB [m] \param[in] zeta surface elevation ζ above the CB [m], up
/// \param[in] hull_height h [m], > 0
/// \throws kelp::invalid_argument naming `hull_height` unless it is finite and > 0 (a parameter:
/// the positions are not checked, a non-finite state is the integrators' to report).
/// \return φ ∈ [0, 1].
template <typename Scalar>
Scalar submerged_fraction(const Scalar& z_cb, const Scalar& zeta, const Scalar& hull_height) {
  check_positive(hull_height, "hull_height");
  const Scalar s = (z_cb + zeta) / hull_height + Scalar(0.5);
  if (s <= Scalar(0)) return Scalar(0);
  if (s >= Scalar(1)) return Scalar(1);
  return s;
}

/// \brief Restoring vector of a submerged vehicle near the free surface (the submerged-fraction
/// model): the hull is a vertical box of height h about the CB, its buoyancy is B φ with φ from
/// submerged_fraction() at the CB, and the weight W acts at r_g:
/// g = restoring_force(W, B φ, r_g, r_b, R).
/// The centre of buoyancy of the wet part lies (1 − φ) h/2 below the CB along the NED vertical,
/// i.e. on the line of action of the (vertical) buoyancy through r_b, so it adds no moment: the
/// moment is that of B φ at r_b. Fully submerged (φ = 1) this is exactly restoring_force(); the
/// force is continuous and bounded by max(W, B) at any height. It is the gradient of the
/// potential of restoring_potential_free_surface() (Fossen 2021 §4.1 for the submerged form; the
/// linear loss of buoyancy through the surface is the box-hull approximation, as the tether's
/// node buoyancy in lumped_mass.hpp).
/// \param[in] weight W [N] \param[in] buoyancy B = ρ g ∇ fully submerged [N]
/// \param[in] r_g CG [m], body \param[in] r_b CB [m], body \param[in] hull_height h [m], > 0
/// \param[in] z NED z of the CO [m] \param[in] zeta surface elevation ζ [m], up
/// \param[in] R rotation body → NED \param[out] fraction φ, if not null.
/// \return g [N, N m], body axes.
template <typename Scalar, typename DG, typename DB, typename DR>
Vector6<Scalar> restoring_force_free_surface(const Scalar& weight, const Scalar& buoyancy,
                                             const Eigen::MatrixBase<DG>& r_g,
                                             const Eigen::MatrixBase<DB>& r_b,
                                             const Scalar& hull_height, const Scalar& z,
                                             const Scalar& zeta, const Eigen::MatrixBase<DR>& R,
                                             Scalar* fraction = nullptr) {
  const Scalar z_cb = z + R.row(2).dot(r_b);
  const Scalar phi = submerged_fraction(z_cb, zeta, hull_height);
  if (fraction != nullptr) *fraction = phi;
  return restoring_force(weight, Scalar(buoyancy * phi), r_g, r_b, R);
}

/// \brief Potential energy [J] whose gradient is restoring_force_free_surface():
/// U = −W z_CG + B h Φ(s), s = (z_CB + ζ)/h + ½, Φ(s) = ∫₀ˢ clamp(σ, 0, 1) dσ (0 for s < 0,
/// s²/2 for 0 ≤ s ≤ 1, s − ½ for s > 1). Fully submerged it is −W z_CG + B (z_CB + ζ) − B h/2, the
/// usual −W z_CG + B z_CB up to a constant. For a fixed surface (ζ constant) the work of g equals
/// −ΔU, so an undamped, unforced vehicle conserves ½ νᵀ M ν + U.
/// \param[in] weight W [N] \param[in] buoyancy B = ρ g ∇ fully submerged [N]
/// \param[in] r_g CG [m], body \param[in] r_b CB [m], body \param[in] hull_height h [m], > 0
/// \param[in] z NED z of the CO [m] \param[in] zeta surface elevation ζ [m], up
/// \param[in] R rotation body → NED
/// \return U [J].
template <typename Scalar, typename DG, typename DB, typename DR>
Scalar restoring_potential_free_surface(const Scalar& weight, const Scalar& buoyancy,
                                        const Eigen::MatrixBase<DG>& r_g,
                                        const Eigen::MatrixBase<DB>& r_b, const Scalar& hull_height,
                                        const Scalar& z, const Scalar& zeta,
                                        const Eigen::MatrixBase<DR>& R) {
  const Scalar z_cg = z + R.row(2).dot(r_g);
  const Scalar z_cb = z + R.row(2).dot(r_b);
  const Scalar s = (z_cb + zeta) / hull_height + Scalar(0.5);
  Scalar big_phi(0);
  if (s >= Scalar(1)) {
    big_phi = s - Scalar(0.5);
  } else if (s > Scalar(0)) {
    big_phi = Scalar(0.5) * s * s;
  }
  return -weight * z_cg + buoyancy * hull_height * big_phi;
}

/// \brief The local surface's downward normal n_s = (ζ_x, ζ_y, 1)/√(1 + ζ_x² + ζ_y²) in body axes,
/// d = Rᵀ n_s ((R₃₁, R₃₂, R₃₃) on calm water), from the slope (∂ζ/∂x, ∂ζ/∂y) and R (body → NED).
/// \param slope (∂ζ/∂x, ∂ζ/∂y) [-], NED. \param R rotation body → NED.
/// \return d, a unit vector in body axes.
template <typename Scalar, typename DS, typename DR>
Vector3<Scalar> surface_normal_in_body(const Eigen::MatrixBase<DS>& slope,
                                       const Eigen::MatrixBase<DR>& R) {
  using std::sqrt;
  const Scalar sx = slope(0), sy = slope(1);
  const Vector3<Scalar> n =
      Vector3<Scalar>(sx, sy, Scalar(1)) / sqrt(Scalar(1) + sx * sx + sy * sy);
  return R.transpose() * n;
}

/// \brief Restoring vector of a surface vessel relative to the local wave surface, bounded when
/// the hull emerges or submerges.
///
/// Heave: the net vertical hydrostatic force ρ g A_wp e along the NED vertical, with e = z + ζ the
/// CO's depth below the local surface (z = −ζ) and, when the hull depth D > 0 is given, e clamped
/// to [−T, D − T] (T = ∇/A_wp the draft): fully emerged the hull loses all its buoyancy (the net
/// force is its weight), fully submerged it has its whole reserve buoyancy ρ g A_wp D − W and no
/// more (wall-sided box hull). Righting: with d = Rᵀ n_s the local surface's downward normal
/// n_s = (ζ_x, ζ_y, 1)/√(1 + ζ_x² + ζ_y²) in body axes (d = (R₃₁, R₃₂, R₃₃) on calm water),
/// g₄ = ρg∇GM_T d_y d_z, g₅ = −ρg∇GM_L d_x d_z, g₆ = ρg∇(GM_L − GM_T) d_x d_y: the gradient of
/// U_rot = ½ ρ g ∇ (GM_T d_y² + GM_L d_x²), so the model is conservative; to first order in the
/// angles from the local surface it is Fossen's linear restoring ρ g ∇ GM_T φ, ρ g ∇ GM_L θ
/// (Fossen 2021, §4.2) and it stays bounded by ½ ρ g ∇ max(GM) at any attitude. The surface under
/// the hull is the plane through the CO's (x, y) with the local elevation and slope (waves long
/// compared with the hull).
/// \param[in] density ρ [kg/m³] \param[in] gravity g [m/s²] \param[in] displaced_volume ∇ [m³]
/// \param[in] waterplane_area A_wp [m²] \param[in] gm_transverse GM_T [m]
/// \param[in] gm_longitudinal GM_L [m] \param[in] hull_depth D [m] (0: no bound, linear heave)
/// \param[in] z NED z of the CO, on the waterline at calm equilibrium [m]
/// \param[in] zeta local elevation ζ [m], up \param[in] slope (∂ζ/∂x, ∂ζ/∂y) [-]
/// \param[in] R rotation body → NED. \return g [N, N m], body axes.
template <typename Scalar, typename DS, typename DR>
Vector6<Scalar> restoring_force_surface_following(
    const Scalar& density, const Scalar& gravity, const Scalar& displaced_volume,
    const Scalar& waterplane_area, const Scalar& gm_transverse, const Scalar& gm_longitudinal,
    const Scalar& hull_depth, const Scalar& z, const Scalar& zeta,
    const Eigen::MatrixBase<DS>& slope, const Eigen::MatrixBase<DR>& R) {
  const Scalar rho_g = density * gravity;
  Scalar e = z + zeta;
  if (hull_depth > Scalar(0)) {
    const Scalar draft = displaced_volume / waterplane_area;
    if (e < -draft) e = -draft;
    if (e > hull_depth - draft) e = hull_depth - draft;
  }
  const Vector3<Scalar> down = R.template bottomRows<1>().transpose();
  const Vector3<Scalar> d = surface_normal_in_body<Scalar>(slope, R);
  const Scalar ct = rho_g * displaced_volume * gm_transverse;
  const Scalar cl = rho_g * displaced_volume * gm_longitudinal;
  Vector6<Scalar> g;
  g.template head<3>() = (rho_g * waterplane_area * e) * down;
  g(3) = ct * d(1) * d(2);
  g(4) = -cl * d(0) * d(2);
  g(5) = (cl - ct) * d(0) * d(1);
  return g;
}

/// \brief Potential energy [J] whose gradient is restoring_force_surface_following() for a fixed
/// surface: U = ρ g A_wp P(z + ζ) + ½ ρ g ∇ (GM_T d_y² + GM_L d_x²), with P(e) = ∫₀ᵉ clamp(ε, −T,
/// D − T) dε (e²/2 inside the bounds, continued linearly outside; no bound when D = 0).
/// \param[in] density ρ [kg/m³] \param[in] gravity g [m/s²] \param[in] displaced_volume ∇ [m³]
/// \param[in] waterplane_area A_wp [m²] \param[in] gm_transverse GM_T [m]
/// \param[in] gm_longitudinal GM_L [m] \param[in] hull_depth D [m] (0: no bound)
/// \param[in] z NED z of the CO [m] \param[in] zeta local elevation ζ [m], up
/// \param[in] slope (∂ζ/∂x, ∂ζ/∂y) [-] \param[in] R rotation body → NED
/// \return U [J] (0 at calm equilibrium: e = 0, level).
template <typename Scalar, typename DS, typename DR>
Scalar restoring_potential_surface_following(
    const Scalar& density, const Scalar& gravity, const Scalar& displaced_volume,
    const Scalar& waterplane_area, const Scalar& gm_transverse, const Scalar& gm_longitudinal,
    const Scalar& hull_depth, const Scalar& z, const Scalar& zeta,
    const Eigen::MatrixBase<DS>& slope, const Eigen::MatrixBase<DR>& R) {
  const Scalar rho_g = density * gravity;
  const Scalar e = z + zeta;
  Scalar p = Scalar(0.5) * e * e;
  if (hull_depth > Scalar(0)) {
    const Scalar lo = -displaced_volume / waterplane_area, hi = hull_depth + lo;
    if (e < lo) p = Scalar(0.5) * lo * lo + lo * (e - lo);
    if (e > hi) p = Scalar(0.5) * hi * hi + hi * (e - hi);
  }
  const Vector3<Scalar> d = surface_normal_in_body<Scalar>(slope, R);
  return rho_g * waterplane_area * p +
         Scalar(0.5) * rho_g * displaced_volume *
             (gm_transverse * d(1) * d(1) + gm_longitudinal * d(0) * d(0));
}

}  // namespace kelp::vehicle
