/// \file
/// \brief The packet kernels of the lumped-mass tether's force evaluation (segment pass, interior
/// wet nodes, final pass) and the passes that run them (`force_passes`), written once over a
/// pack type and compiled twice: kelp/tether/forces.hpp includes this file in namespace
/// `detail::baseline` with `vec` = kelp::simd (the build's own packets) and, where kelp
/// dispatches at run time (KELP_X86_DISPATCH), again in `detail::avx2` with `vec` =
/// kelp::simd::detail::avx2 (4 doubles in AVX registers), inside KELP_AVX2_BEGIN / END. Both give
/// the same bits (kelp/core/simd_avx2.hpp). Not a header of its own: without
/// KELP_FORCE_PASS_BODY defined it is empty, and it has no include guard on purpose.
#if defined(KELP_FORCE_PASS_BODY)

/// ForcePass constants broadcast to every lane once per evaluation (the kernels run in loops
/// that would otherwise broadcast them block after block).
template <typename Scalar, bool Wide>
struct PackedConstants {
  using P = vec::Pack<Scalar, Wide>;
  P zero, one, two, three, l, l2, inv_l, ea, ea_l, ba, ba_l, inv_fade, bed, half_d, wet_weight, kn,
      kt, rho_vol, one_plus_can, cat_minus_can, mass_iso_wet, mass_tan_wet, mass_iso_inv,
      mass_tan_ratio;
  explicit PackedConstants(const ForcePass<Scalar>& c) {
    const NodeConstants<Scalar>& nc = c.kinds[1];
    zero = P::all(Scalar(0));
    one = P::all(Scalar(1));
    two = P::all(Scalar(2));
    three = P::all(Scalar(3));
    l = P::all(c.l);
    l2 = P::all(c.l2);
    inv_l = P::all(c.inv_l);
    ea = P::all(c.ea);
    ea_l = P::all(c.ea_l);
    ba = P::all(c.ba);
    ba_l = P::all(c.ba_l);
    inv_fade = P::all(c.inv_fade);
    bed = P::all(c.bed);
    half_d = P::all(c.half_d);
    wet_weight = P::all(nc.wet_weight);
    kn = P::all(nc.kn);
    kt = P::all(nc.kt);
    rho_vol = P::all(nc.rho_vol);
    one_plus_can = P::all(Scalar(1) + c.can);
    cat_minus_can = P::all(c.cat - c.can);
    mass_iso_wet = P::all(nc.mass_iso_wet);
    mass_tan_wet = P::all(nc.mass_tan_wet);
    mass_iso_inv = P::all(Scalar(1) / nc.mass_iso_wet);
    mass_tan_ratio = P::all(nc.mass_tan_wet / (nc.mass_iso_wet + nc.mass_tan_wet));
  }
};

