/// \file
/// \brief The whole Jacobian of the lumped-mass tether's node forces with the water held (the
/// implicit steps sample the water once per step, TetherWorkspace::water_frozen): every block
/// ∂F_i/∂x_j, ∂F_i/∂v_j (|i − j| ≤ 2) and ∂(M_i(x) d_i)/∂x_j of the mass term, analytic, for
/// every branch of compute_forces (wet, surface band, in air, seabed contact and friction, taut,
/// slack and clamped segments with the dashpot's direction dependence, compressive damping,
/// bending, the added-mass rate terms). The derivatives are handed block by block to a sink,
/// so that the same pass fills a ForceJacobian (tests, diagnostics) or the implicit step's
/// Newton matrix (kelp/tether/whole_newton.hpp) without storing the force blocks.
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/types.hpp"
#include "kelp/tether/block_solve.hpp"
#include "kelp/tether/forces.hpp"
#include "kelp/tether/model.hpp"
#include "kelp/tether/state.hpp"

namespace kelp::tether {

namespace detail {

/// Segment s's axial force T u and its derivatives on `branch` b (0 no force, 1 dashpot only,
/// 2 elastic plus dashpot, see active_set_direction): T_b = [b = 2] EA/l (l_s − l) + [b ≥ 1]
/// σ BA/l r with r = u·e the stretch rate (e = v_{s+1} − v_s) and σ(l_s) the dashpot's fade
/// (TetherModel::dashpot_fade), so with d = x_{s+1} − x_s and P = I − u uᵀ: ∂T_b/∂d = [b = 2]
/// EA/l u + [b ≥ 1] BA/l (σ P e / l_s + σ' r u) (the dashpot turns with the segment),
/// K = ∂(T_b u)/∂d = u ∂T_b/∂dᵀ + T_b P / l_s and C = ∂(T_b u)/∂e = [b ≥ 1] σ BA/l u uᵀ.
template <typename Scalar>
struct SegmentJacobian {
  Matrix3<Scalar> k, c;
  Scalar tension;
};

/// m += f a bᵀ (without the temporaries of an Eigen outer-product expression).
template <typename S>
EIGEN_ALWAYS_INLINE void add_outer(Matrix3<S>& m, S f, const Vector3<S>& a, const Vector3<S>& b) {
  for (int c = 0; c < 3; ++c) {
    const S fb = f * b(c);
    for (int r = 0; r < 3; ++r) m(r, c) += fb * a(r);
  }
}

/// m += f (I − q qᵀ).
template <typename S>
EIGEN_ALWAYS_INLINE void add_projector(Matrix3<S>& m, S f, const Vector3<S>& q) {
  add_outer(m, -f, q, q);
  for (int k = 0; k < 3; ++k) m(k, k) += f;
}

/// SegmentJacobian of segment s on branch `b` (a negative b: the branch compute_forces took)
/// from the segment pass's length and direction in `ws` and the velocities `v`.
template <typename Scalar, typename DV>
SegmentJacobian<Scalar> segment_jacobian(const TetherModel<Scalar>& model,
                                         const TetherWorkspace<Scalar>& ws,
                                         const Eigen::MatrixBase<DV>& v, int s, Scalar b) {
  SegmentJacobian<Scalar> out;
  const Scalar ls = ws.stretched_length(s);
  out.k.setZero();
  out.c.setZero();
  out.tension = Scalar(0);
  if (!(ls > Scalar(0)) || ws.is_parted(s)) return out;
  const Vector3<Scalar> u = ws.direction.col(s);
  const Vector3<Scalar> e = v.col(s + 1) - v.col(s);
  // The segment's own rest length and constants (segment 0's at a winch).
  const SegmentSprings<Scalar> sk = segment_springs(model, ws, s);
  const Scalar r = u.dot(e), ext = ls - sk.l;
  const Scalar ea_l = sk.ea_l, ba_l = sk.ba_l;
  if (b < Scalar(0)) b = segment_branch(model, ext, r, ea_l, ba_l);
  if (b == Scalar(0)) return out;
  const Scalar inv_ls = Scalar(1) / ls;
  Vector3<Scalar> grad = Vector3<Scalar>::Zero();
  if (b == Scalar(2)) {
    out.tension = ea_l * ext;
    grad = ea_l * u;
  }
  if (ba_l != Scalar(0)) {
    // The dashpot σ(l_s) BA/l r (TetherModel::dashpot_fade): ∂/∂d = BA/l (σ' r u + σ P e/l_s).
    const typename TetherModel<Scalar>::Fade fade = segment_fade(model, ws, s, ls);
    const Scalar bs = ba_l * fade.value;
    out.tension += bs * r;
    grad += (bs * inv_ls) * (e - r * u) + (ba_l * fade.slope * r) * u;
    add_outer(out.c, bs, u, u);
  }
  add_outer(out.k, Scalar(1), u, grad);
  add_projector(out.k, out.tension * inv_ls, u);
  return out;
}

/// Hands every block of the Jacobian of compute_forces at (x, v), water held, to `sink`:
/// `sink.x(i, j, A, c)` adds c·A to ∂F_i/∂x_j, `sink.v(i, j, A, c)` to ∂F_i/∂v_j and
/// `sink.m(i, j, A, c)` (zero unless `d` is given) to ∂(M_i(x) d_i)/∂x_j (M_i = a_i I + b_i q_i
/// q_iᵀ, its added mass turning with the tangent and scaled by the submerged fraction); |i − j| ≤ 2
/// always, several calls may add to one block; `sink.xv(i, j, X, V, c)` and `sink.xvm(i, j, X, V,
/// M, c)` add to several at once. Segment branches: those compute_forces took, or `branches` (one
/// per segment, see segment_jacobian) when not null. Preconditions: the last compute_forces of `ws`
/// was at (x, v) (its tangents, segment lengths and directions, submerged fractions and the water
/// it used are read). No heap allocation.
template <typename Scalar, typename Env, typename DX, typename DV, typename DD, typename Sink>
void force_jacobian_blocks(const TetherModel<Scalar>& model, const TetherWorkspace<Scalar>& ws,
                           const Env& env, const Eigen::MatrixBase<DX>& x,
                           const Eigen::MatrixBase<DV>& v, const Eigen::MatrixBase<DD>* d,
                           const VectorX<Scalar>* branches, Sink& sink) {
  using std::abs;
  using std::sqrt;
  using V3 = Vector3<Scalar>;
  using M3 = Matrix3<Scalar>;
  const TetherParameters<Scalar>& p = model.parameters();
  const int n = model.segments();
  const Scalar rho = Scalar(env.water_density()), g = Scalar(env.gravity());
  const Scalar bed = Scalar(env.seabed_depth());
  const M3 eye = M3::Identity();
  const Scalar one(1);

  // Segments: +T u on node s, −T u on node s + 1.
  for (int s = 0; s < n; ++s) {
    const SegmentJacobian<Scalar> sj =
        segment_jacobian(model, ws, v, s, branches ? (*branches)(s) : Scalar(-1));
    sink.xv(s, s + 1, sj.k, sj.c, one);
    sink.xv(s, s, sj.k, sj.c, -one);
    sink.xv(s + 1, s + 1, sj.k, sj.c, -one);
    sink.xv(s + 1, s, sj.k, sj.c, one);
  }

  // Bending E = EI/l (1 − u_a·u_b) at node i between a = x_i − x_{i−1} and b = x_{i+1} − x_i:
  // f_a = −k P_a u_b / l_a on node i − 1, f_b = k P_b u_a / l_b on node i + 1, −f_a − f_b on i.
  if (p.bending_stiffness > Scalar(0)) {
    const Scalar k = p.bending_stiffness * model.inverse_segment_length();
    for (int i = 1; i < n; ++i) {
      const Scalar la = ws.stretched_length(i - 1), lb = ws.stretched_length(i);
      if (!(la > Scalar(0) && lb > Scalar(0))) continue;
      if (ws.is_parted(i - 1) || ws.is_parted(i)) continue;  // as bending_forces
      const V3 ua = ws.direction.col(i - 1), ub = ws.direction.col(i);
      const Scalar cs = ua.dot(ub);
      const M3 pa = eye - ua * ua.transpose(), pb = eye - ub * ub.transpose();
      const V3 pab = pa * ub, pba = pb * ua;
      // ∂f_a/∂a, ∂f_a/∂b, ∂f_b/∂a, ∂f_b/∂b.
      const M3 aa = (k / (la * la)) * (ua * pab.transpose() + pab * ua.transpose() + cs * pa);
      const M3 ab = (-k / (la * lb)) * (pa * pb);
      const M3 ba = (k / (la * lb)) * (pb * pa);
      const M3 bb = (-k / (lb * lb)) * (ub * pba.transpose() + pba * ub.transpose() + cs * pb);
      sink.x(i - 1, i - 1, aa, -one);
      sink.x(i - 1, i, M3(aa - ab), one);
      sink.x(i - 1, i + 1, ab, one);
      sink.x(i + 1, i - 1, ba, -one);
      sink.x(i + 1, i, M3(ba - bb), one);
      sink.x(i + 1, i + 1, bb, one);
      sink.x(i, i - 1, M3(aa + ba), one);
      sink.x(i, i, M3(ab - aa + bb - ba), one);
      sink.x(i, i + 1, M3(ab + bb), -one);
    }
    // Clamped ends (see bending_forces): the pair of forces ±f with the clamp direction t fixed,
    // stiffness 2k; ∂f/∂(segment vector) as bb (start) and aa (far end) above.
    if (ws.clamp_start.squaredNorm() > Scalar(0) && !ws.is_parted(0) &&
        ws.stretched_length(0) > Scalar(0)) {
      const Scalar lb = ws.stretched_length(0);
      const V3 ub = ws.direction.col(0), t = ws.clamp_start;
      const M3 pb = eye - ub * ub.transpose();
      const V3 pbt = pb * t;
      const M3 bb = (Scalar(-2) * k / (lb * lb)) *
                    (ub * pbt.transpose() + pbt * ub.transpose() + t.dot(ub) * pb);
      sink.x(1, 1, bb, one);
      sink.x(1, 0, bb, -one);
      sink.x(0, 1, bb, -one);
      sink.x(0, 0, bb, one);
    }
    if (ws.clamp_end.squaredNorm() > Scalar(0) && !ws.is_parted(n - 1) &&
        ws.stretched_length(n - 1) > Scalar(0)) {
      const Scalar la = ws.stretched_length(n - 1);
      const V3 ua = ws.direction.col(n - 1), t = -ws.clamp_end;
      const M3 pa = eye - ua * ua.transpose();
      const V3 pat = pa * t;
      const M3 aa = (Scalar(2) * k / (la * la)) *
                    (ua * pat.transpose() + pat * ua.transpose() + t.dot(ua) * pa);
      sink.x(n - 1, n, aa, one);
      sink.x(n - 1, n - 1, aa, -one);
      sink.x(n, n, aa, -one);
      sink.x(n, n - 1, aa, one);
    }
  }

  // Nodes.
  const Scalar half_rho_d = Scalar(0.5) * rho * p.diameter;
  const Scalar inv_diam = Scalar(1) / p.diameter;
  const Scalar can = p.normal_added_mass, cat = p.tangential_added_mass;
  const bool mass_turns = model.added_mass_rate_terms();  // as compute_forces
  for (int i = 0; i <= n; ++i) {
    const ChordNodes cnodes = chord_nodes(i, n, ws.any_parted ? ws.parted.data() : nullptr);
    const int hi = cnodes.hi, lo = cnodes.lo;
    const V3 chord = x.col(hi) - x.col(lo);
    const Scalar c2 = chord.squaredNorm();
    const Scalar inv_c = c2 > Scalar(0) ? Scalar(1) / sqrt(c2) : Scalar(0);
    const V3 q = ws.tangent.col(i);
    // (no projector matrix: add_projector)
    const Scalar li = node_length_at(model, ws, i), vol = node_volume_at(model, ws, i);
    const Scalar phi = ws.submerged(i);
    const bool wet = phi > Scalar(0);
    // ∂φ_i/∂z_j in the surface band, j = i − 1, i, i + 1 (detail::node_wetness; the surface
    // elevation held, as the water is).
    Scalar dphi_at[3] = {Scalar(0), Scalar(0), Scalar(0)};
    if (wet && phi < Scalar(1)) {
      const NodeWetness<Scalar> nw = node_wetness_of<Scalar>(
          i, n, [&](int j) { return Scalar(x(2, j)) + ws.surface_elevation(j); },
          [&](int s) {
            return s == 0 && has_winch_segment(ws) ? ws.winch_length : model.segment_length();
          },
          [&](int s) { return ws.is_parted(s); }, p.diameter, inv_diam);
      dphi_at[0] = nw.d_lo;
      dphi_at[1] = nw.d_self;
      dphi_at[2] = nw.d_hi;
    }
    const Scalar dphi = dphi_at[1];
    // The block with column z equal to `col` (∂/∂z_j of a term that scales with φ_i: col =
    // ∂φ_i/∂z_j · term/φ).
    const auto z_column = [](const V3& col) {
      M3 b = M3::Zero();
      b.col(2) = col;
      return b;
    };
    const Scalar rho_vol = rho * vol;
    // ∂F_i/∂x_i collects the z-derivatives (band, seabed) and, at the ends, the chord's.
    M3 fx_i = M3::Zero();
    // Derivatives with respect to the chord c = x_hi − x_lo: of F_i (fc), of the rate term G_i
    // with respect to dc = v_hi − v_lo (gdc) and of M_i d_i (mc); ∂F_i/∂v_i (fvi) and
    // ∂(M_i d_i)/∂x_i (mz).
    M3 fc = M3::Zero(), gdc = M3::Zero(), mc = M3::Zero(), fvi = M3::Zero(), mz = M3::Zero();
    if (wet) {
      const Scalar kn0 = half_rho_d * p.normal_drag * li;
      const Scalar kt0 = half_rho_d * Scalar(kelp::pi) * p.tangential_drag * li;
      const Scalar kn = phi * kn0, kt = phi * kt0;
      // Drag D = kn |v_n| v_n + kt |s| s q on v_r = u_water − v_i, s = q·v_r, v_n = P v_r.
      const V3 vr = ws.water_velocity.col(i) - v.col(i);
      const Scalar s = q.dot(vr);
      const V3 vn = vr - s * q;
      const Scalar vn_abs = vn.norm();
      const Scalar cn = vn_abs > Scalar(0) ? Scalar(1) / vn_abs : Scalar(0);
      // ∂D/∂v_r = kn (|v_n| P + v_n v_nᵀ/|v_n|) + 2 kt |s| q qᵀ; v_r = u − v_i.
      M3 dvr = M3::Zero();
      add_projector(dvr, kn * vn_abs, q);
      add_outer(dvr, kn * cn, vn, vn);
      add_outer(dvr, Scalar(2) * kt * abs(s), q, q);
      // ∂D/∂c = [kn (−s v_n v_nᵀ/|v_n| − |v_n| q v_nᵀ − |v_n| s P)
      //          + kt (2 |s| q v_nᵀ + |s| s P)] / |c|.
      add_outer(fc, inv_c, V3(-kn * s * cn * vn + (Scalar(2) * kt * abs(s) - kn * vn_abs) * q), vn);
      add_projector(fc, inv_c * (kt * abs(s) * s - kn * vn_abs * s), q);
      // The fluid forces scale with φ (∂/∂z = ∂φ/∂z · force/φ); the buoyancy −φ ρ V g e_z.
      V3 dz = kn0 * vn_abs * vn + (kt0 * abs(s) * s) * q;
      dz(2) -= rho_vol * g;
      const V3 aw = ws.water_acceleration.col(i);
      // Froude–Krylov and added-mass forcing ρVφ[(1 + Can) a + (Cat − Can)(q·a) q]:
      // ∂/∂c = ρVφ (Cat − Can)[q (P a)ᵀ + (q·a) P] / |c|.
      const Scalar qa = q.dot(aw);
      const Scalar f_fk = inv_c * phi * rho_vol * (cat - can);
      add_outer(fc, f_fk, q, V3(aw - qa * q));
      add_projector(fc, f_fk * qa, q);
      dz += rho_vol * ((Scalar(1) + can) * aw + (cat - can) * qa * q);
      if (mass_turns) {
        // G_i = κ [s P dc + (v_n·dc) q] on node i and w = κ s v_n on node hi (+) and lo (−),
        // κ = b/|c|, dc = v_hi − v_lo (see compute_forces).
        const Scalar b0 = rho_vol * (cat - can), kappa = phi * b0 * inv_c, kappa0 = b0 * inv_c;
        const V3 dc = v.col(hi) - v.col(lo);
        const Scalar qdc = q.dot(dc), vndc = vn.dot(dc);
        const V3 pdc = dc - qdc * q;
        const V3 gx = s * pdc + vndc * q;  // G/κ
        // ∂G/∂v_r, ∂G/∂dc, ∂G/∂c.
        add_outer(dvr, kappa, pdc, q);
        add_outer(dvr, kappa, q, pdc);
        add_projector(gdc, kappa * s, q);
        add_outer(gdc, kappa, q, vn);
        const Scalar k2 = kappa * inv_c;
        add_outer(fc, -k2, gx, q);
        add_outer(fc, k2, V3(pdc - qdc * q), vn);
        add_outer(fc, Scalar(-2) * s * k2, q, pdc);
        add_projector(fc, k2 * (vndc - s * qdc), q);
        dz += kappa0 * gx;
        // w: ∂w/∂v_r = κ (v_n qᵀ + s P), ∂w/∂c = κ/|c| (v_n v_nᵀ − s v_n qᵀ − s q v_nᵀ − s² P).
        M3 wvr = M3::Zero(), wc = M3::Zero();
        add_outer(wvr, kappa, vn, q);
        add_projector(wvr, kappa * s, q);
        add_outer(wc, k2, V3(vn - s * q), vn);
        add_outer(wc, -k2 * s, vn, q);
        add_projector(wc, -k2 * s * s, q);
        const V3 wz = (kappa0 * s) * vn;
        for (int side = 0; side < 2; ++side) {
          const int t = side == 0 ? hi : lo;
          const Scalar sg = side == 0 ? Scalar(1) : Scalar(-1);
          sink.v(t, i, wvr, -sg);
          sink.x(t, hi, wc, sg);
          sink.x(t, lo, wc, -sg);
          for (int k = 0; k < 3; ++k)
            if (dphi_at[k] != Scalar(0)) sink.x(t, i - 1 + k, z_column(dphi_at[k] * wz), sg);
        }
      }
      fvi -= dvr;
      fx_i.col(2) += dphi * dz;
      for (int k = 0; k < 3; k += 2)
        if (dphi_at[k] != Scalar(0)) sink.x(i, i - 1 + k, z_column(dphi_at[k] * dz), one);
    }
    // Seabed: normal force N = (pen kb d + ż cb d ramp) l_i while positive, friction
    // −μ N_f v_h / max(|v_h|, v_f) with N_f the frozen normal force or N.
    const Scalar pen = x(2, i) - bed;
    if (pen > Scalar(0)) {
      const Scalar bk = p.seabed_stiffness * p.diameter, bc = p.seabed_damping * p.diameter;
      const Scalar vz = v(2, i);
      const bool ramping = pen < p.seabed_damping_depth;
      const Scalar ramp = ramping ? pen / p.seabed_damping_depth : Scalar(1);
      const Scalar normal = (pen * bk + vz * bc * ramp) * li;
      if (normal > Scalar(0)) {
        const Scalar dn_dz =
            bk * li + (ramping ? vz * bc * li / p.seabed_damping_depth : Scalar(0));
        const Scalar dn_dvz = bc * ramp * li;
        fx_i(2, 2) -= dn_dz;
        M3& fv = fvi;
        fv(2, 2) -= dn_dvz;
        if (p.seabed_friction > Scalar(0)) {
          const Scalar vx = v(0, i), vy = v(1, i);
          const Scalar vh2 = vx * vx + vy * vy, vf = p.friction_velocity;
          const Scalar fmax =
              p.seabed_friction * (ws.frozen_friction ? ws.friction_normal(i) : normal);
          if (vh2 > vf * vf) {
            const Scalar vh = sqrt(vh2), coef = fmax / vh;
            const Scalar hx = vx / vh, hy = vy / vh;
            fv(0, 0) -= coef * (Scalar(1) - hx * hx);
            fv(0, 1) += coef * hx * hy;
            fv(1, 0) += coef * hx * hy;
            fv(1, 1) -= coef * (Scalar(1) - hy * hy);
          } else {
            fv(0, 0) -= fmax / vf;
            fv(1, 1) -= fmax / vf;
          }
          if (!ws.frozen_friction) {
            // ∂(coef v_h)/∂N = μ v_h / max(|v_h|, v_f).
            const Scalar den = vh2 > vf * vf ? sqrt(vh2) : vf;
            const Scalar gx = p.seabed_friction * vx / den, gy = p.seabed_friction * vy / den;
            fx_i(0, 2) -= gx * dn_dz;
            fx_i(1, 2) -= gy * dn_dz;
            fv(0, 2) -= gx * dn_dvz;
            fv(1, 2) -= gy * dn_dvz;
          }
        }
      }
    }
    // Mass term M_i d_i = a d + b (q·d) q: ∂/∂c = b/|c| [q (P d)ᵀ + (q·d) P], and in the band
    // ∂/∂z = (ρ V Can d + ρ V (Cat − Can)(q·d) q)/D.
    if (d && wet) {
      const V3 di = d->col(i);
      const Scalar qd = q.dot(di), b0 = rho_vol * (cat - can);
      const Scalar f_m = phi * b0 * inv_c;
      add_outer(mc, f_m, q, V3(di - qd * q));
      add_projector(mc, f_m * qd, q);
      const V3 m_phi = rho_vol * can * di + (b0 * qd) * q;  // ∂(M_i d_i)/∂φ
      if (dphi != Scalar(0)) mz.col(2) = dphi * m_phi;
      for (int k = 0; k < 3; k += 2)
        if (dphi_at[k] != Scalar(0)) sink.m(i, i - 1 + k, z_column(dphi_at[k] * m_phi), one);
    }
    sink.xvm(i, i, fx_i, fvi, mz, one);
    sink.xvm(i, hi, fc, gdc, mc, one);
    sink.xvm(i, lo, fc, gdc, mc, -one);
  }

  // Obstacles (kelp/tether/contact.hpp): segments against cylinders and boxes, nodes against a
  // height-field seabed.
  contact_jacobian_blocks(model, ws, env, x, v, sink);
}

/// Index of block (i, j), |i − j| ≤ 2, in a 9 × 5(N+1) block store: column 5i + (j − i + 2)
/// holds the 3×3 block column-major.
inline Eigen::Index band_block_index(int i, int j) { return 5 * Eigen::Index(i) + (j - i + 2); }

}  // namespace detail

/// \brief The blocks of the whole Jacobian of the node forces (see force_jacobian): for every
/// node i and |i − j| ≤ 2, ∂F_i/∂x_j [N/m], ∂F_i/∂v_j [N s/m] and ∂(M_i(x) d_i)/∂x_j [kg/s]
/// for the vector d given to force_jacobian. Sized once for a model (no allocation afterwards).
/// \tparam Scalar double or float.
template <typename Scalar>
struct ForceJacobian {
  /// \brief Block stores of ∂F/∂x [N/m], ∂F/∂v [N s/m] and ∂(M d)/∂x [kg/s], 9 × 5(N+1) each:
  /// column 5i + (j − i + 2) is block (i, j) column-major.
  ///@{
  Eigen::Matrix<Scalar, 9, Eigen::Dynamic> dfdx, dfdv, dmdx;
  ///@}

