/// \file
/// \brief Lumped-mass tether force evaluation: `compute_forces` (axial tension, internal
/// damping, optional bending stiffness, weight and buoyancy, Morison drag, added mass,
/// fluid-inertia forcing, seabed contact with friction), the accelerations and end forces derived
/// from it, and the line's mechanical energy. The scalar node pass lives here; the SIMD packet
/// kernels in kelp/tether/force_kernels.hpp.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <utility>

#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/simd.hpp"
#include "kelp/core/simd_avx2.hpp"
#include "kelp/core/types.hpp"
#include "kelp/tether/contact.hpp"
#include "kelp/tether/force_kernels.hpp"
#include "kelp/tether/model.hpp"
#include "kelp/tether/state.hpp"

namespace kelp::tether {

namespace detail {

/// True for environments that can say they are still water at all times through
/// `bool is_still_water() const`, as kelp::environment::Environment can. Other environments are
/// always queried.
template <typename Env, typename = void>
struct has_still_water_query : std::false_type {};
template <typename Env>
struct has_still_water_query<
    Env, std::void_t<decltype(bool(std::declval<const Env&>().is_still_water()))>>
    : std::true_type {};

/// True for environments that sample the free-surface elevation along with the water
/// kinematics: `sample_water(points, t, velocity, acceleration, elevation)`, as
/// kelp::environment::Environment can. Other environments are asked `surface_elevation(x, y, t)`
/// node by node.
template <typename Env, typename Scalar, typename = void>
struct has_batch_surface : std::false_type {};
template <typename Env, typename Scalar>
struct has_batch_surface<
    Env, Scalar,
    std::void_t<decltype(std::declval<const Env&>().sample_water(
        std::declval<const Matrix3X<Scalar>&>(), 0.0, std::declval<Matrix3X<Scalar>&>(),
        std::declval<Matrix3X<Scalar>&>(), std::declval<VectorX<Scalar>&>()))>> : std::true_type {};

/// Converts to any lvalue reference: the probe of `has_five_argument_sample_water` (declared
/// only; never called).
struct AnySampleWaterArgument {
  template <typename T>
  operator T&() const;
};

/// True for environments with a `sample_water` of five parameters of any types, const or not:
/// with `has_batch_surface` false, a near miss of the five-argument signature (which the
/// tether would otherwise pass over silently for the per-node elevation queries).
template <typename Env, typename = void>
struct has_five_argument_sample_water : std::false_type {};
template <typename Env>
struct has_five_argument_sample_water<
    Env, std::void_t<decltype(std::declval<Env&>().sample_water(
             AnySampleWaterArgument{}, AnySampleWaterArgument{}, AnySampleWaterArgument{},
             AnySampleWaterArgument{}, AnySampleWaterArgument{}))>> : std::true_type {};

/// Water velocity, acceleration and surface elevation at the points `x` into the workspace.
template <typename Scalar, typename Env, typename DX>
void sample_water_at_nodes(const Env& env, const Eigen::MatrixBase<DX>& x, double t,
                           TetherWorkspace<Scalar>& ws) {
  static_assert(
      has_batch_surface<Env, Scalar>::value || !has_five_argument_sample_water<Env>::value,
      "kelp::tether: the environment's five-argument sample_water cannot be called "
      "as the tether calls it; it must be `void sample_water(const "
      "Eigen::Ref<const kelp::Matrix3X<Scalar>>& points, double t, "
      "Eigen::Ref<kelp::Matrix3X<Scalar>> velocity, Eigen::Ref<kelp::Matrix3X<Scalar>> "
      "acceleration, Eigen::Ref<kelp::VectorX<Scalar>> elevation) const` with the "
      "tether's Scalar (docs/custom-environment.md)");
  if constexpr (has_batch_surface<Env, Scalar>::value) {
    env.sample_water(x, t, ws.water_velocity, ws.water_acceleration, ws.surface_elevation);
  } else {
    env.sample_water(x, t, ws.water_velocity, ws.water_acceleration);
    for (Eigen::Index i = 0; i < x.cols(); ++i)
      ws.surface_elevation(i) = Scalar(env.surface_elevation(x(0, i), x(1, i), t));
  }
}

/// True when `env` reports still water: its water velocity and acceleration are zero everywhere
/// and at all times.
template <typename Env>
bool is_still_water(const Env& env) {
  if constexpr (has_still_water_query<Env>::value)
    return env.is_still_water();
  else
    return false;
}

/// Tangent of node i of a line of n segments: the chord c = r_{i+1} − r_{i−1} inside (the
/// adjacent segment at the ends), 1/|c|² and 1/|c| (both zero for a zero chord) and the unit
/// tangent q = c/|c| (zero for a zero chord).
template <typename Scalar>
struct NodeTangent {
  Vector3<Scalar> chord;
  Scalar inv_c2, inv_c;
  Vector3<Scalar> q;
};

/// The two nodes whose difference is node i's chord, x_hi − x_lo: i ± 1 inside a piece of line,
/// the node itself on the side of an end (node 0, node n, or a segment that has parted:
/// `parted` null or one flag per segment), so that the free end of a parted piece takes its
/// own segment's direction as the ends of the line do.
struct ChordNodes {
  int lo, hi;
};
inline ChordNodes chord_nodes(int i, int n, const std::uint8_t* parted = nullptr) {
  const bool cut_before = i == 0 || (parted && parted[i - 1]);
  const bool cut_after = i == n || (parted && parted[i]);
  return {cut_before ? i : i - 1, cut_after ? i : i + 1};
}

/// The NodeTangent of node i of positions `x` (3 × (n+1)); `parted` as in chord_nodes.
template <typename Scalar, typename DX>
NodeTangent<Scalar> node_tangent(const Eigen::MatrixBase<DX>& x, int i, int n,
                                 const std::uint8_t* parted = nullptr) {
  using std::sqrt;
  NodeTangent<Scalar> t;
  const ChordNodes cn = chord_nodes(i, n, parted);
  t.chord = x.col(cn.hi) - x.col(cn.lo);
  const Scalar c2 = t.chord.squaredNorm();
  t.inv_c2 = c2 > Scalar(0) ? Scalar(1) / c2 : Scalar(0);
  t.inv_c = sqrt(t.inv_c2);
  t.q = t.chord * t.inv_c;
  return t;
}

/// Submerged fraction φ of the cable's cross-section at NED depth z [m] under a free surface at
/// elevation ζ [m]: the cross-section of diameter D goes under over one diameter centred on the
/// line, taken as a linear ramp φ = clamp((z + ζ)/D + ½, 0, 1): ½ exactly at the surface, 1
/// (wet) at least half a diameter below it, 0 (in air) at least half a diameter above it. This
/// is the convention of the vehicles, whose band of one hull height is centred on the centre of
/// buoyancy (vehicle::submerged_fraction). Integrated along each segment (segment_wetness), it
/// gives the nodes' submerged fractions, by which buoyancy, drag, fluid inertia and added mass
/// scale, so the node forces are continuous in the positions (an on/off switch at the surface
/// would leave Newton's method no solution to converge to when a floating line rests at the
/// surface).
template <typename Scalar>
Scalar submerged_fraction(Scalar z, Scalar zeta, Scalar diameter,
                          Scalar inv_diameter = Scalar(-1)) {
  if (inv_diameter < Scalar(0)) inv_diameter = Scalar(1) / diameter;
  const Scalar f = (z + zeta) * inv_diameter + Scalar(0.5);
  return f >= Scalar(1) ? Scalar(1) : (f > Scalar(0) ? f : Scalar(0));
}

/// Antiderivative Φ of submerged_fraction in the depth d = z + ζ: 0 in air (d ≤ −D/2),
/// (d + D/2)²/(2D) in the band and d when wet (d ≥ D/2). The buoyancy potential of a node is
/// +ρ V g Φ [J] (NED z down: its force −ρ V g φ e_z is −∂/∂z of it).
template <typename Scalar>
Scalar submerged_depth_integral(Scalar z, Scalar zeta, Scalar diameter) {
  const Scalar d = z + zeta, half = Scalar(0.5) * diameter;
  if (d >= half) return d;
  if (d <= -half) return Scalar(0);
  return (d + half) * (d + half) / (Scalar(2) * diameter);
}

/// How much of one straight segment is under the surface, lumped on its two nodes: with the depth
/// d(s) = d_a + s (d_b − d_a) along it (s ∈ [0, 1], d = z + ζ at each node, the surface taken as
/// straight between the nodes) and φ(d) the cross-section's submerged fraction
/// (submerged_fraction), a = ∫₀¹ (1 − s) φ ds goes to node a and b = ∫₀¹ s φ ds to node b, the
/// linear shape functions' weights. a + b is the segment's exact submerged fraction, which the
/// crossing point decides and not the nodes' own depths; the buoyancy so lumped is −∂/∂z of the
/// segment's potential (segment_depth_integral), and a level segment gives a = b = φ/2, the node
/// rule of a line lying on the surface. The derivatives daa = ∂a/∂d_a, dab = ∂a/∂d_b = ∂b/∂d_a,
/// dbb = ∂b/∂d_b [1/m] are the integrals of φ' = 1/D over the band against (1 − s)², s (1 − s) and
/// s² (zero in air and in the wholly wet water). Integrated in closed form over the pieces of
/// [0, 1] where φ is 0, linear or 1.
/// Returns a SegmentWetness (declared in kelp/tether/force_kernels.hpp).
template <typename Scalar>
SegmentWetness<Scalar> segment_wetness(Scalar da, Scalar db, Scalar diameter, Scalar inv_d) {
  using std::abs;
  const Scalar half = Scalar(0.5) * diameter, zero(0), one(1);
  SegmentWetness<Scalar> w{zero, zero, zero, zero, zero};
  if (da >= half && db >= half) {
    w.a = w.b = Scalar(0.5);
    return w;
  }
  if (da <= -half && db <= -half) return w;
  const Scalar delta = db - da;
  if (abs(delta) <= Scalar(1e-6) * diameter) {
    // Level to a millionth of the band: φ and φ' of the mid-depth all along.
    const Scalar mid = Scalar(0.5) * (da + db);
    const Scalar phi = submerged_fraction(mid, zero, diameter, inv_d);
    w.a = w.b = Scalar(0.5) * phi;
    if (phi > zero && phi < one) {
      w.daa = w.dbb = inv_d / Scalar(3);
      w.dab = inv_d / Scalar(6);
    }
    return w;
  }
  const auto clamp01 = [&](Scalar s) { return s <= zero ? zero : (s >= one ? one : s); };
  const Scalar inv_delta = one / delta;
  const Scalar s_air = clamp01((-half - da) * inv_delta);  // where d = −D/2
  const Scalar s_wet = clamp01((half - da) * inv_delta);   // where d = +D/2
  // Wholly wet beyond s_wet on the deeper side.
  const Scalar w0 = delta > zero ? s_wet : zero, w1 = delta > zero ? one : s_wet;
  w.b = Scalar(0.5) * (w1 * w1 - w0 * w0);
  w.a = (w1 - w0) - w.b;
  // The band between s_air and s_wet: φ = α + β s.
  const Scalar r0 = delta > zero ? s_air : s_wet, r1 = delta > zero ? s_wet : s_air;
  if (r1 > r0) {
    const Scalar alpha = da * inv_d + Scalar(0.5), beta = delta * inv_d;
    const Scalar m0 = r1 - r0, m1 = Scalar(0.5) * (r1 * r1 - r0 * r0),
                 m2 = (r1 * r1 * r1 - r0 * r0 * r0) / Scalar(3);
    const Scalar i0 = alpha * m0 + beta * m1, i1 = alpha * m1 + beta * m2;
    w.a += i0 - i1;
    w.b += i1;
    const Scalar u0 = one - r0, u1 = one - r1;
    w.daa = inv_d * (u0 * u0 * u0 - u1 * u1 * u1) / Scalar(3);
    w.dab = inv_d * (m1 - m2);
    w.dbb = inv_d * m2;
  }
  return w;
}

/// ∫₀¹ Φ(d_a + s (d_b − d_a)) ds, Φ = submerged_depth_integral: the buoyancy potential of a
/// segment is ρ g A l times it (A the cross-section, l the unstretched length), and its
/// derivatives in d_a and d_b are segment_wetness's a and b. Simpson's rule on each piece where Φ
/// is 0, quadratic or linear, which it integrates exactly.
template <typename Scalar>
Scalar segment_depth_integral(Scalar da, Scalar db, Scalar diameter) {
  using std::abs;
  const Scalar half = Scalar(0.5) * diameter, zero(0), one(1);
  const Scalar delta = db - da;
  const auto big_phi = [&](Scalar s) {
    return submerged_depth_integral(da + s * delta, zero, diameter);
  };
  if (abs(delta) <= Scalar(1e-6) * diameter) return big_phi(Scalar(0.5));
  const auto clamp01 = [&](Scalar s) { return s <= zero ? zero : (s >= one ? one : s); };
  Scalar cut[2] = {clamp01((-half - da) / delta), clamp01((half - da) / delta)};
  if (cut[1] < cut[0]) std::swap(cut[0], cut[1]);
  const Scalar edges[4] = {zero, cut[0], cut[1], one};
  Scalar sum(0);
  for (int k = 0; k < 3; ++k) {
    const Scalar p = edges[k], q = edges[k + 1];
    if (q > p)
      sum += (q - p) / Scalar(6) *
             (big_phi(p) + Scalar(4) * big_phi(Scalar(0.5) * (p + q)) + big_phi(q));
  }
  return sum;
}

/// Node i's submerged fraction φ_i (its share of line under the surface) and its derivatives
/// with respect to the depths d_{i−1}, d_i, d_{i+1}: the wet parts of its half segments,
/// (l_before b_{i−1} + l_after a_i) / ((l_before + l_after)/2) with segment_wetness's a and b,
/// l_before and l_after the unstretched lengths of the segments before and after it (zero at an
/// end). A segment that has parted (`joined_*` false) no longer spans a straight line between
/// its nodes: each node keeps its half at its own depth.
template <typename Scalar>
struct NodeWetness {
  Scalar phi, d_lo, d_self, d_hi;
};

/// node_wetness with the wetness of the segments beside the node from `segment(before)`, which
/// returns segment_wetness of the segment before the node (before = true: depths d_lo, d) or
/// after it (d, d_hi); the force passes keep the last one they computed (node_wetness_in_pass).
template <typename Scalar, typename SegmentOf>
NodeWetness<Scalar> node_wetness_with(Scalar d, Scalar l_before, Scalar l_after, bool joined_before,
                                      bool joined_after, Scalar diameter, Scalar inv_d,
                                      const SegmentOf& segment) {
  const Scalar zero(0), half(0.5);
  NodeWetness<Scalar> w{zero, zero, zero, zero};
  // The half segment of length l before (the node is the segment's end b) or after it (its end
  // a).
  const auto add_half = [&](Scalar l, bool joined, bool before) {
    if (!(l > zero)) return;
    if (!joined) {
      // A half segment held at the node's own depth: φ(d)/2 of it, ∂/∂d = φ'(d)/2.
      const Scalar phi_own = submerged_fraction(d, zero, diameter, inv_d);
      const Scalar dphi_own = phi_own > zero && phi_own < Scalar(1) ? inv_d : zero;
      w.phi += half * l * phi_own;
      w.d_self += half * l * dphi_own;
      return;
    }
    const SegmentWetness<Scalar> s = segment(before);
    w.phi += l * (before ? s.b : s.a);
    (before ? w.d_lo : w.d_hi) += l * s.dab;
    w.d_self += l * (before ? s.dbb : s.daa);
  };
  add_half(l_before, joined_before, true);
  add_half(l_after, joined_after, false);
  const Scalar inv_h = Scalar(2) / (l_before + l_after);
  w.phi *= inv_h;
  w.d_lo *= inv_h;
  w.d_self *= inv_h;
  w.d_hi *= inv_h;
  return w;
}

template <typename Scalar>
NodeWetness<Scalar> node_wetness(Scalar d_lo, Scalar d, Scalar d_hi, Scalar l_before,
                                 Scalar l_after, bool joined_before, bool joined_after,
                                 Scalar diameter, Scalar inv_d) {
  return node_wetness_with(d, l_before, l_after, joined_before, joined_after, diameter, inv_d,
                           [&](bool before) {
                             return before ? segment_wetness(d_lo, d, diameter, inv_d)
                                           : segment_wetness(d, d_hi, diameter, inv_d);
                           });
}

/// node_wetness of node i of a line of n segments: `depth(j)` the depth under the surface of
/// node j, `rest(s)` the unstretched length of segment s, `parted(s)` whether segment s has
/// parted, `segment_of(s, d_a, d_b)` segment_wetness of segment s between the depths d_a and d_b
/// of its nodes; φ = 1 without arithmetic when the node and its neighbours are half a diameter
/// or more below the surface.
template <typename Scalar, typename Depth, typename Rest, typename Parted, typename SegmentOf>
NodeWetness<Scalar> node_wetness_of(int i, int n, const Depth& depth, const Rest& rest,
                                    const Parted& parted, Scalar diameter, Scalar inv_d,
                                    const SegmentOf& segment_of) {
  const bool joined_before = i > 0 && !parted(i - 1);
  const bool joined_after = i < n && !parted(i);
  const Scalar d = depth(i), half_d = Scalar(0.5) * diameter;
  const Scalar d_lo = joined_before ? depth(i - 1) : d, d_hi = joined_after ? depth(i + 1) : d;
  if (d >= half_d && d_lo >= half_d && d_hi >= half_d)
    return {Scalar(1), Scalar(0), Scalar(0), Scalar(0)};
  return node_wetness_with(d, i > 0 ? rest(i - 1) : Scalar(0), i < n ? rest(i) : Scalar(0),
                           joined_before, joined_after, diameter, inv_d, [&](bool before) {
                             return before ? segment_of(i - 1, d_lo, d) : segment_of(i, d, d_hi);
                           });
}

/// node_wetness_of with each segment's wetness computed here.
template <typename Scalar, typename Depth, typename Rest, typename Parted>
NodeWetness<Scalar> node_wetness_of(int i, int n, const Depth& depth, const Rest& rest,
                                    const Parted& parted, Scalar diameter, Scalar inv_d) {
  return node_wetness_of<Scalar>(
      i, n, depth, rest, parted, diameter, inv_d,
      [&](int, Scalar da, Scalar db) { return segment_wetness(da, db, diameter, inv_d); });
}

/// node_wetness_of node i of a force pass (segment 0 at a winch: TetherWorkspace::winch_length).
/// A segment crossing the surface band serves the nodes at both its ends: the pass keeps the
/// last segment's wetness (ForcePass::wet_segment), which the node after it takes again.
template <typename Scalar>
NodeWetness<Scalar> node_wetness_in_pass(const ForcePass<Scalar>& c,
                                         const TetherWorkspace<Scalar>& ws, int i) {
  return node_wetness_of<Scalar>(
      i, c.n, [&](int j) { return c.still ? c.X(2, j) : c.X(2, j) + ws.surface_elevation(j); },
      [&](int s) { return c.winch && s == 0 ? ws.winch_length : c.l; },
      [&](int s) { return c.parted && c.parted[s]; }, c.p->diameter, c.inv_d,
      [&](int s, Scalar da, Scalar db) {
        if (c.wet_segment != s) {
          c.wet = segment_wetness(da, db, c.p->diameter, c.inv_d);
          c.wet_segment = s;
        }
        return c.wet;
      });
}

/// Node i, any kind and state (end node, surface band, in air, on the seabed): tangent, node
/// force without the added-mass coupling to the neighbours, that coupling term w_i, masses,
/// submerged fraction, seabed force and the Jacobian terms.
template <bool WithJacobian, typename Scalar>
void node_general(const ForcePass<Scalar>& c, TetherWorkspace<Scalar>& ws, int i) {
  using std::abs;
  using std::sqrt;
  using V3 = Vector3<Scalar>;
  const TetherParameters<Scalar>& p = *c.p;
  const int n = c.n;
  // Tangent: unit(r_{i+1} − r_{i−1}) inside, the adjacent segment at the ends. The drag below
  // is written with the unnormalised chord and 1/|c|² so that its square root and the
  // tangent's run in parallel instead of one after the other.
  const ChordNodes span = chord_nodes(i, n, c.parted);
  const int hi = span.hi, lo = span.lo;
  const NodeTangent<Scalar> nt = node_tangent<Scalar>(c.positions(), i, n, c.parted);
  const V3& chord = nt.chord;
  const Scalar inv_c2 = nt.inv_c2, inv_c = nt.inv_c;
  const V3& q = nt.q;
  ws.tangent.col(i) = q;
  V3 f;
  for (int k = 0; k < 3; ++k) {
    const Scalar in = i < n ? ws.pass_buffer(i, kSegmentForce + k) : Scalar(0);
    const Scalar out = i > 0 ? ws.pass_buffer(i - 1, kSegmentForce + k) : Scalar(0);
    f(k) = in - out;
  }
  const int kind = i == 0 ? 0 : (i == n ? 2 : (i == 1 && c.winch ? 3 : 1));
  const Scalar li = c.kinds[kind].li;
  const Scalar z = c.X(2, i);
  // The wet share of the node's half segments (φ = 1 without arithmetic when it and its
  // neighbours are half a diameter or more below the surface).
  const NodeWetness<Scalar> wetness = node_wetness_in_pass(c, ws, i);
  const Scalar phi = wetness.phi;
  ws.submerged(i) = phi;
  const bool wet = phi > Scalar(0);
  // A node in the surface band (0 < φ < 1) scales its wet constants by φ.
  NodeConstants<Scalar> band;
  const bool in_band = wet && phi < Scalar(1);
  const NodeConstants<Scalar>& nc = in_band ? (band = c.kinds[kind].submerged(phi)) : c.kinds[kind];
  // −∂F_i/∂v_i (symmetric: xx, yx, zx, yy, zy, zz), filled only WithJacobian.
  Scalar dv[6] = {Scalar(0), Scalar(0), Scalar(0), Scalar(0), Scalar(0), Scalar(0)};
  V3 w = V3::Zero();
  if (wet) {
    f(2) += nc.wet_weight;
    // Morison drag on the relative velocity, split along q.
    const V3 vi(c.V(0, i), c.V(1, i), c.V(2, i));
    const V3 vr = ws.water_velocity.col(i) - vi;
    const Scalar vc = (vr(0) * chord(0) + vr(1) * chord(1)) + vr(2) * chord(2);  // = |c| v_q
    const Scalar sc = vc * inv_c2;
    const V3 vn = vr - sc * chord;
    const Scalar vn_abs = sqrt((vn(0) * vn(0) + vn(1) * vn(1)) + vn(2) * vn(2));
    const Scalar vq = vc * inv_c;
    const Scalar kn = nc.kn, kt = nc.kt;
    const Scalar dn = kn * vn_abs, dt = (kt * abs(vq)) * vq;
    for (int k = 0; k < 3; ++k) f(k) += dn * vn(k) + dt * q(k);
    if (!c.still) {
      // Froude–Krylov plus added-mass forcing from the water acceleration.
      const V3 aw = ws.water_acceleration.col(i);
      const Scalar qa = (c.cat - c.can) * ((q(0) * aw(0) + q(1) * aw(1)) + q(2) * aw(2));
      for (int k = 0; k < 3; ++k) f(k) += nc.rho_vol * ((Scalar(1) + c.can) * aw(k) + qa * q(k));
    }
    ws.mass_iso(i) = nc.mass_iso_wet;
    ws.mass_tan(i) = nc.mass_tan_wet;
    if (c.mass_turns) {
      // Added-mass rate terms, written with w_r = u_water − v = −v_r (vr above; both factors
      // of each term flip sign): G_i = b[(q̇·w_r) q + s q̇] and ∂T/∂x = ±b s P w_r/|c| with
      // s = q·w_r = vq, P w_r = vn, q̇ = P (v_hi − v_lo)/|c|.
      // With k = b/|c| and dc = v_hi − v_lo: G_i = k[s dc + (dc·vn − s q·dc) q], w = k s vn,
      // which goes to node hi with a plus sign and to node lo with a minus sign.
      const Scalar k = nc.mass_tan_wet * inv_c, ks = k * vq;
      const V3 dc(c.V(0, hi) - c.V(0, lo), c.V(1, hi) - c.V(1, lo), c.V(2, hi) - c.V(2, lo));
      const Scalar m = k * ((dc(0) * vn(0) + dc(1) * vn(1)) + dc(2) * vn(2)) -
                       ks * ((q(0) * dc(0) + q(1) * dc(1)) + q(2) * dc(2));
      for (int j = 0; j < 3; ++j) f(j) += ks * dc(j) + m * q(j);
      w = ks * vn;
    }
    if constexpr (WithJacobian) {
      // −∂F/∂v of the drag (q held fixed): kn(|v_n| P + v_n v_nᵀ/|v_n|) + 2 kt |v_q| q qᵀ
      // = c1 I + (c3 − c1) q qᵀ + cn v_n v_nᵀ.
      const Scalar cn = vn_abs > Scalar(0) ? kn / vn_abs : Scalar(0);
      const Scalar c31 = (Scalar(2) * kt) * abs(vq) - dn;
      dv[0] = dn + c31 * q(0) * q(0) + cn * vn(0) * vn(0);
      dv[1] = c31 * q(1) * q(0) + cn * vn(1) * vn(0);
      dv[2] = c31 * q(2) * q(0) + cn * vn(2) * vn(0);
      dv[3] = dn + c31 * q(1) * q(1) + cn * vn(1) * vn(1);
      dv[4] = c31 * q(2) * q(1) + cn * vn(2) * vn(1);
      dv[5] = dn + c31 * q(2) * q(2) + cn * vn(2) * vn(2);
    }
  } else {
    f(2) += nc.dry_weight;
    ws.mass_iso(i) = nc.mass_dry;
    ws.mass_tan(i) = Scalar(0);
  }
  // Seabed: spring–damper normal force (never pulling) and saturated-viscous friction.
  Scalar normal(0), kz(0);
  const Scalar pen = z - c.bed;
  if (pen > Scalar(0)) {
    const Scalar vz = c.V(2, i);
    const Scalar ramp = pen < p.seabed_damping_depth ? pen / p.seabed_damping_depth : Scalar(1);
    normal = (pen * c.bed_k + vz * c.bed_c * ramp) * li;
    if (normal > Scalar(0)) {
      f(2) -= normal;
      kz = c.bed_k * li;
      // The ramp's ∂/∂z while landing (ż > 0); left out when rising, where it is negative.
      if (ramp < Scalar(1) && vz > Scalar(0)) kz += vz * c.bed_c * li / p.seabed_damping_depth;
      if constexpr (WithJacobian) dv[5] += c.bed_c * ramp * li;
      if (p.seabed_friction > Scalar(0)) {
        const Scalar vx = c.V(0, i), vy = c.V(1, i);
        const Scalar vh2 = vx * vx + vy * vy;
        const Scalar vf = p.friction_velocity;
        // The implicit steps hold the normal force of the start of the step (see
        // TetherWorkspace::frozen_friction).
        const Scalar fmax =
            p.seabed_friction * (ws.frozen_friction ? ws.friction_normal(i) : normal);
        const Scalar coef = vh2 > vf * vf ? fmax / sqrt(vh2) : fmax / vf;
        f(0) -= coef * vx;
        f(1) -= coef * vy;
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
  ws.mass_iso_inv(i) = Scalar(1) / ws.mass_iso(i);
  ws.mass_tan_ratio(i) = ws.mass_tan(i) / (ws.mass_iso(i) + ws.mass_tan(i));
  // In the surface band the buoyancy −φ ρ V g grows with depth: a restoring spring ρ V g ∂φ_i/∂z_i.
  // (φ_i depends on the neighbours' depths too; the symmetric Jacobian keeps its diagonal only:
  // its off-diagonal blocks are the segments'. Lumping the row's sum on the diagonal instead took
  // the static solver 2-4 times as many iterations on a floating line.)
  if (in_band) kz += c.kinds[kind].rho_vol * c.g * wetness.d_self;
  if constexpr (WithJacobian) {
    for (int k = 0; k < 6; ++k) ws.node_dv(k, i) = dv[k];
    ws.node_kz(i) = kz;
  }
  for (int k = 0; k < 3; ++k) {
    ws.pass_buffer(i, kNodeForce + k) = f(k);
    ws.pass_buffer(i, kMassRate + k) = w(k);
  }
}

/// Bending forces into ws.bending from the segment pass (see compute_forces).
template <typename Scalar>
void bending_forces(const ForcePass<Scalar>& c, TetherWorkspace<Scalar>& ws) {
  using V3 = Vector3<Scalar>;
  // E_i = k (1 − c), c = u_a·u_b, k = EI/l at interior node i between segment a (i−1) and b (i);
  // F_{i−1} = −k (u_b − c u_a)/l_a, F_{i+1} = k (u_a − c u_b)/l_b, F_i = −F_{i−1} − F_{i+1}.
  ws.bending.setZero();
  const Scalar k = c.p->bending_stiffness * c.inv_l;
  for (int i = 1; i < c.n; ++i) {
    // No moment is carried across a parted segment.
    if (c.parted && (c.parted[i - 1] || c.parted[i])) continue;
    const Scalar la = ws.stretched_length(i - 1), lb = ws.stretched_length(i);
    if (!(la > Scalar(0) && lb > Scalar(0))) continue;
    const V3 ua = ws.direction.col(i - 1), ub = ws.direction.col(i);
    const Scalar cs = ua.dot(ub);
    const V3 fa = (-k / la) * (ub - cs * ua);
    const V3 fb = (k / lb) * (ua - cs * ub);
    ws.bending.col(i - 1) += fa;
    ws.bending.col(i + 1) += fb;
    ws.bending.col(i) -= fa + fb;
  }
  // A clamped end (EndMotion::direction t): E = 2k (1 − t·u) with u the end segment's direction
  // away from the end, the same pair of forces with t in place of the neighbouring segment's
  // direction, at twice the stiffness (the beam's rotation between the clamp and its first node
  // is taken over half a segment; with k: the tip deflection's error is 1.5/N of P L³/(3EI), with
  // 2k the trapezoidal rule's 1/(2N²)).
  const int n = c.n;
  if (ws.clamp_start.squaredNorm() > Scalar(0) && !(c.parted && c.parted[0])) {
    const Scalar lb = ws.stretched_length(0);
    if (lb > Scalar(0)) {
      const V3 ub = ws.direction.col(0), t = ws.clamp_start;
      const V3 fb = (Scalar(2) * k / lb) * (t - t.dot(ub) * ub);
      ws.bending.col(1) += fb;
      ws.bending.col(0) -= fb;
    }
  }
  if (ws.clamp_end.squaredNorm() > Scalar(0) && !(c.parted && c.parted[n - 1])) {
    const Scalar la = ws.stretched_length(n - 1);
    if (la > Scalar(0)) {
      // The line leaves node N along −u_{N−1}: E = 2k (1 + t·u_{N−1}).
      const V3 ua = ws.direction.col(n - 1), t = -ws.clamp_end;
      const V3 fa = (Scalar(-2) * k / la) * (t - t.dot(ua) * ua);
      ws.bending.col(n - 1) += fa;
      ws.bending.col(n) -= fa;
    }
  }
}

/// Zeroes the axial force of the parted segments (TetherState::parted) and its Jacobian terms:
/// a parted segment carries no force between its two nodes.
template <bool WithJacobian, typename Scalar>
void parted_segments(const ForcePass<Scalar>& c, TetherWorkspace<Scalar>& ws) {
  for (int s = 0; s < c.n; ++s) {
    if (!c.parted[s]) continue;
    ws.tension(s) = Scalar(0);
    for (int k = 0; k < 3; ++k) ws.pass_buffer(s, kSegmentForce + k) = Scalar(0);
    if constexpr (WithJacobian) {
      ws.seg_k_uu(s) = Scalar(0);
      ws.seg_k_perp(s) = Scalar(0);
      ws.seg_c_uu(s) = Scalar(0);
    }
  }
}

/// Points `data`/`stride` at the columns of `m` when it is column-major storage with unit inner
/// stride; otherwise evaluates `m` into `copy` (sized by the workspace) and points at that.
template <typename Scalar, typename D>
void bind_columns(const Eigen::MatrixBase<D>& m, Matrix3X<Scalar>& copy, const Scalar*& data,
                  Eigen::Index& stride) {
  using M = typename D::PlainObject;
  constexpr int flags = Eigen::internal::traits<D>::Flags;
  if constexpr (bool(flags & Eigen::DirectAccessBit) && !bool(flags & Eigen::RowMajorBit) &&
                std::is_same_v<typename M::Scalar, Scalar>) {
    if (m.derived().innerStride() == 1) {
      data = m.derived().data();
      stride = m.derived().outerStride();
      return;
    }
  }
  copy = m;
  data = copy.data();
  stride = 3;
}

// The packet kernels and force_passes (kelp/tether/force_pass_body.hpp): once for the build's own
// packets, and where kelp dispatches at run time once more for AVX2 (same bits; chosen by
// run_force_passes below). Doxygen does not read them (their namespaces are details).
#if !defined(KELP_DOXYGEN)
namespace baseline {
namespace vec = ::kelp::simd;
#define KELP_FORCE_PASS_BODY 1
#include "kelp/tether/force_pass_body.hpp"  // IWYU pragma: keep
#undef KELP_FORCE_PASS_BODY
}  // namespace baseline

#if defined(KELP_X86_DISPATCH)
KELP_AVX2_BEGIN
namespace avx2 {
namespace vec = ::kelp::simd::detail::avx2;
#define KELP_FORCE_PASS_BODY 1
#include "kelp/tether/force_pass_body.hpp"  // IWYU pragma: keep
#undef KELP_FORCE_PASS_BODY
}  // namespace avx2
KELP_AVX2_END
#endif
#endif  // KELP_DOXYGEN

/// force_passes on the widest build this CPU runs: AVX2 for doubles when
/// force_passes_take_avx2(), the build's own packets otherwise. Both give the same bits.
template <bool WithJacobian, typename Scalar>
void run_force_passes(ForcePass<Scalar>& c, TetherWorkspace<Scalar>& ws) {
#if defined(KELP_X86_DISPATCH)
  if constexpr (std::is_same_v<Scalar, double>) {
    if (force_passes_take_avx2()) {
      avx2::force_passes<WithJacobian>(c, ws);
      return;
    }
  }
#endif
  baseline::force_passes<WithJacobian>(c, ws);
}

/// soa_inputs_summed on the build run_force_passes takes: the inputs into the pass buffer and their
/// sum.
template <typename Scalar>
Scalar run_soa_inputs_summed(const ForcePass<Scalar>& c, TetherWorkspace<Scalar>& ws) {
#if defined(KELP_X86_DISPATCH)
  if constexpr (std::is_same_v<Scalar, double>)
    if (force_passes_take_avx2()) return avx2::soa_inputs_summed(c, ws);
#endif
  return baseline::soa_inputs_summed(c, ws);
}

/// compute_forces, and when `acc` is not null the node accelerations M⁻¹F of every node into
/// `acc` (3 × (N+1), column-major; the kinematic ends' entries are M⁻¹F too, not their
/// prescribed accelerations); when `residual` is not null, the implicit step's residual
/// (ImplicitResidual).
template <bool WithJacobian, typename Scalar, typename Env, typename DX, typename DV>
void evaluate_forces(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws, const Env& env,
                     double t, const Eigen::MatrixBase<DX>& x, const Eigen::MatrixBase<DV>& v,
                     Scalar* acc, ImplicitResidual<Scalar>* residual = nullptr,
                     bool check_inputs = false) {
  const TetherParameters<Scalar>& p = model.parameters();
  const int n = model.segments();
  ForcePass<Scalar> c;
  c.p = &p;
  c.n = n;
  // The passes read the coordinates through a pointer and a column stride: straight from
  // column-major storage, or from a copy of any other expression.
  bind_columns(x, ws.x_eval, c.x, c.xs);
  bind_columns(v, ws.v_eval, c.v, c.vs);
  if (check_inputs) {
    // compute_forces' check of x and v, in the pass that moves them into the pass buffer, before
    // anything else is written or sampled. NaN and ±Inf survive the sum (a sum that overflows is
    // refused too, rightly: coordinates of 1e307 m are not a tether).
    if (!is_finite(run_soa_inputs_summed(c, ws))) {
      check_all_finite(x, "compute_forces: x");
      check_all_finite(v, "compute_forces: v");
      ::kelp::detail::throw_invalid_argument("compute_forces: x and v overflow");
    }
    c.inputs_ready = true;
  }
  // Any evaluation overwrites what an explicit step kept from its end (TetherWorkspace::
  // end_evaluated; that step sets it again after its own).
  ws.end_evaluated = false;
  c.rho = Scalar(env.water_density());
  c.g = Scalar(env.gravity());
  c.bed = Scalar(env.seabed_depth());
  c.l = model.segment_length();
  c.l2 = c.l * c.l;
  c.inv_l = model.inverse_segment_length();
  c.ea_l = model.axial_spring();
  c.ba_l = model.axial_damper();
  c.ea = p.axial_stiffness;
  c.ba = p.internal_damping;
  c.can = p.normal_added_mass;
  c.cat = p.tangential_added_mass;
  c.inv_d = Scalar(1) / p.diameter;
  c.half_d = Scalar(0.5) * p.diameter;
  c.bed_k = p.seabed_stiffness * p.diameter;
  c.bed_c = p.seabed_damping * p.diameter;
  c.clamp = !p.compressive_damping;
  c.damping = c.ba != Scalar(0);
  c.fade = model.dashpot_fade_length() > Scalar(0);
  c.inv_fade = model.inverse_dashpot_fade_length();
  c.bending = p.bending_stiffness > Scalar(0);
  // Added-mass rate terms (see compute_forces); none when Cat = Can (b = 0) and none in
  // MoorDyn's line model (TetherModel::added_mass_rate_terms).
  c.mass_turns = model.added_mass_rate_terms();
  c.parted = ws.any_parted ? ws.parted.data() : nullptr;
  c.obstacles = obstacles_of(env);
  if (!c.obstacles) ws.any_contact = false;

  // Water velocity and acceleration at the nodes; a still environment (no waves, no current)
  // gives zeros everywhere, which the buffers keep from the last time they were zeroed.
  c.still = is_still_water(env);
  if (!c.still) {
    if (!ws.water_frozen) {
      ws.water_is_zero = false;
      sample_water_at_nodes(env, x, t, ws);
    }
  } else if (!ws.water_is_zero) {
    ws.water_velocity.setZero();
    ws.water_acceleration.setZero();
    ws.surface_elevation.setZero();
    ws.water_is_zero = true;
  }

  // The constants of the three kinds of node (start, interior, end), once per evaluation.
  const Scalar half_rho_d = Scalar(0.5) * c.rho * p.diameter;
  const Scalar kn_per_l = half_rho_d * p.normal_drag;
  const Scalar kt_per_l = half_rho_d * Scalar(kelp::pi) * p.tangential_drag;
  // Node constants from its structural mass m, displaced volume vol and lumped line length li.
  const auto constants_of = [&](Scalar m, Scalar vol, Scalar li) {
    return NodeConstants<Scalar>{li,
                                 m * c.g,
                                 (m - c.rho * vol) * c.g,
                                 c.rho * vol,
                                 kn_per_l * li,
                                 kt_per_l * li,
                                 m,
                                 m + c.rho * vol * c.can,
                                 c.rho * vol * (c.cat - c.can)};
  };
  const auto node_constants = [&](int i) {
    return constants_of(model.node_mass(i), model.node_volume(i), model.node_length(i));
  };
  c.kinds[0] = node_constants(0);
  c.kinds[1] = node_constants(n > 1 ? 1 : 0);
  c.kinds[2] = node_constants(n);
  // A winch at the start end (TetherWorkspace::winch_length): segment 0 has rest length l_w,
  // node 0 carries l_w/2 of line and node 1 (l + l_w)/2 (l_w/2 when it is the far end).
  c.winch = has_winch_segment(ws);
  if (c.winch) {
    const auto winch_node = [&](int i) {
      return constants_of(node_mass_at(model, ws, i), node_volume_at(model, ws, i),
                          node_length_at(model, ws, i));
    };
    c.kinds[0] = winch_node(0);
    if (n > 1)
      c.kinds[3] = winch_node(1);
    else
      c.kinds[2] = winch_node(1);
  }

  c.acc = acc;
  c.residual = residual;
  run_force_passes<WithJacobian>(c, ws);
}

}  // namespace detail

/// \brief Net force on every node of the tether at positions `x`, velocities `v`, time `t`.
///
/// Fills `ws.force` (NED [N]) and the per-node mass matrices M_i = a_i I + b_i q_i q_iᵀ
/// (`ws.mass_iso`, `ws.mass_tan`), plus tensions, tangents and seabed forces. Per node i:
/// \f[ F_i = T_i u_i − T_{i−1} u_{i−1} + (m_i − ρ V_i) g e_z + F^{drag}_i + F^{FK}_i + F^{bed}_i
/// \f]
/// - axial: T_s = max(0, EA·max(0, ε_s) + σ(l_s) BA ε̇_s): the elastic part acts only when
///   l_s > l, the dashpot at any length (faded out by σ on a segment folded below l/10 in kelp's
///   line, TetherModel::dashpot_fade), and the sum is clamped at zero so that a segment never
///   pushes (`compressive_damping` or LineModel::moordyn drops the clamp, as MoorDyn does);
/// - drag (Morison, on v_r = u_water − v_i): ½ρ d l_i Cdn |v_rn| v_rn + ½ρ π d l_i Cdt |v_rt| v_rt;
/// - fluid inertia: ρ V_i [(1 + Can)(I − q qᵀ) + (1 + Cat) q qᵀ] a_water;
/// - added mass ρ V_i [Can (I − q qᵀ) + Cat q qᵀ] in the mass matrix (never as a force from a
///   previous acceleration), with the terms of its rate of change: the added mass is part of the
///   kinetic energy ½ v_rᵀ M_i v_r (v_r = v_i − u_water), and since M_i = a_i I + b_i q_i q_iᵀ
///   turns with the tangent, Lagrange's equations add G_i = −b_i[(q̇_i·v_r) q_i + (q_i·v_r) q̇_i]
///   on node i and ±b_i (q_i·v_r)(I − q_i q_iᵀ) v_r/|c_i| on the two nodes of its chord c_i
///   (∂T/∂x). Without them the line gains energy whenever Cat ≠ Can; with them the model is
///   passive (Lamb 1932, Hydrodynamics §137: fluid kinetic energy in Lagrange's equations). In a
///   steady axial flow along a curved line they are the fluid's "centrifugal" force of
///   slender-body theory (Lighthill 1960; Païdoussis 1966). LineModel::moordyn leaves them out,
///   as MoorDyn v2 does;
/// - seabed (z_i > h): upward (z_i − h) kb d l_i + ż_i cb d l_i (≥ 0), and saturated-viscous
///   friction −μ_f N v_h / max(|v_h|, v_f);
/// - bending (EI > 0): EI/l (1 − u_{i−1}·u_i) at every interior node, and 2EI/l (1 − t·u) at a
///   clamped end (the unit direction t in `ws.clamp_start` / `ws.clamp_end`, which the steps copy
///   from EndMotion::direction; u the end segment's direction away from the end);
/// - a parted segment (`ws.parted`, which the steps copy from TetherState::parted) carries no
///   axial force and no bending moment, and the nodes beside it are the ends of their pieces
///   (their tangent is their own segment: kelp/tether/failure.hpp);
/// - buoyancy, drag, fluid inertia and added mass scale with the node's submerged fraction φ_i,
///   the wet share of its two half segments: each segment's wet length is exact where it pierces
///   the surface (the crossing between its nodes, the surface straight between them, a cable
///   cross-section going under over one diameter), lumped on its nodes by the linear shape
///   functions, so that the buoyancy is the gradient of the line's potential and a line crossing
///   the surface converges with the segment length (detail::segment_wetness, node_wetness). A line
///   lying level on the surface has φ = ½ at the surface, 1 half a diameter below, 0 above.
/// Evaluated in passes over SIMD packets (kelp/core/simd.hpp): the segments, then the interior
/// nodes of the wet line a packet at a time (the ends and nodes in the surface band, in air or
/// on the seabed one by one, with every branch), then the added-mass coupling of neighbours and
/// bending; each pass ends with a packet that overlaps the one before. x and v are checked in
/// the first pass, which copies them, before anything else is written. Also fills
/// `ws.mass_iso_inv` and `ws.mass_tan_ratio`. No heap allocation.
/// \tparam WithJacobian also fill the ingredients of the symmetric block-tridiagonal Jacobian
/// of the implicit steps (`ws.seg_*`, `ws.node_dv`, `ws.node_kz`), which leaves out the tangent's
/// dependence on the positions in drag, forcing and added mass, the added-mass rate terms, the
/// surface band's scaling of the fluid forces, the dashpot's direction and bending, and the
/// buoyancy's dependence on the neighbours' depths (it keeps ∂φ_i/∂z_i only); the whole
/// Jacobian, every term exact, is kelp/tether/jacobian.hpp's force_jacobian.
/// \param[in] model the tether \param[in,out] ws workspace \param[in] env environment
/// \param[in] t time [s] \param[in] x node positions 3×(N+1) [m] \param[in] v velocities [m/s]
/// \throws kelp::invalid_argument when `ws` was not built for `model` (TetherWorkspace::fits),
/// x or v is not 3×(N+1), or t, x or v is not finite (O(N) check; the integrators call the
/// evaluation behind it directly, after checking the state once per step).
/// \tparam Scalar double or float (deduced from the model).
/// \tparam Env the environment type (kelp/tether/lumped_mass.hpp).
/// \tparam DX an Eigen 3×(N+1) matrix type (positions, NED [m]).
/// \tparam DV an Eigen 3×(N+1) matrix type (velocities, NED [m/s]).
template <bool WithJacobian = false, typename Scalar, typename Env, typename DX, typename DV>
void compute_forces(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws, const Env& env,
                    double t, const Eigen::MatrixBase<DX>& x, const Eigen::MatrixBase<DV>& v) {
  detail::check_workspace(model, ws);
  KELP_CHECK(
      x.rows() == 3 && x.cols() == model.nodes() && v.rows() == 3 && v.cols() == model.nodes(),
      "compute_forces: x and v must be 3 x (segments + 1)");
  check_finite(t, "compute_forces: t");
  // x and v are checked in the evaluation's first pass (evaluate_forces' check_inputs).
  detail::evaluate_forces<WithJacobian>(model, ws, env, t, x, v, static_cast<Scalar*>(nullptr),
                                        static_cast<detail::ImplicitResidual<Scalar>*>(nullptr),
                                        true);
}

/// \brief Node accelerations a_i = M_i⁻¹ F_i from the last `compute_forces` (free nodes only;
/// kinematic ends get the prescribed acceleration `a_start`, `a_end`).
///
/// M_i = a I + b q qᵀ is inverted in closed form: M⁻¹ F = (F − b/(a+b) q (q·F)) / a, with
/// 1/a and b/(a+b) from compute_forces (constants along the wet part of the line).
/// \throws kelp::invalid_argument when `ws` was not built for `model`, `acc` is not 3×(N+1) or
/// an end acceleration is not finite.
/// \tparam Scalar double or float.
/// \tparam DA a writable Eigen 3×(N+1) matrix type.
/// \param[in] model the tether.
/// \param[in] ws the workspace holding the last compute_forces (forces, tangents, masses).
/// \param[in] a_start the prescribed acceleration of a kinematic start end, NED [m/s²].
/// \param[in] a_end the prescribed acceleration of a kinematic far end, NED [m/s²].
/// \param[out] acc the node accelerations, NED [m/s²], 3×(N+1).
template <typename Scalar, typename DA>
void accelerations_from_forces(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                               const Vector3<Scalar>& a_start, const Vector3<Scalar>& a_end,
                               Eigen::MatrixBase<DA>& acc) {
  detail::check_workspace(model, ws);
  KELP_CHECK(acc.rows() == 3 && acc.cols() == model.nodes(),
             "accelerations_from_forces: acc must be 3 x (segments + 1)");
  check_all_finite(a_start, "accelerations_from_forces: a_start");
  check_all_finite(a_end, "accelerations_from_forces: a_end");
  const int n = model.segments();
  for (int i = model.first_free_node(); i <= model.last_free_node(); ++i) {
    const auto q = ws.tangent.col(i);
    const auto f = ws.force.col(i);
    acc.col(i) = (f - (ws.mass_tan_ratio(i) * q.dot(f)) * q) * ws.mass_iso_inv(i);
  }
  if (model.first_free_node() == 1) acc.col(0) = a_start;
  if (model.last_free_node() == n - 1) acc.col(n) = a_end;
}

namespace detail {
/// M_i a of node i from the last compute_forces: its isotropic and tangential mass (with the
/// added mass) times the acceleration `a`.
template <typename Scalar>
Vector3<Scalar> node_inertia(const TetherWorkspace<Scalar>& ws, int i, const Vector3<Scalar>& a) {
  const Vector3<Scalar> q = ws.tangent.col(i);
  return ws.mass_iso(i) * a + ws.mass_tan(i) * q.dot(a) * q;
}
}  // namespace detail

/// \brief Forces the tether exerts on its kinematic attachment points from the last
/// `compute_forces`: F_end = F_node − M_node a_end (the negative of the constraint force that
/// holds the end node on its prescribed path), NED [N]. Zero for a free end.
/// \throws kelp::invalid_argument when `ws` was not built for `model` or `boundary` is not finite.
/// \tparam Scalar double or float.
/// \param[in] model the tether.
/// \param[in] ws the workspace holding the last compute_forces.
/// \param[in] boundary the end motion at the evaluation's instant (its accelerations are used).
/// \return the forces on the start and far attachment points, NED [N].
template <typename Scalar>
EndForces<Scalar> end_forces_from_workspace(const TetherModel<Scalar>& model,
                                            const TetherWorkspace<Scalar>& ws,
                                            const TetherBoundary<Scalar>& boundary) {
  detail::check_workspace(model, ws);
  check_boundary(boundary);
  EndForces<Scalar> out;
  const int n = model.segments();
  if (model.parameters().start_mode == EndMode::kinematic)
    out.on_start = ws.force.col(0) - detail::node_inertia(ws, 0, boundary.start.acceleration);
  if (model.parameters().end_mode == EndMode::kinematic)
    out.on_end = ws.force.col(n) - detail::node_inertia(ws, n, boundary.end.acceleration);
  return out;
}

namespace detail {
/// Sets ws.end_node_forces from ws.end_forces: F_node = end force + M_node a_end.
template <typename Scalar>
void set_end_node_forces(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                         const TetherBoundary<Scalar>& boundary) {
  const int n = model.segments();
  ws.end_node_forces = EndForces<Scalar>{};
  if (model.parameters().start_mode == EndMode::kinematic)
    ws.end_node_forces.on_start =
        ws.end_forces.on_start + node_inertia(ws, 0, boundary.start.acceleration);
  if (model.parameters().end_mode == EndMode::kinematic)
    ws.end_node_forces.on_end =
        ws.end_forces.on_end + node_inertia(ws, n, boundary.end.acceleration);
}
}  // namespace detail

/// \brief Total mechanical energy [J]: kinetic ½ Σ vᵢᵀ Mᵢ vᵢ (with added mass) + potential of
/// the weight −Σ mᵢ g zᵢ (NED z down) and of the buoyancy ρ g A Σ_s l_s ∫₀¹ Φ(d(σ)) dσ over the
/// segments (Φ the depth of wet line, d the depth along the segment, see
/// detail::segment_depth_integral) + elastic ½ EA/l Σ (l_s − l)² over
/// stretched segments + bending EI/l Σ (1 − u_{i−1}·u_i). Ignores the seabed spring. Recomputes the
/// tangents and wetness itself.
/// \throws kelp::invalid_argument when the state does not fit the model or is not finite.
/// \tparam Scalar double or float.
/// \tparam Env the environment type (water_density(), gravity(), surface_elevation()).
/// \param model the tether.
/// \param env the water (density, gravity, surface elevation at the state's time).
/// \param state the state (positions NED [m], velocities [m/s], winch length, parted segments).
/// \return the energy [J], relative to the sea surface (z = 0) for the weight.
template <typename Scalar, typename Env>
Scalar tether_energy(const TetherModel<Scalar>& model, const Env& env,
                     const TetherState<Scalar>& state) {
  using std::sqrt;
  check_state(model, state);
  const TetherParameters<Scalar>& p = model.parameters();
  const int n = model.segments();
  const Scalar rho = Scalar(env.water_density()), g = Scalar(env.gravity());
  const Scalar l = model.segment_length();
  Scalar e(0);
  const std::uint8_t* parted =
      state.parted.size() == n && state.parted.any() ? state.parted.data() : nullptr;
  // Segment 0 and nodes 0, 1 at a winch (TetherState::winch_length): their own rest length,
  // spring and masses.
  const Scalar lw = state.winch_length > Scalar(0) ? state.winch_length : l;
  for (int s = 0; s < n; ++s) {
    if (parted && parted[s]) continue;  // a parted segment stores no energy
    const Scalar ls = (state.position.col(s + 1) - state.position.col(s)).norm();
    const Scalar rest = s == 0 ? lw : l;
    if (ls > rest) e += Scalar(0.5) * (p.axial_stiffness / rest) * (ls - rest) * (ls - rest);
  }
  if (p.bending_stiffness > Scalar(0))
    for (int i = 1; i < n; ++i) {
      if (parted && (parted[i - 1] || parted[i])) continue;
      const Vector3<Scalar> a = state.position.col(i) - state.position.col(i - 1);
      const Vector3<Scalar> b = state.position.col(i + 1) - state.position.col(i);
      const Scalar na = a.norm(), nb = b.norm();
      if (na > Scalar(0) && nb > Scalar(0))
        e += p.bending_stiffness / l * (Scalar(1) - a.dot(b) / (na * nb));
    }
  // Depth under the surface of node i and rest length of segment s.
  const auto depth = [&](int i) {
    return state.position(2, i) +
           Scalar(env.surface_elevation(state.position(0, i), state.position(1, i), state.time));
  };
  const auto rest = [&](int s) { return s == 0 ? lw : l; };
  const Scalar inv_d = Scalar(1) / p.diameter;
  // Buoyancy: ρ g A l Σ_s ∫ Φ over each joined segment, the halves of a parted one at their nodes'
  // depths (detail::segment_wetness).
  for (int s = 0; s < n; ++s) {
    const Scalar da = depth(s), db = depth(s + 1);
    const Scalar integral =
        parted && parted[s]
            ? Scalar(0.5) * (detail::submerged_depth_integral(da, Scalar(0), p.diameter) +
                             detail::submerged_depth_integral(db, Scalar(0), p.diameter))
            : detail::segment_depth_integral(da, db, p.diameter);
    e += rho * g * model.area() * rest(s) * integral;
  }
  for (int i = 0; i <= n; ++i) {
    const Vector3<Scalar> q = detail::node_tangent<Scalar>(state.position, i, n, parted).q;
    const Scalar z = state.position(2, i);
    const Scalar phi =
        detail::node_wetness_of<Scalar>(
            i, n, depth, rest, [&](int s) { return parted && parted[s]; }, p.diameter, inv_d)
            .phi;
    const Scalar extra = detail::winch_extra_length(model, state.winch_length, i);
    const Scalar m = model.node_mass(i) + p.mass_per_length * extra;
    const Scalar vol = model.node_volume(i) + model.area() * extra;
    const Scalar rv = phi * rho * vol;
    const Vector3<Scalar> vi = state.velocity.col(i);
    const Scalar vq = vi.dot(q);
    e += Scalar(0.5) * ((m + rv * p.normal_added_mass) * vi.squaredNorm() +
                        rv * (p.tangential_added_mass - p.normal_added_mass) * vq * vq);
    e -= m * g * z;
  }
  return e;
}

}  // namespace kelp::tether