/// Segments s … s + lanes − 1 (see compute_forces): length, direction, axial force T_s (elastic
/// EA·ε when stretched plus the dashpot BA·ε̇ at any length, clamped at zero unless
/// compressive_damping), T_s u_s into the pass buffer, and the Jacobian terms.
template <bool WithJacobian, bool Wide, typename Scalar>
EIGEN_ALWAYS_INLINE void segment_block(const ForcePass<Scalar>& c,
                                       const PackedConstants<Scalar, Wide>& pc,
                                       TetherWorkspace<Scalar>& ws, int s) {
  using P = vec::Pack<Scalar, Wide>;
  const P zero = pc.zero;
  // Positions and velocities one column per component (soa_inputs): whole loads, no gathers.
  const Eigen::Index col = ws.pass_buffer.rows();
  const Scalar* a = &ws.pass_buffer(s, kPosition);
  const P d0 = P::load(a + 1) - P::load(a);
  const P d1 = P::load(a + col + 1) - P::load(a + col);
  const P d2 = P::load(a + 2 * col + 1) - P::load(a + 2 * col);
  const P ls2 = (d0 * d0 + d1 * d1) + d2 * d2;
  const P ls = sqrt(ls2);
  const auto positive = vec::greater(ls, zero);
  const P inv_ls = vec::select(positive, pc.one / ls, zero);
  const P u0 = d0 * inv_ls, u1 = d1 * inv_ls, u2 = d2 * inv_ls;
  const auto stretched = vec::greater(ls2, pc.l2);
  P tension = vec::select(stretched, (pc.ea * (ls - pc.l)) * pc.inv_l, zero);
  P k_axial = vec::select(stretched, pc.ea_l, zero);
  P c_axial = pc.ba_l;
  P rate = zero;
  if (c.damping) {
    const Scalar* b = &ws.pass_buffer(s, kVelocity);
    const P e0 = P::load(b + 1) - P::load(b);
    const P e1 = P::load(b + col + 1) - P::load(b + col);
    const P e2 = P::load(b + 2 * col + 1) - P::load(b + 2 * col);
    rate = (u0 * e0 + u1 * e1) + u2 * e2;
    P damping = (pc.ba * rate) * pc.inv_l;
    if (c.fade) {
      // kelp's line: the dashpot fades out below l_f (TetherModel::dashpot_fade), σ = ρ²(3 − 2ρ)
      // with ρ = min(l_s/l_f, 1); σ = 1 exactly above l_f. Its slope σ' BA/l ε̇ joins the axial
      // stiffness where it is positive (the symmetric matrix stays positive semi-definite).
      const P r0 = ls * pc.inv_fade;
      const P r = vec::select(vec::greater(r0, pc.one), pc.one, r0);
      const P sigma = (r * r) * (pc.three - pc.two * r);
      const P k_fade = ((pc.two * pc.three) * r * (pc.one - r) * pc.inv_fade) * (pc.ba_l * rate);
      damping = damping * sigma;
      c_axial = c_axial * sigma;
      k_axial = k_axial + vec::select(vec::greater(k_fade, zero), k_fade, zero);
    }
    tension += damping;
    if (c.clamp) {
      // A zero-length segment keeps its dashpot slope (its force is zero either way).
      const auto keep = vec::greater(tension, zero);
      tension = vec::select(keep, tension, zero);
      k_axial = vec::select(keep, k_axial, zero);
      c_axial = vec::select(keep || vec::greater_equal(zero, ls), c_axial, zero);
    }
  }
  ls.store(&ws.stretched_length(s));
  tension.store(&ws.tension(s));
  Scalar* dir = ws.direction.data() + 3 * s;
  P::store3(dir, u0, u1, u2);
  (tension * u0).store(&ws.pass_buffer(s, kSegmentForce));
  (tension * u1).store(&ws.pass_buffer(s, kSegmentForce + 1));
  (tension * u2).store(&ws.pass_buffer(s, kSegmentForce + 2));
  if constexpr (WithJacobian) {
    // ∂(T u)/∂x_{s+1} = k_axial u uᵀ + (T/l_s)(I − u uᵀ); the geometric term is kept only for
    // T > 0 so that the Jacobian stays positive semi-definite.
    const P k_perp = vec::select(vec::greater(tension, zero), tension * inv_ls, zero);
    (k_axial - k_perp).store(&ws.seg_k_uu(s));
    k_perp.store(&ws.seg_k_perp(s));
    c_axial.store(&ws.seg_c_uu(s));
    rate.store(&ws.seg_rate(s));
  }
}

