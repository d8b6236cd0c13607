/// \file
/// \brief The solve with a kept block-tridiagonal factor (forward elimination and back
/// substitution of the twisted elimination, kelp/tether/block_solve.hpp), written once and
/// compiled twice as the force passes are (kelp/tether/force_pass_body.hpp): block_solve.hpp
/// includes this file in namespace `detail::kept_baseline` and, where kelp dispatches at run time
/// (KELP_X86_DISPATCH), again in `detail::kept_avx2` inside KELP_AVX2_BEGIN / END, where the
/// same two-lane operations take the VEX encoding (three operands, unaligned memory operands):
/// fewer instructions, the same bits (no FMA). Not a header of its own: without
/// KELP_KEPT_SOLVE_BODY defined it is empty, and it has no include guard on purpose.
#if defined(KELP_KEPT_SOLVE_BODY)

/// Back substitution of the twisted elimination (factor_solve_block_tridiagonal), outward from
/// the meeting node m whose δ_m is in `delta`, the elimination steps in reverse:
/// δ_i = P_i (rhs'_i + A δ_k) = z_i + Cᵀ δ_k (C = A P_i, A symmetric), z_i = P_i rhs'_i held in
/// δ's column i by the forward elimination, k the neighbour towards m, A = α u uᵀ + β I the
/// segment between them. Step −1 (node f0 in both lanes) copies lane 0.
template <typename Scalar, typename V>
void back_substitute_block_tridiagonal(const TetherModel<Scalar>& model, const Scalar* kept,
                                       Matrix3X<Scalar>& delta) {
  using S = Scalar;
  const int f0 = model.first_free_node(), f1 = model.last_free_node();
  const int m = f0 + (f1 - f0 + 1) / 2, pairs = f1 - m;
  const bool extra = m - f0 > pairs;
  const auto kept_pair = [](const S* in) { return load_lane_pair<V>(in); };
  const S y0 = delta(0, m), y1 = delta(1, m), y2 = delta(2, m);
  V d0{y0, y0}, d1{y1, y1}, d2{y2, y2};
  for (int k = pairs - 1; k >= (extra ? -1 : 0); --k) {
    const int i0 = m - pairs + k, i1 = k < 0 ? f0 : f1 - k;
    if (k < 0) {
      d0 = V{d0[0], d0[0]};
      d1 = V{d1[0], d1[0]};
      d2 = V{d2[0], d2[0]};
    }
    const S* const in = kept + kKeptStepSize * (k + (extra ? 1 : 0));
    const auto q = [&](int j) { return kept_pair(in + 2 * j); };
    const V z0{delta(0, i0), delta(0, i1)}, z1{delta(1, i0), delta(1, i1)},
        z2{delta(2, i0), delta(2, i1)};
    const V e0 = d0, e1 = d1, e2 = d2;
    d0 = z0 + (q(6) * e0 + q(9) * e1 + q(12) * e2);
    d1 = z1 + (q(7) * e0 + q(10) * e1 + q(13) * e2);
    d2 = z2 + (q(8) * e0 + q(11) * e1 + q(14) * e2);
    delta(0, i0) = d0[0];
    delta(0, i1) = d0[1];
    delta(1, i0) = d1[0];
    delta(1, i1) = d1[1];
    delta(2, i0) = d2[0];
    delta(2, i1) = d2[1];
  }
}

/// Solves J δ = rhs with the factor that factor_solve_block_tridiagonal kept in `kept` (with
/// keep_meeting): forward elimination of rhs (into the free columns of δ) and back
/// substitution, the same arithmetic as the factorisation's own solve, so that the same rhs
/// gives the same δ bit for bit. Reads only `kept` and `rhs`; O(N), no heap allocation.
template <typename Scalar, typename V>
void solve_factored_block_tridiagonal(const TetherModel<Scalar>& model, const Scalar* kept,
                                      const Matrix3X<Scalar>& rhs, Matrix3X<Scalar>& delta) {
  using S = Scalar;
  const int f0 = model.first_free_node(), f1 = model.last_free_node();
  if (f1 < f0) return;
  const int m = f0 + (f1 - f0 + 1) / 2, pairs = f1 - m;
  const bool extra = m - f0 > pairs;
  const auto kept_pair = [](const S* in) { return load_lane_pair<V>(in); };
  const auto lanes_row = [](const auto& a, int row, int i0, int i1) {
    return V{a(row, i0), a(row, i1)};
  };
  const auto put = [](auto& a, int row, int i0, int i1, const V& x) {
    a(row, i0) = x[0];
    a(row, i1) = x[1];
  };
  V cr0{S(0), S(0)}, cr1{S(0), S(0)}, cr2{S(0), S(0)};
  V r0, r1, r2;
  for (int k = extra ? -1 : 0;; ++k) {
    const int i0 = m - pairs + k, i1 = k < 0 ? f0 : f1 - k;
    r0 = lanes_row(rhs, 0, i0, i1) + cr0;
    r1 = lanes_row(rhs, 1, i0, i1) + cr1;
    r2 = lanes_row(rhs, 2, i0, i1) + cr2;
    if (k == pairs) break;
    const S* const in = kept + kKeptStepSize * (k + (extra ? 1 : 0));
    const auto q = [&](int j) { return kept_pair(in + 2 * j); };
    const V p00 = q(0), p10 = q(1), p20 = q(2), p11 = q(3), p21 = q(4), p22 = q(5);
    put(delta, 0, i0, i1, p00 * r0 + p10 * r1 + p20 * r2);
    put(delta, 1, i0, i1, p10 * r0 + p11 * r1 + p21 * r2);
    put(delta, 2, i0, i1, p20 * r0 + p21 * r1 + p22 * r2);
    cr0 = q(6) * r0 + q(7) * r1 + q(8) * r2;
    cr1 = q(9) * r0 + q(10) * r1 + q(11) * r2;
    cr2 = q(12) * r0 + q(13) * r1 + q(14) * r2;
    if (k < 0) {
      cr0 = V{cr0[0], S(0)};
      cr1 = V{cr1[0], S(0)};
      cr2 = V{cr2[0], S(0)};
    }
  }
  {
    const S* const pm = kept + kKeptStepSize * (pairs + (extra ? 1 : 0));
    const S s0 = r0[0] + cr0[1], s1 = r1[0] + cr1[1], s2 = r2[0] + cr2[1];
    delta(0, m) = pm[0] * s0 + pm[1] * s1 + pm[2] * s2;
    delta(1, m) = pm[1] * s0 + pm[3] * s1 + pm[4] * s2;
    delta(2, m) = pm[2] * s0 + pm[4] * s1 + pm[5] * s2;
  }
  back_substitute_block_tridiagonal<Scalar, V>(model, kept, delta);
}

#endif  // KELP_KEPT_SOLVE_BODY