  ForceJacobian() = default;
  /// \brief Zero blocks sized for `model`.
  /// \param model the tether (its node count).
  explicit ForceJacobian(const TetherModel<Scalar>& model) {
    for (auto* m : {&dfdx, &dfdv, &dmdx}) m->setZero(9, 5 * Eigen::Index(model.nodes()));
  }
  /// \brief ∂F_i/∂x_j (zero beyond |i − j| ≤ 2).
  /// \param i the node whose force, 0 ≤ i ≤ N (a zero block outside).
  /// \param j the node whose position.
  /// \return the 3×3 block [N/m], NED.
  Matrix3<Scalar> dF_dx(int i, int j) const { return block(dfdx, i, j); }
  /// \brief ∂F_i/∂v_j (zero beyond |i − j| ≤ 2).
  /// \param i the node whose force, 0 ≤ i ≤ N (a zero block outside).
  /// \param j the node whose velocity.
  /// \return the 3×3 block [N s/m], NED.
  Matrix3<Scalar> dF_dv(int i, int j) const { return block(dfdv, i, j); }
  /// \brief ∂(M_i d_i)/∂x_j (zero beyond |i − j| ≤ 1).
  /// \param i the node whose mass matrix, 0 ≤ i ≤ N (a zero block outside).
  /// \param j the node whose position.
  /// \return the 3×3 block [kg/s], NED.
  Matrix3<Scalar> dMd_dx(int i, int j) const { return block(dmdx, i, j); }