/// Interior nodes i … i + lanes − 1 (1 ≤ i, i + lanes ≤ N) when all of them and their neighbours
/// are below the surface band (at least half a diameter deep: their half segments are wholly wet)
/// and they are off the seabed (returns false, writing nothing, otherwise): tangent, node force
/// without the added-mass coupling to the neighbours, that coupling term w_i, masses and the
/// Jacobian terms. The same arithmetic as node_general for such nodes.
template <bool WithJacobian, bool Wide, typename Scalar>
EIGEN_ALWAYS_INLINE bool interior_block(const ForcePass<Scalar>& c,
                                        const PackedConstants<Scalar, Wide>& pc,
                                        TetherWorkspace<Scalar>& ws, int i) {
  using P = vec::Pack<Scalar, Wide>;
  const P zero = pc.zero;
  const Eigen::Index col = ws.pass_buffer.rows();
  const Scalar* a = &ws.pass_buffer(i, kPosition);  // soa_inputs' columns
  const Scalar* az = a + 2 * col;
  const P z = P::load(az);
  // Wholly wet (the node and its neighbours at least half a diameter under the surface: φ = 1)
  // and off the seabed.
  const P z_lo = P::load(az - 1), z_hi = P::load(az + 1);
  P d = z, d_lo = z_lo, d_hi = z_hi;
  if (!c.still) {
    const Scalar* zeta = &ws.surface_elevation(i);
    d += P::load(zeta);
    d_lo += P::load(zeta - 1);
    d_hi += P::load(zeta + 1);
  }
  if (vec::any(vec::less(d, pc.half_d) || vec::less(d_lo, pc.half_d) ||
               vec::less(d_hi, pc.half_d) || vec::greater(z - pc.bed, zero)))
    return false;
  const P c0 = P::load(a + 1) - P::load(a - 1);
  const P c1 = P::load(a + col + 1) - P::load(a + col - 1);
  const P c2 = z_hi - z_lo;
  const P cc = (c0 * c0 + c1 * c1) + c2 * c2;
  const P inv_c2 = vec::select(vec::greater(cc, zero), pc.one / cc, zero);
  const P inv_c = sqrt(inv_c2);
  const P q0 = c0 * inv_c, q1 = c1 * inv_c, q2 = c2 * inv_c;
  Scalar* tan = ws.tangent.data() + 3 * i;
  P::store3(tan, q0, q1, q2);
  const Scalar* tu = &ws.pass_buffer(i, kSegmentForce);
  P f0 = P::load(tu) - P::load(tu - 1);
  P f1 = P::load(tu + col) - P::load(tu + col - 1);
  P f2 = P::load(tu + 2 * col) - P::load(tu + 2 * col - 1);
  f2 += pc.wet_weight;
  // Morison drag on the relative velocity, split along the chord.
  const Scalar* vi = &ws.pass_buffer(i, kVelocity);
  // Still water: the water velocity buffer holds +0 (evaluate_forces), which zero is.
  const Scalar* wi = ws.water_velocity.data() + 3 * i;
  P w0 = zero, w1 = zero, w2 = zero;
  if (!c.still) P::load3(wi, w0, w1, w2);
  const P vr0 = w0 - P::load(vi);
  const P vr1 = w1 - P::load(vi + col);
  const P vr2 = w2 - P::load(vi + 2 * col);
  const P vc = (vr0 * c0 + vr1 * c1) + vr2 * c2;
  const P sc = vc * inv_c2;
  const P vn0 = vr0 - sc * c0, vn1 = vr1 - sc * c1, vn2 = vr2 - sc * c2;
  const P vn_abs = sqrt((vn0 * vn0 + vn1 * vn1) + vn2 * vn2);
  const P vq = vc * inv_c;
  const P kn = pc.kn, kt = pc.kt;
  const P dn = kn * vn_abs, dt = (kt * abs(vq)) * vq;
  f0 += dn * vn0 + dt * q0;
  f1 += dn * vn1 + dt * q1;
  f2 += dn * vn2 + dt * q2;
  if (!c.still) {
    // Froude–Krylov plus added-mass forcing (zero where the water does not accelerate).
    const Scalar* ai = ws.water_acceleration.data() + 3 * i;
    P aw0, aw1, aw2;
    P::load3(ai, aw0, aw1, aw2);
    const P qa = pc.cat_minus_can * ((q0 * aw0 + q1 * aw1) + q2 * aw2);
    const P rv = pc.rho_vol, ca = pc.one_plus_can;
    f0 += rv * (ca * aw0 + qa * q0);
    f1 += rv * (ca * aw1 + qa * q1);
    f2 += rv * (ca * aw2 + qa * q2);
  }
  pc.mass_iso_wet.store(&ws.mass_iso(i));
  pc.mass_tan_wet.store(&ws.mass_tan(i));
  pc.mass_iso_inv.store(&ws.mass_iso_inv(i));
  pc.mass_tan_ratio.store(&ws.mass_tan_ratio(i));
  if (c.mass_turns) {
    // Added-mass rate terms (see compute_forces; zero for a zero chord, where 1/|c| = 0).
    const P k = pc.mass_tan_wet * inv_c, ks = k * vq;
    const P dc0 = P::load(vi + 1) - P::load(vi - 1);
    const P dc1 = P::load(vi + col + 1) - P::load(vi + col - 1);
    const P dc2 = P::load(vi + 2 * col + 1) - P::load(vi + 2 * col - 1);
    const P m = k * ((dc0 * vn0 + dc1 * vn1) + dc2 * vn2) - ks * ((q0 * dc0 + q1 * dc1) + q2 * dc2);
    f0 += ks * dc0 + m * q0;
    f1 += ks * dc1 + m * q1;
    f2 += ks * dc2 + m * q2;
    (ks * vn0).store(&ws.pass_buffer(i, kMassRate));
    (ks * vn1).store(&ws.pass_buffer(i, kMassRate + 1));
    (ks * vn2).store(&ws.pass_buffer(i, kMassRate + 2));
  }
  f0.store(&ws.pass_buffer(i, kNodeForce));
  f1.store(&ws.pass_buffer(i, kNodeForce + 1));
  f2.store(&ws.pass_buffer(i, kNodeForce + 2));
  pc.one.store(&ws.submerged(i));
  zero.store(&ws.seabed_force(i));
  if constexpr (WithJacobian) {
    // −∂F/∂v of the drag (q held fixed) = c1 I + (c3 − c1) q qᵀ + cn v_n v_nᵀ.
    const P cn = vec::select(vec::greater(vn_abs, zero), kn / vn_abs, zero);
    const P c31 = (pc.two * kt) * abs(vq) - dn;
    Scalar* dv = ws.node_dv.data() + 6 * i;
    (dn + c31 * q0 * q0 + cn * vn0 * vn0).scatter(dv, 6);
    (c31 * q1 * q0 + cn * vn1 * vn0).scatter(dv + 1, 6);
    (c31 * q2 * q0 + cn * vn2 * vn0).scatter(dv + 2, 6);
    (dn + c31 * q1 * q1 + cn * vn1 * vn1).scatter(dv + 3, 6);
    (c31 * q2 * q1 + cn * vn2 * vn1).scatter(dv + 4, 6);
    (dn + c31 * q2 * q2 + cn * vn2 * vn2).scatter(dv + 5, 6);
    zero.store(&ws.node_kz(i));
  }
  return true;
}

