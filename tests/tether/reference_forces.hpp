// The scalar force evaluation kelp shipped before its SIMD passes (kelp::tether::compute_forces
// up to commit 0aea047), kept verbatim apart from its name and namespace as the reference that
// the vectorised passes must reproduce (test_force_passes.cpp).
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "kelp/core/constants.hpp"
#include "kelp/tether/lumped_mass.hpp"

namespace kelp_test {

namespace kt = kelp::tether;
using kelp::Matrix3X;
using kelp::Vector3;

template <bool WithJacobian = false, typename Scalar, typename Env, typename DX, typename DV>
void reference_compute_forces(const kt::TetherModel<Scalar>& model, kt::TetherWorkspace<Scalar>& ws,
                              const Env& env, double t, const Eigen::MatrixBase<DX>& x,
                              const Eigen::MatrixBase<DV>& v) {
  using std::abs;
  using std::sqrt;
  using V3 = Vector3<Scalar>;
  const kt::TetherParameters<Scalar>& p = model.parameters();
  const int n = model.segments();
  const Scalar rho = Scalar(env.water_density());
  const Scalar g = Scalar(env.gravity());
  const Scalar bed = Scalar(env.seabed_depth());
  const Scalar l = model.segment_length(), l2 = l * l, inv_l = model.inverse_segment_length();
  const Scalar ea_l = model.axial_spring(), ba_l = model.axial_damper();
  const Scalar ea = p.axial_stiffness, ba = p.internal_damping;

  // Water velocity and acceleration at the nodes; a still environment (no waves, no current)
  // gives zeros everywhere, which the buffers keep from the last time they were zeroed.
  const bool still = kt::detail::is_still_water(env);
  if (!still) {
    if (!ws.water_frozen) {
      ws.water_is_zero = false;
      kt::detail::sample_water_at_nodes(env, x, t, ws);
    }
  } else if (!ws.water_is_zero) {
    ws.water_velocity.setZero();
    ws.water_acceleration.setZero();
    ws.surface_elevation.setZero();
    ws.water_is_zero = true;
  }

  // Segments: elastic tension EA·ε when stretched plus the internal dashpot BA·ε̇, which acts
  // whether or not the segment is stretched, so that the axial force is continuous in the node
  // positions (a dashpot switched on at l_s = l would make it jump, which Newton's method cannot
  // handle); the sum is clamped at zero (a cable cannot push) unless compressive_damping. The
  // clamp is a kink like the one of the elastic force at l_s = l; the implicit schemes' active
  // set handles both (kt::detail::active_set_direction). Returns T_s u_s.
  // kelp's line fades the dashpot out on a segment shorter than l_f = l/10 (0: no fade):
  // σ(l_s) BA·ε̇ with the smoothstep σ = ρ²(3 − 2ρ), ρ = l_s/l_f (TetherModel::dashpot_fade);
  // its slope σ' BA/l ε̇ joins the axial stiffness where it is positive.
  const bool clamp = !p.compressive_damping;
  const Scalar lf = model.dashpot_fade_length();
  const auto segment = [&](int s) -> V3 {
    const V3 d = x.col(s + 1) - x.col(s);
    const Scalar ls2 = d.squaredNorm();
    const Scalar ls = sqrt(ls2);
    ws.stretched_length(s) = ls;
    const bool fading = lf > Scalar(0) && ls < lf;
    const Scalar rf = fading ? ls / lf : Scalar(1);
    const Scalar sigma = rf * rf * (Scalar(3) - Scalar(2) * rf);
    const Scalar sigma_slope = fading ? Scalar(6) * rf * (Scalar(1) - rf) / lf : Scalar(0);
    Scalar tension(0), k_axial(0), c_axial(ba_l * sigma);
    V3 u = V3::Zero();
    if (ls > Scalar(0)) {
      const Scalar inv_ls = Scalar(1) / ls;
      u = d * inv_ls;
      if (ls2 > l2) {
        tension = ea * (ls - l) * inv_l;
        k_axial = ea_l;
      }
      if (ba != Scalar(0)) {
        const Scalar rate = u.dot(v.col(s + 1) - v.col(s));
        if constexpr (WithJacobian) ws.seg_rate(s) = rate;
        tension += ba * rate * inv_l * sigma;
        if (sigma_slope * ba_l * rate > Scalar(0)) k_axial += sigma_slope * ba_l * rate;
        if (clamp && !(tension > Scalar(0))) {
          tension = Scalar(0);
          k_axial = c_axial = Scalar(0);
        }
      } else if constexpr (WithJacobian) {
        ws.seg_rate(s) = Scalar(0);
      }
      if constexpr (WithJacobian) {
        // ∂(T u)/∂x_{s+1} = k_axial u uᵀ + (T/l_s)(I − u uᵀ); the geometric term is kept only for
        // T > 0 so that the Jacobian stays positive semi-definite.
        const Scalar k_perp = tension > Scalar(0) ? tension * inv_ls : Scalar(0);
        ws.seg_k_uu(s) = k_axial - k_perp;
        ws.seg_k_perp(s) = k_perp;
      }
    } else if constexpr (WithJacobian) {
      ws.seg_k_uu(s) = ws.seg_k_perp(s) = ws.seg_rate(s) = Scalar(0);
    }
    ws.direction.col(s) = u;
    ws.tension(s) = tension;
    if constexpr (WithJacobian) ws.seg_c_uu(s) = c_axial;
    return tension * u;
  };

  // Bending: E_i = k (1 − c), c = u_a·u_b, k = EI/l at interior node i between segment a (i−1)
  // and b (i); F_{i−1} = −k (u_b − c u_a)/l_a, F_{i+1} = k (u_a − c u_b)/l_b, F_i = −F_{i−1} −
  // F_{i+1}. It needs every segment first; without it the segments are computed inside the node
  // loop (one pass over the line).
  const bool bending = p.bending_stiffness > Scalar(0);
  if (bending) {
    for (int s = 0; s < n; ++s) segment(s);
    ws.bending.setZero();
    const Scalar k = p.bending_stiffness * inv_l;
    for (int i = 1; i < n; ++i) {
      const Scalar la = ws.stretched_length(i - 1), lb = ws.stretched_length(i);
      if (!(la > Scalar(0) && lb > Scalar(0))) continue;
      const V3 ua = ws.direction.col(i - 1), ub = ws.direction.col(i);
      const Scalar c = ua.dot(ub);
      const V3 fa = (-k / la) * (ub - c * ua);
      const V3 fb = (k / lb) * (ua - c * ub);
      ws.bending.col(i - 1) += fa;
      ws.bending.col(i + 1) += fb;
      ws.bending.col(i) -= fa + fb;
    }
  }

  // Nodes. The interior nodes share their mass, volume and length; the constants of the three
  // kinds of node (start, interior, end) are computed once per evaluation.
  const Scalar half_rho_d = Scalar(0.5) * rho * p.diameter;
  const Scalar kn_per_l = half_rho_d * p.normal_drag;
  const Scalar kt_per_l = half_rho_d * Scalar(kelp::pi) * p.tangential_drag;
  const Scalar can = p.normal_added_mass, cat = p.tangential_added_mass;
  const Scalar bed_k = p.seabed_stiffness * p.diameter, bed_c = p.seabed_damping * p.diameter;
  struct NodeConstants {
    Scalar li, dry_weight, wet_weight, rho_vol, kn, kt, mass_dry, mass_iso_wet, mass_tan_wet;
    // The constants of a node with submerged fraction φ (fluid terms scaled by φ).
    NodeConstants submerged(Scalar phi) const {
      NodeConstants c = *this;
      c.wet_weight = dry_weight + phi * (wet_weight - dry_weight);
      c.rho_vol = phi * rho_vol;
      c.kn = phi * kn;
      c.kt = phi * kt;
      c.mass_iso_wet = mass_dry + phi * (mass_iso_wet - mass_dry);
      c.mass_tan_wet = phi * mass_tan_wet;
      return c;
    }
  };
  const auto node_constants = [&](int i) {
    const Scalar m = model.node_mass(i), vol = model.node_volume(i), li = model.node_length(i);
    return NodeConstants{li,
                         m * g,
                         (m - rho * vol) * g,
                         rho * vol,
                         kn_per_l * li,
                         kt_per_l * li,
                         m,
                         m + rho * vol * can,
                         rho * vol * (cat - can)};
  };
  const NodeConstants kinds[3] = {node_constants(0), node_constants(n > 1 ? 1 : 0),
                                  node_constants(n)};
  // Added-mass rate terms (see the function's documentation); none when Cat = Can (b = 0).
  const bool mass_turns = cat != can;
  const Scalar inv_d = Scalar(1) / p.diameter;
  V3 tu_prev = V3::Zero();  // T_{i−1} u_{i−1}
  V3 carry = V3::Zero();    // ∂T/∂x_{i} from node i − 1's tangent, added when node i is built
  for (int i = 0; i <= n; ++i) {
    // Tangent: unit(r_{i+1} − r_{i−1}) inside, the adjacent segment at the ends.
    // The drag below is written with the unnormalised chord and 1/|c|² so that its square root
    // and the tangent's run in parallel instead of one after the other.
    const kt::detail::NodeTangent<Scalar> nt = kt::detail::node_tangent<Scalar>(x, i, n);
    const V3& chord = nt.chord;
    const Scalar inv_c2 = nt.inv_c2, inv_c = nt.inv_c;
    const V3& q = nt.q;
    ws.tangent.col(i) = q;

    V3 f;
    if (i < n) {
      const V3 tu = bending ? V3(ws.tension(i) * ws.direction.col(i)) : segment(i);
      f = tu - tu_prev;
      tu_prev = tu;
    } else {
      f = -tu_prev;
    }
    if (bending) f += ws.bending.col(i);
    if (mass_turns) {
      f += carry;
      carry.setZero();
    }

    const int kind = i == 0 ? 0 : (i == n ? 2 : 1);
    const Scalar li = kinds[kind].li;
    // The wet share of the node's half segments (kt::detail::node_wetness, tested on its own
    // against quadrature), 1 when it and its neighbours are half a diameter or more below.
    const auto depth = [&](int j) {
      return Scalar(x(2, j)) + (still ? Scalar(0) : ws.surface_elevation(j));
    };
    const Scalar d_lo = depth(i > 0 ? i - 1 : i), d_i = depth(i), d_hi = depth(i < n ? i + 1 : i);
    const Scalar half_d = Scalar(0.5) * p.diameter;
    const kt::detail::NodeWetness<Scalar> wetness =
        d_lo >= half_d && d_i >= half_d && d_hi >= half_d
            ? kt::detail::NodeWetness<Scalar>{Scalar(1), Scalar(0), Scalar(0), Scalar(0)}
            : kt::detail::node_wetness(d_lo, d_i, d_hi, i > 0 ? model.segment_length() : Scalar(0),
                                       i < n ? model.segment_length() : Scalar(0), i > 0, i < n,
                                       p.diameter, inv_d);
    const Scalar phi = wetness.phi;
    ws.submerged(i) = phi;
    const bool wet = phi > Scalar(0);
    // A node in the surface band (0 < φ < 1) scales its wet constants by φ.
    NodeConstants band;
    const bool in_band = wet && phi < Scalar(1);
    const NodeConstants& nc = in_band ? (band = kinds[kind].submerged(phi)) : kinds[kind];
    // −∂F_i/∂v_i (symmetric: xx, yx, zx, yy, zy, zz), filled only WithJacobian.
    Scalar dv[6] = {Scalar(0), Scalar(0), Scalar(0), Scalar(0), Scalar(0), Scalar(0)};
    if (wet) {
      f(2) += nc.wet_weight;
      // Morison drag on the relative velocity, split along q.
      const V3 vr = ws.water_velocity.col(i) - v.col(i);
      const Scalar vc = vr.dot(chord);  // = |c| v_q
      const V3 vn = vr - (vc * inv_c2) * chord;
      const Scalar vn_abs = sqrt(vn.squaredNorm());
      const Scalar vq = vc * inv_c;
      const Scalar kn = nc.kn, kt = nc.kt;
      f += (kn * vn_abs) * vn + (kt * abs(vq) * vq) * q;
      // Froude–Krylov plus added-mass forcing from the water acceleration.
      const V3 aw = ws.water_acceleration.col(i);
      if (!still && aw.squaredNorm() > Scalar(0))  // skipped in still water and steady current
        f += nc.rho_vol * ((Scalar(1) + can) * aw + ((cat - can) * q.dot(aw)) * q);
      ws.mass_iso(i) = nc.mass_iso_wet;
      ws.mass_tan(i) = nc.mass_tan_wet;
      if (mass_turns && inv_c > Scalar(0)) {
        // Added-mass rate terms, written with w_r = u_water − v = −v_r (vr above; both factors
        // of each term flip sign): G_i = b[(q̇·w_r) q + s q̇] and ∂T/∂x = ±b s P w_r/|c| with
        // s = q·w_r = vq, P w_r = vn, q̇ = P (v_hi − v_lo)/|c|.
        // With k = b/|c| and dc = v_hi − v_lo: G_i = k[s dc + (dc·vn − s q·dc) q], w = k s vn.
        const int hi = i < n ? i + 1 : n, lo = i > 0 ? i - 1 : 0;
        const Scalar k = nc.mass_tan_wet * inv_c, ks = k * vq;
        const V3 dc = v.col(hi) - v.col(lo);
        f += ks * dc + (k * dc.dot(vn) - ks * q.dot(dc)) * q;
        const V3 w = ks * vn;
        if (hi == i)
          f += w;
        else
          carry = w;
        if (lo == i)
          f -= w;
        else
          ws.force.col(lo) -= w;
      }
      if constexpr (WithJacobian) {
        // −∂F/∂v of the drag (q held fixed): kn(|v_n| P + v_n v_nᵀ/|v_n|) + 2 kt |v_q| q qᵀ
        // = c1 I + (c3 − c1) q qᵀ + cn v_n v_nᵀ.
        const Scalar c1 = kn * vn_abs, cn = vn_abs > Scalar(0) ? kn / vn_abs : Scalar(0);
        const Scalar c31 = Scalar(2) * kt * abs(vq) - c1;
        dv[0] = c1 + c31 * q(0) * q(0) + cn * vn(0) * vn(0);
        dv[1] = c31 * q(1) * q(0) + cn * vn(1) * vn(0);
        dv[2] = c31 * q(2) * q(0) + cn * vn(2) * vn(0);
        dv[3] = c1 + c31 * q(1) * q(1) + cn * vn(1) * vn(1);
        dv[4] = c31 * q(2) * q(1) + cn * vn(2) * vn(1);
        dv[5] = c1 + c31 * q(2) * q(2) + cn * vn(2) * vn(2);
      }
    } else {
      f(2) += nc.dry_weight;
      ws.mass_iso(i) = nc.mass_dry;
      ws.mass_tan(i) = Scalar(0);
    }
    // Seabed: spring–damper normal force (never pulling) and saturated-viscous friction.
    Scalar normal(0), kz(0);
    const Scalar pen = x(2, i) - bed;
    if (pen > Scalar(0)) {
      const Scalar ramp = pen < p.seabed_damping_depth ? pen / p.seabed_damping_depth : Scalar(1);
      normal = (pen * bed_k + v(2, i) * bed_c * ramp) * li;
      if (normal > Scalar(0)) {
        f(2) -= normal;
        kz = bed_k * li;
        // The ramp's ∂/∂z while landing (ż > 0); left out when rising, where it is negative.
        if (ramp < Scalar(1) && v(2, i) > Scalar(0))
          kz += v(2, i) * bed_c * li / p.seabed_damping_depth;
        if constexpr (WithJacobian) dv[5] += bed_c * ramp * li;
        if (p.seabed_friction > Scalar(0)) {
          const Scalar vh2 = v(0, i) * v(0, i) + v(1, i) * v(1, i);
          const Scalar vf = p.friction_velocity;
          // The implicit steps hold the normal force of the start of the step (see
          // TetherWorkspace::frozen_friction).
          const Scalar fmax =
              p.seabed_friction * (ws.frozen_friction ? ws.friction_normal(i) : normal);
          const Scalar coef = vh2 > vf * vf ? fmax / sqrt(vh2) : fmax / vf;
          f(0) -= coef * v(0, i);
          f(1) -= coef * v(1, i);
          if constexpr (WithJacobian) {
            dv[0] += coef;
            dv[3] += coef;
          }
        }
      } else {
        normal = Scalar(0);
      }
    }
    ws.seabed_force(i) = normal;
    // In the surface band the buoyancy −φ ρ V g grows with depth: a restoring spring ρ V g / D.
    if (in_band) kz += kinds[kind].rho_vol * g * wetness.d_self;
    if constexpr (WithJacobian) {
      for (int k = 0; k < 6; ++k) ws.node_dv(k, i) = dv[k];
      ws.node_kz(i) = kz;
    }
    ws.force.col(i) = f;
  }
}

}  // namespace kelp_test