  /// \brief Sink of detail::force_jacobian_blocks: adds c·a to ∂F_i/∂x_j.
  /// \param i block row (node), \param j block column (node), |i − j| ≤ 2, both in [0, N].
  /// \param a the 3×3 block [N/m]. \param c its factor (kelp's assembly passes ±1: the sign
  /// with which the block enters).
  void x(int i, int j, const Matrix3<Scalar>& a, Scalar c) { add(dfdx, i, j, c * a); }
  /// \brief Sink: adds c·a to ∂F_i/∂v_j.
  /// \param i block row, \param j block column, as x().
  /// \param a the 3×3 block [N s/m]. \param c its factor.
  void v(int i, int j, const Matrix3<Scalar>& a, Scalar c) { add(dfdv, i, j, c * a); }
  /// \brief Sink: adds c·a to ∂(M_i d_i)/∂x_j.
  /// \param i block row, \param j block column, as x().
  /// \param a the 3×3 block [kg/s]. \param c its factor.
  void m(int i, int j, const Matrix3<Scalar>& a, Scalar c) { add(dmdx, i, j, c * a); }
  /// \brief Sink: x(i, j, ax, c) and v(i, j, av, c) together.
  /// \param i block row, \param j block column, as x().
  /// \param ax the ∂F/∂x block [N/m]. \param av the ∂F/∂v block [N s/m].
  /// \param c their factor.
  void xv(int i, int j, const Matrix3<Scalar>& ax, const Matrix3<Scalar>& av, Scalar c) {
    x(i, j, ax, c);
    v(i, j, av, c);
  }
  /// \brief Sink: x(), v() and m() of one block (i, j) together.
  /// \param i block row, \param j block column, as x().
  /// \param ax the ∂F/∂x block [N/m]. \param av the ∂F/∂v block [N s/m].
  /// \param am the ∂(M d)/∂x block [kg/s]. \param c their factor.
  void xvm(int i, int j, const Matrix3<Scalar>& ax, const Matrix3<Scalar>& av,
           const Matrix3<Scalar>& am, Scalar c) {
    x(i, j, ax, c);
    v(i, j, av, c);
    m(i, j, am, c);
  }