/// The running maximum of |R_ik| / a_i and sum of R_ik of the implicit step's residual, lane by
/// lane (residual_block).
template <typename P>
struct ResidualLanes {
  P max_scaled, sum;
};

/// The implicit step's residual at nodes i … i + lanes − 1 (ImplicitResidual) from their forces
/// `f`: the arithmetic of the pass it replaces, operation for operation, so that it gives the
/// same bits. A single node outside f0 … f1 (a kinematic end) has none; the packets cover
/// interior nodes only, which are free.
template <typename P, typename Scalar>
EIGEN_ALWAYS_INLINE void residual_block(const ImplicitResidual<Scalar>& res,
                                        const TetherWorkspace<Scalar>& ws, int i, const P (&f)[3],
                                        ResidualLanes<P>& lanes) {
  if constexpr (P::lanes == 1)
    if (i < res.f0 || i > res.f1) return;
  const Scalar *vh = res.v_hat + 3 * i, *tq = ws.tangent.data() + 3 * i;
  P h0, h1, h2, q0, q1, q2;
  P::load3(vh, h0, h1, h2);
  P::load3(tq, q0, q1, q2);
  const P d0 = P::load(&ws.pass_buffer(i, kVelocity)) - h0;
  const P d1 = P::load(&ws.pass_buffer(i, kVelocity + 1)) - h1;
  const P d2 = P::load(&ws.pass_buffer(i, kVelocity + 2)) - h2;
  const P a = P::load(&ws.mass_iso(i));
  const P bqd = P::load(&ws.mass_tan(i)) * ((q0 * d0 + q1 * d1) + q2 * d2);
  const P g = P::all(res.gh);
  const P r0 = g * f[0] - (a * d0 + bqd * q0);
  const P r1 = g * f[1] - (a * d1 + bqd * q1);
  const P r2 = g * f[2] - (a * d2 + bqd * q2);
  Scalar* out = res.rhs + 3 * i;
  P::store3(out, r0, r1, r2);
  lanes.max_scaled =
      max(lanes.max_scaled, max(max(abs(r0), abs(r1)), abs(r2)) * P::load(&ws.mass_iso_inv(i)));
  lanes.sum += (r0 + r1) + r2;
}

