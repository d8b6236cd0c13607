/// \file
/// \brief The linear algebra of the implicit tether steps: the Jacobian's segment coupling
/// blocks, the block-tridiagonal (block-Thomas, O(N)) solve of the Newton system with floored
/// 3×3 LDLᵀ pivots, and the active-set pass that settles which segments are slack.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"

#include "kelp/tether/model.hpp"
#include "kelp/tether/state.hpp"
#include "kelp/tether/stepping.hpp"

namespace kelp::tether {

namespace detail {

/// A_s = c_v·(−∂F/∂v) + c_x·(−∂F/∂x) coupling block of segment s (symmetric PSD).
template <typename Scalar>
Matrix3<Scalar> segment_block(const TetherWorkspace<Scalar>& ws, int s, Scalar c_v, Scalar c_x) {
  const Vector3<Scalar> u = ws.direction.col(s);
  Matrix3<Scalar> a = ((c_v * ws.seg_c_uu(s) + c_x * ws.seg_k_uu(s)) * u) * u.transpose();
  a.diagonal().array() += c_x * ws.seg_k_perp(s);
  return a;
}

/// Symmetric 3×3 block (xx, yx, zx, yy, zy, zz) of a scalar or of a pair of lanes.
template <typename T>
struct Sym3 {
  T xx, yx, zx, yy, zy, zz;
};

#if defined(__GNUC__) || defined(__clang__)
/// Two lanes of S, one per chain of solve_block_tridiagonal: a GCC/Clang vector (for double, one
/// SSE2 register, so that both chains advance with the same instructions), else an Eigen array.
/// Either takes T{a, b}, t[i], + − * / and a scalar on either side.
template <typename S>
struct LanePair {
  typedef S type __attribute__((vector_size(2 * sizeof(S))));
};
#else
template <typename S>
struct LanePair {
  using type = Eigen::Array<S, 2, 1>;
};
#endif

/// P = D⁻¹ of a symmetric 3×3 block as L⁻ᵀ diag(1/e) L⁻¹ from D = L diag(e) Lᵀ (no pivoting),
/// each pivot raised to `floor` (see solve_block_tridiagonal). \throws kelp::numerical_error if
/// a factor is not finite.
template <typename S>
Sym3<S> floored_ldlt_inverse(const Sym3<S>& d, S floor) {
  const S e0 = std::max(d.xx, floor), i0 = S(1) / e0;
  const S l10 = d.yx * i0, l20 = d.zx * i0;
  const S e1 = std::max(d.yy - l10 * d.yx, floor), i1 = S(1) / e1;
  const S l21 = (d.zy - l20 * d.yx) * i1;
  const S e2 = std::max(d.zz - l20 * d.zx - l21 * l21 * e1, floor), i2 = S(1) / e2;
  if (!is_finite(i0 + i1 + i2 + l10 + l20 + l21))
    ::kelp::detail::throw_numerical_error(
        "tether Newton step: non-finite Jacobian block; the state is unchanged");
  // L⁻¹ = [1 0 0; m10 1 0; m20 m21 1].
  const S m10 = -l10, m21 = -l21, m20 = l10 * l21 - l20;
  return {i0 + m10 * m10 * i1 + m20 * m20 * i2,
          m10 * i1 + m20 * m21 * i2,
          m20 * i2,
          i1 + m21 * m21 * i2,
          m21 * i2,
          i2};
}

/// D⁻¹ = g N of a symmetric positive definite 3×3 block D (a scalar block or a pair of lanes),
/// the LDLᵀ inverse L⁻ᵀ diag(1/e) L⁻¹ (D = L diag(e) Lᵀ, no pivoting) written fraction-free
/// over one division, so that everything built from D⁻¹ can be formed from N while g is being
/// computed. With e0 = d_xx, det₂ = d_xx d_yy − d_yx² = e0 e1, t21 = d_xx d_zy − d_yx d_zx
/// = det₂ l21, t20 = d_yx t21 − d_zx det₂ = e0 det₂ m20 ((m20, m21, 1) the last row of L⁻¹) and
/// det₃ = d_zz e0 det₂ − (d_zx² det₂ + t21²) = e0² e1 e2 (each the product form of an
/// elimination step, with its cancellation, so as accurate), g = 1 / (e0 det₂ det₃) and
///   N = [det₂ det₃ + d_yx² det₃ + t20²,  −e0 (d_yx det₃ + t20 t21),  e0 det₂ t20;
///        ·,  e0² (det₃ + t21²),  −e0² det₂ t21;   ·,  ·,  e0² det₂²],
/// the diagonal a sum of positive terms as in L⁻ᵀ diag(1/e) L⁻¹. When a pivot is below `floor`
/// (tested before dividing: e0 ≥ floor, det₂ ≥ floor e0, det₃ ≥ floor e0 det₂) or e0 det₂ det₃
/// is not a finite normal number, N = floored_ldlt_inverse(D) and g = 1, lane by lane.
template <typename T, typename S>
void invert_block(const Sym3<T>& d, S floor, Sym3<T>& nm, T& g) {
  const T det2 = d.xx * d.yy - d.yx * d.yx, t21 = d.xx * d.zy - d.yx * d.zx;
  const T t20 = d.yx * t21 - d.zx * det2, e001 = d.xx * det2;
  const T det3 = d.zz * e001 - (d.zx * d.zx * det2 + t21 * t21);
  const T den = e001 * det3;
  const S big = std::numeric_limits<S>::max(), tiny = std::numeric_limits<S>::min();
  bool ok;
  if constexpr (std::is_arithmetic_v<T>) {
    ok = d.xx >= floor && det2 >= floor * d.xx && det3 >= floor * e001 && den <= big && den >= tiny;
  } else if constexpr (std::is_base_of_v<Eigen::ArrayBase<T>, T>) {
    ok = ((d.xx >= floor) && (det2 >= floor * d.xx) && (det3 >= floor * e001) && (den <= big) &&
          (den >= tiny))
             .all();
  } else {  // GCC/Clang vector: comparisons give lane masks
    const auto m = (d.xx >= floor) & (det2 >= floor * d.xx) & (det3 >= floor * e001) &
                   (den <= big) & (den >= tiny);
    ok = m[0] && m[1];
  }
  if (ok) {
    g = S(1) / den;
    const T e00 = d.xx * d.xx;
    nm.xx = (det2 + d.yx * d.yx) * det3 + t20 * t20;
    nm.yx = d.xx * (S(0) - (d.yx * det3 + t20 * t21));
    nm.zx = e001 * t20;
    nm.yy = e00 * (det3 + t21 * t21);
    nm.zy = (S(0) - e00 * det2) * t21;
    nm.zz = e00 * (det2 * det2);
  } else if constexpr (std::is_arithmetic_v<T>) {
    nm = floored_ldlt_inverse(d, floor);
    g = S(1);
  } else {
    const Sym3<S> q0 =
        floored_ldlt_inverse(Sym3<S>{d.xx[0], d.yx[0], d.zx[0], d.yy[0], d.zy[0], d.zz[0]}, floor);
    const Sym3<S> q1 =
        floored_ldlt_inverse(Sym3<S>{d.xx[1], d.yx[1], d.zx[1], d.yy[1], d.zy[1], d.zz[1]}, floor);
    nm = {T{q0.xx, q1.xx}, T{q0.yx, q1.yx}, T{q0.zx, q1.zx},
          T{q0.yy, q1.yy}, T{q0.zy, q1.zy}, T{q0.zz, q1.zz}};
    g = T{S(1), S(1)};
  }
}

/// A lane pair V read from two consecutive scalars (the layout of the kept factors).
template <typename V, typename S>
V load_lane_pair(const S* in) {
  if constexpr (std::is_trivially_copyable_v<V>) {
    V x;
    std::memcpy(&x, in, sizeof(V));
    return x;
  } else {
    return V{in[0], in[1]};
  }
}

/// A lane pair V written to two consecutive scalars.
template <typename V, typename S>
void store_lane_pair(S* out, const V& x) {
  if constexpr (std::is_trivially_copyable_v<V>) {
    std::memcpy(out, &x, sizeof(V));
  } else {
    out[0] = x[0];
    out[1] = x[1];
  }
}

/// Per elimination step, the block elimination keeps 15 lane pairs: P = D'⁻¹ (symmetric: xx, yx,
/// zx, yy, zy, zz) and C = A P (row by row); the meeting node's P takes 6 scalars after the last
/// step.
inline constexpr int kKeptStepSize = 30;
static_assert(kKeptStepSize == kNewtonFactorStepSize, "newton_factor_size (state.hpp) is stale");

// The solve with a kept factor (kelp/tether/kept_solve_body.hpp): once for the build's own
// instructions, and where kelp dispatches at run time once more for AVX2 (VEX-encoded), taken
// as the force passes are (force_passes_take_avx2). Doxygen does not read them (details).
#if !defined(KELP_DOXYGEN)
namespace kept_baseline {
#define KELP_KEPT_SOLVE_BODY 1
#include "kelp/tether/kept_solve_body.hpp"  // IWYU pragma: keep
#undef KELP_KEPT_SOLVE_BODY
}  // namespace kept_baseline

#if defined(KELP_X86_DISPATCH)
KELP_AVX2_BEGIN
namespace kept_avx2 {
#define KELP_KEPT_SOLVE_BODY 1
#include "kelp/tether/kept_solve_body.hpp"  // IWYU pragma: keep
#undef KELP_KEPT_SOLVE_BODY
}  // namespace kept_avx2
KELP_AVX2_END
#endif
#endif  // KELP_DOXYGEN

/// Solves J δ = rhs over the free nodes f0…f1, J = c_m M + c_v (−∂F/∂v) + c_x (−∂F/∂x), block
/// tridiagonal and symmetric positive definite. The off-diagonal block of segment s is −A_s with
/// A_s = α_s u uᵀ + β_s I (α = c_v BA/l + c_x k_uu, β = c_x k_perp); the diagonal block of node
/// i is D_i = c_m M_i + c_v D_v,i + c_x kz_i e_z e_zᵀ + A_{i−1} + A_i (A_{−1} = A_N = 0).
///
/// Twisted block elimination ("burn at both ends"): a top chain eliminates nodes f0, f0+1, …,
/// m−1 and a bottom chain nodes f1, f1−1, …, m+1 in the same loop (block LDLᵀ from both ends),
/// in the two lanes of LanePair: two independent dependency chains, advanced by the same
/// instructions (SIMD for double). Eliminating node i, whose block after the earlier
/// eliminations is D'_i, with P_i = D'⁻¹_i and z_i = P_i rhs'_i, adds A − A P_i A to the block
/// of its neighbour towards m and A z_i to its rhs (A the segment between them). The chains meet
/// at the middle node m, whose block (both neighbours eliminated) gives δ_m; the back
/// substitution δ_i = z_i + P_i A δ_k (k the neighbour towards m) then runs outward both ways.
/// Each D' is inverted by invert_block as P = g N with a single division g = 1/(…), so that
/// A P A = g L, L = u eᵀ + e uᵀ + β² N, e = ½ α² (u·N u) u + α β N u, is formed while the
/// division runs: the dependency chain per step is D' → g → A − g L → next D'. The right-hand
/// side goes on as A z = C rhs' (C = A P) and the back substitution is δ_i = z_i + Cᵀ δ_k: one
/// 3×3 product per step on each of their dependency chains, so that a solve with a kept factor
/// (solve_factored_block_tridiagonal) costs about a fifth of the factorisation.
///
/// Pivot floor: in exact arithmetic every LDLᵀ pivot of every D' is at least λ_min(J) ≥ c_m ·
/// min_node_mass (J − c_m M is positive semi-definite); a computed pivot below half that bound
/// is round-off (e.g. (γh)² EA/l ≫ M at a very large step, or a very short segment) and is
/// raised to it (floored_ldlt_inverse), which keeps the factor positive definite and the
/// direction a descent direction for the line search; a non-finite factor throws
/// kelp::numerical_error. The twisted elimination's blocks D' are not those of a one-sided
/// sweep, so where the floor acts the result differs from that of a one-sided elimination (both
/// are regularised solutions; elsewhere they agree to round-off). A non-finite right-hand side
/// is not checked: it gives a non-finite δ.
///
/// Reads the Jacobian ingredients of the last compute_forces<true> and ws.rhs; writes the free
/// columns of ws.delta (the kinematic end columns are left as they are) and keeps the factor in
/// `kept` (newton_factor_size(nodes) scalars; the meeting node's block only when `keep_meeting`:
/// without it kKeptStepSize · (nodes / 2) suffice), so that solve_factored_block_tridiagonal can
/// solve for further right-hand sides with it. O(N), no heap allocation. `V` is the lane
/// pair (a template parameter for the tests).
template <typename Scalar, typename V = typename LanePair<Scalar>::type>
void factor_solve_block_tridiagonal(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                                    Scalar c_m, Scalar c_v, Scalar c_x, Scalar* kept,
                                    bool keep_meeting) {
  using S = Scalar;
  const int n = model.segments();
  const int f0 = model.first_free_node(), f1 = model.last_free_node();
  if (f1 < f0) return;
  const S floor = S(0.5) * c_m * model.min_node_mass();
  // Meeting node m; the chains (lane 0: top, lane 1: bottom) eliminate `pairs` nodes each side
  // by side. With an even number of free nodes the top chain has one more, f0, eliminated
  // first in both lanes.
  const int m = f0 + (f1 - f0 + 1) / 2, pairs = f1 - m;
  const bool extra = m - f0 > pairs;
  const auto keep = [](S* out, const V& x) { store_lane_pair(out, x); };

  const auto lanes = [](const auto& v, int i0, int i1) { return V{v(i0), v(i1)}; };
  const auto lanes_row = [](const auto& a, int row, int i0, int i1) {
    return V{a(row, i0), a(row, i1)};
  };
  const auto put = [](auto& a, int row, int i0, int i1, const V& x) {
    a(row, i0) = x[0];
    a(row, i1) = x[1];
  };
  // Each chain carries the coupling of the node it eliminated last to the next one:
  // A − A P A (cpl) and A z (cr). Before the first node P = 0 and z = 0 (cpl = A, cr = 0), A
  // being the segment to the kinematic end, or zero when the end is free.
  const auto end_coupling = [&](int s) {
    if (s < 0 || s >= n) return Sym3<S>{S(0), S(0), S(0), S(0), S(0), S(0)};
    const Matrix3<S> a = segment_block(ws, s, c_v, c_x);
    return Sym3<S>{a(0, 0), a(1, 0), a(2, 0), a(1, 1), a(2, 1), a(2, 2)};
  };
  const Sym3<S> top = end_coupling(f0 - 1), bottom = end_coupling(f1);
  const Sym3<S> first = extra ? top : bottom;
  Sym3<V> cpl{V{top.xx, first.xx}, V{top.yx, first.yx}, V{top.zx, first.zx},
              V{top.yy, first.yy}, V{top.zy, first.zy}, V{top.zz, first.zz}};
  V cr0{S(0), S(0)}, cr1{S(0), S(0)}, cr2{S(0), S(0)};
  // Step k eliminates nodes (i0, i1) = (m − pairs + k, f1 − k), both f0 at k = −1; step
  // k = pairs stops at the meeting node, after its D in `base`. (One loop, so that its body is
  // compiled once.)
  Sym3<V> base;
  V r0, r1, r2;
  for (int k = extra ? -1 : 0;; ++k) {
    const int i0 = m - pairs + k, i1 = k < 0 ? f0 : f1 - k;
    // D = c_m (a I + b q qᵀ) + c_v D_v + c_x kz e_z e_zᵀ.
    {
      const V a = c_m * lanes(ws.mass_iso, i0, i1), bq = c_m * lanes(ws.mass_tan, i0, i1);
      const V qx = lanes_row(ws.tangent, 0, i0, i1), qy = lanes_row(ws.tangent, 1, i0, i1),
              qz = lanes_row(ws.tangent, 2, i0, i1);
      const V bx = bq * qx, by = bq * qy, bz = bq * qz;
      base.xx = a + bx * qx + c_v * lanes_row(ws.node_dv, 0, i0, i1);
      base.yx = by * qx + c_v * lanes_row(ws.node_dv, 1, i0, i1);
      base.zx = bz * qx + c_v * lanes_row(ws.node_dv, 2, i0, i1);
      base.yy = a + by * qy + c_v * lanes_row(ws.node_dv, 3, i0, i1);
      base.zy = bz * qy + c_v * lanes_row(ws.node_dv, 4, i0, i1);
      base.zz =
          a + bz * qz + c_v * lanes_row(ws.node_dv, 5, i0, i1) + c_x * lanes(ws.node_kz, i0, i1);
      if (ws.any_contact) {
        // Obstacle contacts' normal stiffness (kelp/tether/contact.hpp).
        base.xx += c_x * lanes_row(ws.node_kc, 0, i0, i1);
        base.yx += c_x * lanes_row(ws.node_kc, 1, i0, i1);
        base.zx += c_x * lanes_row(ws.node_kc, 2, i0, i1);
        base.yy += c_x * lanes_row(ws.node_kc, 3, i0, i1);
        base.zy += c_x * lanes_row(ws.node_kc, 4, i0, i1);
        base.zz += c_x * lanes_row(ws.node_kc, 5, i0, i1);
      }
      r0 = lanes_row(ws.rhs, 0, i0, i1) + cr0;
      r1 = lanes_row(ws.rhs, 1, i0, i1) + cr1;
      r2 = lanes_row(ws.rhs, 2, i0, i1) + cr2;
    }
    if (k == pairs) break;
    // D' = D + A of the segment on the other side (top: i0, bottom: i1 − 1), which couples to
    // the chain's next node, + the coupling to the eliminated neighbour.
    const int s0 = i0, s1 = k < 0 ? f0 : i1 - 1;
    const V al = c_v * lanes(ws.seg_c_uu, s0, s1) + c_x * lanes(ws.seg_k_uu, s0, s1);
    const V be = c_x * lanes(ws.seg_k_perp, s0, s1);
    const V ux = lanes_row(ws.direction, 0, s0, s1), uy = lanes_row(ws.direction, 1, s0, s1),
            uz = lanes_row(ws.direction, 2, s0, s1);
    Sym3<V> a_s;
    {
      const V ax = al * ux, ay = al * uy, az = al * uz;
      a_s = {ax * ux + be, ay * ux, az * ux, ay * uy + be, az * uy, az * uz + be};
    }
    const Sym3<V> d{base.xx + a_s.xx + cpl.xx, base.yx + a_s.yx + cpl.yx,
                    base.zx + a_s.zx + cpl.zx, base.yy + a_s.yy + cpl.yy,
                    base.zy + a_s.zy + cpl.zy, base.zz + a_s.zz + cpl.zz};
    // P = D'⁻¹ = g N. Alongside the division: N u, L = u eᵀ + e uᵀ + β² N with
    // e = ½ α² (u·N u) u + α β N u (A P A = g L); then only products with g.
    Sym3<V> nm;
    V g;
    invert_block(d, floor, nm, g);
    const V nx = nm.xx * ux + nm.yx * uy + nm.zx * uz;
    const V ny = nm.yx * ux + nm.yy * uy + nm.zy * uz;
    const V nz = nm.zx * ux + nm.zy * uy + nm.zz * uz;
    const V h = S(0.5) * al * al * (ux * nx + uy * ny + uz * nz), ab = al * be, bb = be * be;
    const V ex = h * ux + ab * nx, ey = h * uy + ab * ny, ez = h * uz + ab * nz;
    const V lxx = ux * ex, lyy = uy * ey, lzz = uz * ez;
    const Sym3<V> l{lxx + lxx + bb * nm.xx,         uy * ex + ey * ux + bb * nm.yx,
                    uz * ex + ez * ux + bb * nm.zx, lyy + lyy + bb * nm.yy,
                    uz * ey + ez * uy + bb * nm.zy, lzz + lzz + bb * nm.zz};
    // The coupling to the chain's next node, A − A P A = A − g L (a_s and l are done with).
    cpl = {a_s.xx - g * l.xx, a_s.yx - g * l.yx, a_s.zx - g * l.zx,
           a_s.yy - g * l.yy, a_s.zy - g * l.zy, a_s.zz - g * l.zz};
    // P = g N, C = A P = α u (P u)ᵀ + β P; the chain's rhs goes on as A z = C rhs' and the back
    // substitution is δ_i = z_i + Cᵀ δ_k (z = P rhs'): one 3×3 product per step on each
    // dependency chain (the form solve_factored_block_tridiagonal repeats). z goes to δ's
    // columns until the back substitution; P and C to `kept`, step by step (both lanes side by
    // side), each as soon as it is formed (fewer values live at once: the loop spilled).
    S* const out = kept + kKeptStepSize * (k + (extra ? 1 : 0));
    const Sym3<V> p{g * nm.xx, g * nm.yx, g * nm.zx, g * nm.yy, g * nm.zy, g * nm.zz};
    keep(out, p.xx);
    keep(out + 2, p.yx);
    keep(out + 4, p.zx);
    keep(out + 6, p.yy);
    keep(out + 8, p.zy);
    keep(out + 10, p.zz);
    put(ws.delta, 0, i0, i1, p.xx * r0 + p.yx * r1 + p.zx * r2);
    put(ws.delta, 1, i0, i1, p.yx * r0 + p.yy * r1 + p.zy * r2);
    put(ws.delta, 2, i0, i1, p.zx * r0 + p.zy * r1 + p.zz * r2);
    const V px = g * nx, py = g * ny, pz = g * nz;
    {
      const V ax = al * ux;
      const V c00 = ax * px + be * p.xx, c01 = ax * py + be * p.yx, c02 = ax * pz + be * p.zx;
      keep(out + 12, c00);
      keep(out + 14, c01);
      keep(out + 16, c02);
      cr0 = c00 * r0 + c01 * r1 + c02 * r2;
    }
    {
      const V ay = al * uy;
      const V c10 = ay * px + be * p.yx, c11 = ay * py + be * p.yy, c12 = ay * pz + be * p.zy;
      keep(out + 18, c10);
      keep(out + 20, c11);
      keep(out + 22, c12);
      cr1 = c10 * r0 + c11 * r1 + c12 * r2;
    }
    {
      const V az = al * uz;
      const V c20 = az * px + be * p.zx, c21 = az * py + be * p.zy, c22 = az * pz + be * p.zz;
      keep(out + 24, c20);
      keep(out + 26, c21);
      keep(out + 28, c22);
      cr2 = c20 * r0 + c21 * r1 + c22 * r2;
    }
    if (k < 0) {
      // Lane 1 starts the bottom chain.
      cpl = {V{cpl.xx[0], bottom.xx}, V{cpl.yx[0], bottom.yx}, V{cpl.zx[0], bottom.zx},
             V{cpl.yy[0], bottom.yy}, V{cpl.zy[0], bottom.zy}, V{cpl.zz[0], bottom.zz}};
      cr0 = V{cr0[0], S(0)};
      cr1 = V{cr1[0], S(0)};
      cr2 = V{cr2[0], S(0)};
    }
  }
  // Meeting node: δ_m = D'⁻¹_m rhs'_m, with the couplings to both eliminated neighbours (r
  // holds rhs_m plus lane 0's).
  {
    Sym3<S> pm;
    S g;
    invert_block(Sym3<S>{base.xx[0] + cpl.xx[0] + cpl.xx[1], base.yx[0] + cpl.yx[0] + cpl.yx[1],
                         base.zx[0] + cpl.zx[0] + cpl.zx[1], base.yy[0] + cpl.yy[0] + cpl.yy[1],
                         base.zy[0] + cpl.zy[0] + cpl.zy[1], base.zz[0] + cpl.zz[0] + cpl.zz[1]},
                 floor, pm, g);
    const S s0 = r0[0] + cr0[1], s1 = r1[0] + cr1[1], s2 = r2[0] + cr2[1];
    const S p[6] = {g * pm.xx, g * pm.yx, g * pm.zx, g * pm.yy, g * pm.zy, g * pm.zz};
    ws.delta(0, m) = p[0] * s0 + p[1] * s1 + p[2] * s2;
    ws.delta(1, m) = p[1] * s0 + p[3] * s1 + p[4] * s2;
    ws.delta(2, m) = p[2] * s0 + p[4] * s1 + p[5] * s2;
    if (keep_meeting) std::copy(p, p + 6, kept + kKeptStepSize * (pairs + (extra ? 1 : 0)));
  }
  kept_baseline::back_substitute_block_tridiagonal<Scalar, V>(model, kept, ws.delta);
}

/// Solves J δ = rhs with the factor that factor_solve_block_tridiagonal kept in `kept` (with
/// keep_meeting): forward elimination of rhs (into the free columns of δ) and back
/// substitution, the same arithmetic as the factorisation's own solve, so that the same rhs
/// gives the same δ bit for bit; on AVX2 where the force passes take it (the same bits). Reads
/// only `kept` and `rhs`; O(N), no heap allocation.
template <typename Scalar, typename V = typename LanePair<Scalar>::type>
void solve_factored_block_tridiagonal(const TetherModel<Scalar>& model, const Scalar* kept,
                                      const Matrix3X<Scalar>& rhs, Matrix3X<Scalar>& delta) {
#if defined(KELP_X86_DISPATCH)
  if constexpr (std::is_same_v<Scalar, double> &&
                std::is_same_v<V, typename LanePair<double>::type>)
    if (force_passes_take_avx2())
      return kept_avx2::solve_factored_block_tridiagonal<Scalar, V>(model, kept, rhs, delta);
#endif
  kept_baseline::solve_factored_block_tridiagonal<Scalar, V>(model, kept, rhs, delta);
}

/// solve_block_tridiagonal's elimination with its factor kept in ws.block_inv (as scratch: the
/// meeting node's block is not kept): solves J δ = rhs, see factor_solve_block_tridiagonal.
template <typename Scalar, typename V = typename LanePair<Scalar>::type>
void solve_block_tridiagonal(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                             Scalar c_m, Scalar c_v, Scalar c_x) {
  KELP_ASSERT(ws.block_inv.size() >= kKeptStepSize * (model.nodes() / 2));
  factor_solve_block_tridiagonal<Scalar, V>(model, ws, c_m, c_v, c_x, ws.block_inv.data(), false);
}

/// The branch compute_forces takes for a segment of extension e = l_s − l [m] and stretch rate r
/// [m/s] (2 taut, 1 dashpot only, 0 clamped at zero or slack without a dashpot), with the
/// segment's EA/l_s and BA/l_s (its own for segment 0 at a winch); `clamp` when the axial force
/// is clamped at zero (no `compressive_damping`).
template <typename Scalar>
Scalar segment_branch(bool clamp, Scalar e, Scalar r, Scalar ea_l, Scalar ba_l) {
  const bool elastic = e > Scalar(0);
  const Scalar force = (elastic ? ea_l * e : Scalar(0)) + ba_l * r;
  if (clamp && !(force > Scalar(0))) return Scalar(0);
  return elastic ? Scalar(2) : Scalar(1);
}

/// segment_branch with the model's clamp.
template <typename Scalar>
Scalar segment_branch(const TetherModel<Scalar>& model, Scalar e, Scalar r, Scalar ea_l,
                      Scalar ba_l) {
  return segment_branch(!model.parameters().compressive_damping, e, r, ea_l, ba_l);
}

/// segment_branch with the model's uniform EA/l and BA/l.
template <typename Scalar>
Scalar segment_branch(const TetherModel<Scalar>& model, Scalar e, Scalar r) {
  return segment_branch(model, e, r, model.axial_spring(), model.axial_damper());
}

/// Primal–dual active set for the kinks of the axial force (semismooth Newton on
/// T = max(0, EA·max(0, ε) + BA·ε̇), or without the outer max when compressive_damping), shared
/// by both Newton matrices. Over a Newton correction δ (velocities; positions move by γh δ) a
/// segment's force is a monotone piecewise-linear function of w = u·(δ_{s+1} − δ_s) with three
/// branches: 2 elastic and dashpot (taut), 1 dashpot only (slack), 0 no force (clamped). In the
/// linear model each segment sits on one branch (ws.seg_branch), extended linearly beyond its
/// kink (negative values allowed inside the linear model). The branches start from those at the
/// current point (segments with l_s ≥ (1 − band)·l start taut) and are updated from the predicted
/// extension and stretch rate until they repeat (at most `max_passes` passes). In each pass the
/// force of a segment off its true branch is replaced in ws.rhs by its branch's, and
/// `solve(on_true_branches)` forms the Newton matrix with the slopes of the branches in
/// ws.seg_branch (only the true ones when `on_true_branches`) and solves it for ws.rhs into
/// ws.delta. Reads ws.rhs (= −R) and the segment terms of compute_forces<true>; ws.rhs is
/// restored. Returns the number of passes (factorisations).
template <typename Scalar, typename Solve>
int segment_active_set(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws, Scalar gh,
                       Scalar band, int max_passes, Solve&& solve) {
  const int n = model.segments();
  const int f0 = model.first_free_node(), f1 = model.last_free_node();
  // Each segment's rest length and constants (segment 0's are its own at a winch), read once.
  const SegmentSprings<Scalar> first = segment_springs(model, ws, 0),
                               rest = segment_springs(model, ws, 1);
  const auto springs = [&](int s) -> const SegmentSprings<Scalar>& {
    return s == 0 ? first : rest;
  };
  // segment_branch with the model's clamp read once.
  const bool clamp = !model.parameters().compressive_damping;
  const auto branch_of = [clamp](Scalar e, Scalar r, const SegmentSprings<Scalar>& k) {
    return segment_branch(clamp, e, r, k.ea_l, k.ba_l);
  };
  // A parted segment (TetherState::parted) has no force on any branch.
  const auto true_branch = [&](int s) {
    if (ws.is_parted(s)) return Scalar(0);
    const SegmentSprings<Scalar>& k = springs(s);
    return branch_of(ws.stretched_length(s) - k.l, ws.seg_rate(s), k);
  };
  // Updates the branches from the extension and rate predicted by ws.delta; true if any changed.
  const auto update = [&]() {
    bool changed = false;
    for (int s = 0; s < n; ++s) {
      Scalar w(0);
      const auto u = ws.direction.col(s);
      if (s >= f0 && s <= f1) w -= u.dot(ws.delta.col(s));
      if (s + 1 >= f0 && s + 1 <= f1) w += u.dot(ws.delta.col(s + 1));
      const SegmentSprings<Scalar>& k = springs(s);
      const Scalar now =
          ws.is_parted(s) ? Scalar(0)
                          : branch_of(ws.stretched_length(s) - k.l + gh * w, ws.seg_rate(s) + w, k);
      if (now != ws.seg_branch(s)) {
        changed = true;
        ws.seg_branch(s) = now;
      }
    }
    return changed;
  };
  bool on_true_branch = true;
  for (int s = 0; s < n; ++s) {
    const Scalar bt = true_branch(s);
    const bool banded = band > Scalar(0) &&
                        ws.stretched_length(s) >= (Scalar(1) - band) * springs(s).l &&
                        !ws.is_parted(s);
    ws.seg_branch(s) = banded ? Scalar(2) : bt;
    if (ws.seg_branch(s) != bt) on_true_branch = false;
  }
  int pass = 0;
  if (on_true_branch) {
    // Common case: plain Newton; done unless the prediction crosses a kink.
    solve(true);
    if (max_passes <= 1 || !update()) return 1;
    pass = 1;
  }
  ws.rhs_true = ws.rhs;
  for (;; ++pass) {
    ws.rhs = ws.rhs_true;
    for (int s = 0; s < n; ++s) {
      const Scalar b = ws.seg_branch(s);
      if (b == true_branch(s)) continue;
      // The branch's force at the current point replaces the true one.
      const SegmentSprings<Scalar> k = springs(s);
      const Scalar e = ws.stretched_length(s) - k.l, r = ws.seg_rate(s);
      const Scalar tb =
          (b == Scalar(2) ? k.ea_l * e : Scalar(0)) +
          (b > Scalar(0) ? k.ba_l * segment_fade(model, ws, s, ws.stretched_length(s)).value * r
                         : Scalar(0));
      const Vector3<Scalar> df = (gh * (tb - ws.tension(s))) * ws.direction.col(s);
      ws.rhs.col(s) += df;
      ws.rhs.col(s + 1) -= df;
    }
    solve(false);
    if (pass + 1 >= max_passes || !update()) break;
  }
  ws.rhs.swap(ws.rhs_true);
  return pass + 1;
}

/// Newton direction with the symmetric block-tridiagonal matrix and the active set of
/// segment_active_set: the slopes of a segment off its true branch are its branch's. Reads
/// ws.rhs (= −R) and the Jacobian terms of compute_forces<true>; writes ws.delta; ws.rhs and the
/// Jacobian terms are restored.
///
/// Each pass factors the Newton matrix (factor_solve_block_tridiagonal): into `kept` with the
/// meeting node's block when given (newton_factor_size(nodes) scalars, the last pass's factor
/// then serves solve_factored_block_tridiagonal, its branches being those left in
/// ws.seg_branch), else into ws.block_inv as scratch. Returns the number of passes
/// (factorisations).
template <typename Scalar>
int active_set_direction(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws, Scalar gh,
                         Scalar band, int max_passes, Scalar* kept = nullptr) {
  const int n = model.segments();
  bool saved = false;
  const int passes = segment_active_set(model, ws, gh, band, max_passes, [&](bool on_true) {
    if (!on_true) {
      if (!saved) {
        ws.seg_true_k_uu = ws.seg_k_uu;
        ws.seg_true_c_uu = ws.seg_c_uu;
        saved = true;
      }
      for (int s = 0; s < n; ++s) {
        const Scalar b = ws.seg_branch(s);
        const SegmentSprings<Scalar> k = segment_springs(model, ws, s);
        if (ws.is_parted(s) || b == segment_branch(model, ws.stretched_length(s) - k.l,
                                                   ws.seg_rate(s), k.ea_l, k.ba_l)) {
          ws.seg_k_uu(s) = ws.seg_true_k_uu(s);
          ws.seg_c_uu(s) = ws.seg_true_c_uu(s);
        } else {
          ws.seg_k_uu(s) = (b == Scalar(2) ? k.ea_l : Scalar(0)) - ws.seg_k_perp(s);
          // (Off its true branch a segment has no fade slope in k: a clamped one has r ≤ 0, a
          // banded one is longer than the fade length.)
          ws.seg_c_uu(s) = b > Scalar(0)
                               ? k.ba_l * segment_fade(model, ws, s, ws.stretched_length(s)).value
                               : Scalar(0);
        }
      }
    }
    if (kept)
      factor_solve_block_tridiagonal(model, ws, Scalar(1), gh, gh * gh, kept, true);
    else
      solve_block_tridiagonal(model, ws, Scalar(1), gh, gh * gh);
  });
  if (saved) {
    ws.seg_k_uu = ws.seg_true_k_uu;
    ws.seg_c_uu = ws.seg_true_c_uu;
  }
  return passes;
}

}  // namespace detail

}  // namespace kelp::tether