 private:
  static Matrix3<Scalar> block(const Eigen::Matrix<Scalar, 9, Eigen::Dynamic>& s, int i, int j) {
    if (i < 0 || j < i - 2 || j > i + 2 || j < 0 || 5 * i + 4 >= s.cols())
      return Matrix3<Scalar>::Zero();
    return Eigen::Map<const Matrix3<Scalar>>(s.col(detail::band_block_index(i, j)).data());
  }
  static void add(Eigen::Matrix<Scalar, 9, Eigen::Dynamic>& s, int i, int j,
                  const Matrix3<Scalar>& a) {
    Eigen::Map<Matrix3<Scalar>>(s.col(detail::band_block_index(i, j)).data()) += a;
  }
};

/// \brief The whole Jacobian of compute_forces at (x, v) with the water held, into `jac`:
/// ∂F_i/∂x_j, ∂F_i/∂v_j and ∂(M_i(x) d_i)/∂x_j for every node (kinematic ends included).
///
/// Exact, analytic, for every term of compute_forces: axial force on the branch it took
/// (elastic, dashpot with its direction dependence ∂(u·e)/∂x = P e/l_s, clamped at zero or not),
/// geometric stiffness T P/l_s (also for a compressive T), bending, Morison drag with the
/// tangent's dependence on the chord (q = c/|c|, ∂q/∂c = P/|c|), Froude–Krylov and added-mass
/// forcing, the added-mass rate terms (G_i on node i, w_i on the chord's nodes, which reach
/// i ± 2: the Jacobian is block-pentadiagonal and not symmetric), the surface band (buoyancy,
/// drag, forcing, added mass scale with φ_i, which depends on z_{i−1}, z_i and z_{i+1} through
/// the segments' wet lengths, detail::node_wetness; the surface elevation is held), seabed spring,
/// ramped damper and friction (through the normal force unless TetherWorkspace::frozen_friction).
/// At a kink (segment at its rest length or force at zero, φ at 0 or 1, seabed touch, |v_n| = 0,
/// |v_h| = v_f) it is the derivative of the branch compute_forces took.
/// \param[in] model the tether \param[in] ws the workspace of the last compute_forces, which
/// must have been at (x, v) \param[in] env the environment (density, gravity, seabed depth)
/// \param[in] x, v node positions and velocities 3×(N+1) \param[in] d vector of the mass term
/// (3×(N+1)) \param[out] jac zeroed, then filled.
/// \throws kelp::invalid_argument when the sizes do not fit the model.
/// \tparam Scalar double or float (deduced from the model).
/// \tparam Env the environment type (kelp/tether/lumped_mass.hpp).
/// \tparam DX an Eigen 3×(N+1) matrix type (positions).
/// \tparam DV an Eigen 3×(N+1) matrix type (velocities).
/// \tparam DD an Eigen 3×(N+1) matrix type (the mass term's vector).
template <typename Scalar, typename Env, typename DX, typename DV, typename DD>
void force_jacobian(const TetherModel<Scalar>& model, const TetherWorkspace<Scalar>& ws,
                    const Env& env, const Eigen::MatrixBase<DX>& x, const Eigen::MatrixBase<DV>& v,
                    const Eigen::MatrixBase<DD>& d, ForceJacobian<Scalar>& jac) {
  detail::check_workspace(model, ws);
  const Eigen::Index cols = model.nodes();
  KELP_CHECK(x.rows() == 3 && x.cols() == cols && v.rows() == 3 && v.cols() == cols &&
                 d.rows() == 3 && d.cols() == cols,
             "force_jacobian: x, v and d must be 3 x (segments + 1)");
  KELP_CHECK(
      jac.dfdx.cols() == 5 * cols && jac.dfdv.cols() == 5 * cols && jac.dmdx.cols() == 5 * cols,
      "force_jacobian: jac was not built for this tether: use ForceJacobian(model)");
  jac.dfdx.setZero();
  jac.dfdv.setZero();
  jac.dmdx.setZero();
  detail::force_jacobian_blocks(model, ws, env, x, v, &d,
                                static_cast<const VectorX<Scalar>*>(nullptr), jac);
}

}  // namespace kelp::tether