/// The residual's lanes (residual_block) reduced into `res`.
template <typename P, typename Scalar>
void reduce_residual(const ResidualLanes<P>& lanes, ImplicitResidual<Scalar>& res) {
  Scalar m[P::lanes], t[P::lanes];
  lanes.max_scaled.store(m);
  lanes.sum.store(t);
  for (int k = 0; k < P::lanes; ++k) {
    res.r_max = std::max(res.r_max, m[k]);
    res.sum += t[k];
  }
}

/// Node forces i … i + lanes − 1 into ws.force: the node pass's force plus the added-mass
/// coupling of the neighbours (+w_{i−1} − w_{i+1}; at node 0 the node's own −w_0, at node N its
/// own +w_N, as its chord is its own segment) and bending.
template <bool Wide, typename Scalar>
EIGEN_ALWAYS_INLINE void finish_block(const ForcePass<Scalar>& c, TetherWorkspace<Scalar>& ws,
                                      int i, ResidualLanes<vec::Pack<Scalar, Wide>>& lanes) {
  using P = vec::Pack<Scalar, Wide>;
  P f[3], bend[3];
  if (c.bending) P::load3(ws.bending.data() + 3 * i, bend[0], bend[1], bend[2]);
  for (int k = 0; k < 3; ++k) {
    f[k] = P::load(&ws.pass_buffer(i, kNodeForce + k));
    if (c.mass_turns) {
      const Scalar* w = &ws.pass_buffer(0, kMassRate + k);
      if constexpr (P::lanes == 1) {
        // At an end of the line or of a parted piece the node's own w stands for its neighbour's
        // (its chord is its own segment: detail::chord_nodes).
        const bool cut_before = i == 0 || (c.parted && c.parted[i - 1]);
        const bool cut_after = i == c.n || (c.parted && c.parted[i]);
        const Scalar prev = cut_before ? -w[i] : w[i - 1], next = cut_after ? -w[i] : w[i + 1];
        f[k] = f[k] + (P::all(prev) - P::all(next));
      } else {
        f[k] = f[k] + (P::load(w + i - 1) - P::load(w + i + 1));
      }
    }
    if (c.bending) f[k] += bend[k];
  }
  P::store3(ws.force.data() + 3 * i, f[0], f[1], f[2]);
  if (c.residual) residual_block(*c.residual, ws, i, f, lanes);
  if (c.acc) {
    // a = M⁻¹F = (F − (b/(a+b)) q (q·F)) / a (see accelerations_from_forces).
    const Scalar* tq = ws.tangent.data() + 3 * i;
    P q0, q1, q2;
    P::load3(tq, q0, q1, q2);
    const P rq = P::load(&ws.mass_tan_ratio(i)) * ((q0 * f[0] + q1 * f[1]) + q2 * f[2]);
    const P ia = P::load(&ws.mass_iso_inv(i));
    Scalar* a = c.acc + 3 * i;
    P::store3(a, (f[0] - rq * q0) * ia, (f[1] - rq * q1) * ia, (f[2] - rq * q2) * ia);
  }
}

/// Positions and velocities into TetherWorkspace::pass_buffer, one column per component
/// (kPosition, kVelocity): the segment and interior kernels then load 4 neighbouring nodes' x with
/// one instruction, where gathering them from 3-strided columns took five and their addresses
/// (each coordinate is read by 2–3 kernels, so it is gathered once here instead of at each use).
/// With Sum, also returns a sum in which every coordinate and velocity appears, finite only when
/// all of them are (compute_forces' input check, in the same pass); without it, 0.
template <bool Sum, typename Scalar>
EIGEN_ALWAYS_INLINE Scalar soa_inputs(const ForcePass<Scalar>& c, TetherWorkspace<Scalar>& ws) {
  using W = vec::Pack<Scalar, vec::vectorized<Scalar>>;
  const Eigen::Index col = ws.pass_buffer.rows();
  Scalar* px = &ws.pass_buffer(0, kPosition);
  Scalar* pv = &ws.pass_buffer(0, kVelocity);
  const int nodes = c.n + 1;
  int i = 0;
  W lanes = W::all(Scalar(0));
  const auto packet = [&](int j) {
    W r[3], u[3];
    W::load3(c.x + 3 * j, r[0], r[1], r[2]);
    for (int k = 0; k < 3; ++k) r[k].store(px + k * col + j);
    W::load3(c.v + 3 * j, u[0], u[1], u[2]);
    for (int k = 0; k < 3; ++k) u[k].store(pv + k * col + j);
    if constexpr (Sum) lanes += ((r[0] + r[1]) + r[2]) + ((u[0] + u[1]) + u[2]);
  };
  if (c.xs == 3 && c.vs == 3 && nodes >= W::lanes) {
    for (; i + W::lanes <= nodes; i += W::lanes) packet(i);
    // The last nodes in one more packet that overlaps the one before (copies of the same values;
    // the sum then counts some twice, which keeps it finite exactly when they all are).
    if (i < nodes) {
      packet(nodes - W::lanes);
      i = nodes;
    }
  }
  Scalar rest(0);
  for (; i < nodes; ++i)
    for (int k = 0; k < 3; ++k) {
      px[k * col + i] = c.X(k, i);
      pv[k * col + i] = c.V(k, i);
      if constexpr (Sum) rest += c.X(k, i) + c.V(k, i);
    }
  if constexpr (Sum)
    return lanes.sum() + rest;
  else
    return Scalar(0);
}

/// soa_inputs with the sum of its inputs, on its own (compute_forces runs it before anything
/// else writes the workspace; the passes then skip theirs: ForcePass::inputs_ready).
template <typename Scalar>
Scalar soa_inputs_summed(const ForcePass<Scalar>& c, TetherWorkspace<Scalar>& ws) {
  return soa_inputs<true>(c, ws);
}

/// The passes of compute_forces on positions and velocities stored column-major with the given
/// column strides.
template <bool WithJacobian, typename Scalar>
void force_passes(ForcePass<Scalar>& c, TetherWorkspace<Scalar>& ws) {
  constexpr bool wide = vec::vectorized<Scalar>;
  constexpr int lanes = vec::Pack<Scalar, wide>::lanes;
  const int n = c.n;
  if (!c.inputs_ready) soa_inputs<false>(c, ws);
  const PackedConstants<Scalar, wide> packed(c);
  const PackedConstants<Scalar, false> single(c);
  using PW = vec::Pack<Scalar, wide>;
  using P1 = vec::Pack<Scalar, false>;
  ResidualLanes<PW> res_wide{PW::all(Scalar(0)), PW::all(Scalar(0))};
  ResidualLanes<P1> res_one{P1::all(Scalar(0)), P1::all(Scalar(0))};
  int s = 0;
  if (c.winch) {
    // Segment 0 at a winch: its own rest length l_w (TetherWorkspace::winch_length), the same
    // arithmetic with l, EA/l, BA/l and the fade length taken for l_w.
    ForcePass<Scalar> cw = c;
    const Scalar lw = ws.winch_length;
    cw.l = lw;
    cw.l2 = lw * lw;
    cw.inv_l = Scalar(1) / lw;
    cw.ea_l = c.ea * cw.inv_l;
    cw.ba_l = c.ba * cw.inv_l;
    cw.inv_fade = c.inv_fade * (c.l * cw.inv_l);
    segment_block<WithJacobian, false>(cw, PackedConstants<Scalar, false>(cw), ws, 0);
    s = 1;
  }
  // The packets of the segment pass, the interior nodes' and the last pass end with one that
  // overlaps the packet before it rather than with single lanes: their kernels write the same
  // values again on the nodes they share.
  if constexpr (wide) {
    const int s0 = s;
    for (; s + lanes <= n; s += lanes) segment_block<WithJacobian, true>(c, packed, ws, s);
    if (s < n && n - lanes >= s0) {
      segment_block<WithJacobian, true>(c, packed, ws, n - lanes);
      s = n;
    }
  }
  for (; s < n; ++s) segment_block<WithJacobian, false>(c, single, ws, s);
  if (c.parted) {
    // A parted line (TetherState::parted) takes the general path: its parted segments carry no
    // axial force, and the nodes beside them are ends of their pieces (chord_nodes).
    parted_segments<WithJacobian>(c, ws);
    if (c.bending) bending_forces(c, ws);
    for (int i = 0; i <= n; ++i) node_general<WithJacobian>(c, ws, i);
    if (c.obstacles) contact_pass<WithJacobian>(c, ws);
    for (int i = 0; i <= n; ++i) finish_block<false>(c, ws, i, res_one);
    if (c.residual) reduce_residual(res_one, *c.residual);
    return;
  }
  if (c.bending) bending_forces(c, ws);
  node_general<WithJacobian>(c, ws, 0);
  int i = 1;
  // Node 1 next to a winch segment has its own constants (kinds[3]).
  if (c.winch && n > 1) node_general<WithJacobian>(c, ws, i++);
  if constexpr (wide) {
    // A packet with a node that the kernel does not take (in the surface band, on the seabed, or
    // beside such a node) gives its first node to the single-lane kernel or the general path, and
    // the next packet starts one node on: a line that dips under the surface at node 1 runs its
    // packets from node 2.
    const int i0 = i;
    while (i + lanes <= n) {
      if (interior_block<WithJacobian, true>(c, packed, ws, i)) {
        i += lanes;
      } else {
        if (!interior_block<WithJacobian, false>(c, single, ws, i))
          node_general<WithJacobian>(c, ws, i);
        ++i;
      }
    }
    if (i < n && n - lanes >= i0 && interior_block<WithJacobian, true>(c, packed, ws, n - lanes))
      i = n;
  }
  for (; i < n; ++i)
    if (!interior_block<WithJacobian, false>(c, single, ws, i))
      node_general<WithJacobian>(c, ws, i);
  if (n > 0) node_general<WithJacobian>(c, ws, n);
  // Obstacles (kelp/tether/contact.hpp): none in most environments, and then no pass at all.
  if (c.obstacles) contact_pass<WithJacobian>(c, ws);
  finish_block<false>(c, ws, 0, res_one);
  i = 1;
  // Nodes 1 … N − 1 in packets (an overlapping last packet makes the residual's sum count the
  // nodes it shares twice: that sum only tells whether every entry is finite,
  // ImplicitResidual::sum), N alone.
  if constexpr (wide) {
    for (; i + lanes <= n; i += lanes) finish_block<true>(c, ws, i, res_wide);
    if (i < n && n - lanes >= 1) {
      finish_block<true>(c, ws, n - lanes, res_wide);
      i = n;
    }
  }
  for (; i <= n; ++i) finish_block<false>(c, ws, i, res_one);
  if (c.residual) {
    reduce_residual(res_wide, *c.residual);
    reduce_residual(res_one, *c.residual);
  }
}

#endif  // KELP_FORCE_PASS_BODY
