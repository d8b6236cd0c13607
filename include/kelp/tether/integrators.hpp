/// \file
/// \brief Time integration of the lumped-mass tether: semi-implicit (symplectic) Euler, RK2
/// (midpoint), RK4, and implicit backward Euler / BDF2 solved by Newton's method with the
/// analytic block-tridiagonal Jacobian (O(N) block-Thomas solve); an explicit stable-dt estimate,
/// a sub-stepping driver and a static-equilibrium solve.
///
/// Kinematic ends follow the prescribed EndMotion within a step (p + vτ + ½aτ²). Explicit schemes
/// report the end forces at the start of the step, implicit ones at its end.
///
/// Every step works in preallocated workspace buffers (no heap allocation) and commits the new
/// state only when it is finite and, for the implicit schemes, when Newton's method met its
/// tolerance: an implicit step that does not converge is retried in sub-steps (halving up to
/// `ImplicitOptions::max_step_halvings` times), and a step that cannot be completed throws
/// `kelp::numerical_error` and leaves the state as it was. Time steps and the clock are doubles
/// for every Scalar; the integrator history (BDF2) lives in the TetherState.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/environment/limits.hpp"
#include "kelp/tether/lumped_mass.hpp"

namespace kelp::tether {

/// \brief Time-stepping scheme.
enum class Integrator {
  symplectic_euler,  ///< v ← v + h a(x, v); x ← x + h v (first order, symplectic)
  rk2,               ///< explicit midpoint (MoorDyn's default RK2)
  rk4,               ///< classical fourth-order Runge–Kutta
  implicit_euler,    ///< backward Euler, Newton with the block-tridiagonal Jacobian
  bdf2               ///< second-order BDF (backward Euler on the first step or after a dt change)
};

/// \brief Name of an integrator ("symplectic_euler", "rk2", "rk4", "implicit_euler", "bdf2").
inline const char* integrator_name(Integrator i) {
  switch (i) {
    case Integrator::symplectic_euler:
      return "symplectic_euler";
    case Integrator::rk2:
      return "rk2";
    case Integrator::rk4:
      return "rk4";
    case Integrator::implicit_euler:
      return "implicit_euler";
    case Integrator::bdf2:
      return "bdf2";
  }
  return "unknown";
}

/// \brief True for a value of the enumeration (false for an out-of-range cast).
inline bool is_valid(Integrator i) {
  return static_cast<int>(i) >= static_cast<int>(Integrator::symplectic_euler) &&
         static_cast<int>(i) <= static_cast<int>(Integrator::bdf2);
}

/// \brief True for the Newton-solved schemes.
inline bool is_implicit(Integrator i) {
  return i == Integrator::implicit_euler || i == Integrator::bdf2;
}

/// \brief Newton settings of the implicit schemes.
template <typename Scalar>
struct ImplicitOptions {
  /// Maximum Newton corrections per step (each: one Jacobian factorisation and solve).
  int max_iterations = 8;
  /// Newton converges when max_i |R_i| / a_i ≤ acceleration_tolerance · dt, R_i the momentum
  /// residual of node i and a_i its isotropic mass: an error ΔF in the node force shows up as
  /// γ dt ΔF / a_i, so this bounds the node forces' error per unit mass [m/s²] whatever the step,
  /// and a smaller dt is never less accurate (a fixed velocity tolerance would let the error
  /// grow as dt shrinks). At least one Newton correction is always made, so the velocity
  /// predictor alone never makes a step. Default 1.5e-4 m/s² in double (1.5e-6 m/s at 10 ms, node
  /// forces to ~3e-6 N on the benchmark line); 0.1 m/s² in single precision, whose rounding of
  /// ~10 m coordinates already costs EA/l · 6e-7 m of tension (use a softer line or double for
  /// stiff tethers).
  Scalar acceleration_tolerance =
      Scalar(std::numeric_limits<Scalar>::epsilon() > Scalar(1e-10) ? 0.1 : 1.5e-4);
  /// Segments at least (1 − band)·l long start each Newton iteration's active set in the taut
  /// branch (see detail::active_set_direction); 0 starts from the branches at the current point.
  Scalar slack_band = Scalar(0);
  /// Maximum active-set passes (block-tridiagonal solves, no force evaluation) per Newton
  /// iteration; 1 is plain Newton on the current branch.
  int max_active_set_passes = 32;
  /// When false, the last of the `max_iterations` Newton corrections is applied without
  /// evaluating the forces again (no line search, no convergence check) and the end forces are
  /// extrapolated linearly with the Jacobian. With max_iterations = 1 this is the linearly
  /// implicit (Rosenbrock–Euler-type) scheme: one force evaluation and one O(N) solve per step.
  bool check_convergence = true;
  /// Maximum line-search corrections (secant steps, each one force evaluation) per Newton
  /// iteration; 0 always takes the full Newton step.
  int max_backtracks = 6;
  /// A step whose Newton iteration does not converge is retried as two half steps, each of
  /// which may be halved again, down to dt / 2^max_step_halvings; if that fails too the step
  /// throws kelp::numerical_error with the state unchanged. 0: no retry.
  int max_step_halvings = 6;
  /// When false (the default) the water velocity, acceleration and surface elevation are sampled
  /// once per step, at the predicted node positions at t + dt (the first force evaluation), and
  /// held through the Newton iteration: the corrections move the nodes by millimetres, while
  /// sampling a sea of 64 components costs more than the rest of a force evaluation. The price
  /// is smaller than the step's own error: a 50-segment line crossing the surface in the
  /// paper's rough sea, BDF2 at 10 ms, has its end tension 0.14 % RMS off the run that samples
  /// at every iterate, against 0.6 % between 10 ms and 5 ms steps. True samples at every
  /// iterate (the discrete equations then hold exactly at the converged positions).
  bool resample_water = false;
};

/// \brief What one step (or one driver call) did.
template <typename Scalar>
struct StepReport {
  /// Steps committed (1 unless an implicit step was retried in sub-steps, or a driver took
  /// several).
  int substeps = 0;
  /// Force evaluations used, failed attempts included.
  int force_evaluations = 0;
  /// Newton corrections, failed attempts included (0 for explicit schemes).
  int newton_iterations = 0;
  /// Worst final scaled Newton residual max_i |R_i|/a_i over the committed steps [m/s] (0 for
  /// explicit schemes).
  Scalar residual = Scalar(0);
  /// Implicit steps that did not converge at their first step length and were split.
  int retries = 0;
  /// Worst final residual of the attempts that did not converge and were split [m/s].
  Scalar rejected_residual = Scalar(0);

  /// \brief Adds another step's report: counts add up, the residual is the worst.
  StepReport& operator+=(const StepReport& o) {
    substeps += o.substeps;
    force_evaluations += o.force_evaluations;
    newton_iterations += o.newton_iterations;
    residual = std::max(residual, o.residual);
    retries += o.retries;
    rejected_residual = std::max(rejected_residual, o.rejected_residual);
    return *this;
  }
};

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
/// A P A = g L, L = u eᵀ + e uᵀ + β² N, e = ½ α² (u·N u) u + α β N u, and N rhs' are formed
/// while the division runs: the dependency chain per step is D' → g → A − g L → next D'.
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
/// columns of ws.delta (the kinematic end columns are left as they are) and uses ws.block_inv
/// as scratch for the back substitution (per step, both lanes: N rhs', N, g, g β, α g N u, u).
/// O(N), no heap allocation. `V` is the lane pair (a template parameter for the tests).
template <typename Scalar, typename V = typename LanePair<Scalar>::type>
void solve_block_tridiagonal(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                             Scalar c_m, Scalar c_v, Scalar c_x) {
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
  // Each elimination step keeps kStepVectors lane pairs for the back substitution in
  // ws.block_inv, two columns per step (there are at most (N + 1) / 2 steps), both lanes of a
  // pair side by side.
  constexpr int kStepVectors = 17, kStepSize = 2 * kStepVectors;
  static_assert(kStepSize <= 2 * std::decay_t<decltype(ws.block_inv)>::RowsAtCompileTime);
  KELP_ASSERT(ws.block_inv.cols() == model.nodes());
  const auto keep = [](S* out, const V& x) {
    if constexpr (std::is_trivially_copyable_v<V>) {
      std::memcpy(out, &x, sizeof(V));
    } else {
      out[0] = x[0];
      out[1] = x[1];
    }
  };
  const auto kept = [](const S* in) {
    if constexpr (std::is_trivially_copyable_v<V>) {
      V x;
      std::memcpy(&x, in, sizeof(V));
      return x;
    } else {
      return V{in[0], in[1]};
    }
  };

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
    // e = ½ α² (u·N u) u + α β N u (A P A = g L), v = N r', A v; then only products with g.
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
    const V v0 = nm.xx * r0 + nm.yx * r1 + nm.zx * r2;
    const V v1 = nm.yx * r0 + nm.yy * r1 + nm.zy * r2;
    const V v2 = nm.zx * r0 + nm.zy * r1 + nm.zz * r2;
    const V uv = al * (ux * v0 + uy * v1 + uz * v2);
    const V av0 = uv * ux + be * v0, av1 = uv * uy + be * v1, av2 = uv * uz + be * v2;
    // Coupling to the chain's next node: A − A P A = A − g L, A z = g A v.
    cpl = {a_s.xx - g * l.xx, a_s.yx - g * l.yx, a_s.zx - g * l.zx,
           a_s.yy - g * l.yy, a_s.zy - g * l.zy, a_s.zz - g * l.zz};
    cr0 = g * av0;
    cr1 = g * av1;
    cr2 = g * av2;
    // Kept for the back substitution, step by step (both lanes side by side).
    {
      const V ag = al * g;
      S* const out = ws.block_inv.data() + kStepSize * (k + (extra ? 1 : 0));
      keep(out, v0);
      keep(out + 2, v1);
      keep(out + 4, v2);
      keep(out + 6, nm.xx);
      keep(out + 8, nm.yx);
      keep(out + 10, nm.zx);
      keep(out + 12, nm.yy);
      keep(out + 14, nm.zy);
      keep(out + 16, nm.zz);
      keep(out + 18, g);
      keep(out + 20, g * be);
      keep(out + 22, ag * nx);
      keep(out + 24, ag * ny);
      keep(out + 26, ag * nz);
      keep(out + 28, ux);
      keep(out + 30, uy);
      keep(out + 32, uz);
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
  S y0, y1, y2;
  {
    Sym3<S> pm;
    S g;
    invert_block(Sym3<S>{base.xx[0] + cpl.xx[0] + cpl.xx[1], base.yx[0] + cpl.yx[0] + cpl.yx[1],
                         base.zx[0] + cpl.zx[0] + cpl.zx[1], base.yy[0] + cpl.yy[0] + cpl.yy[1],
                         base.zy[0] + cpl.zy[0] + cpl.zy[1], base.zz[0] + cpl.zz[0] + cpl.zz[1]},
                 floor, pm, g);
    const S s0 = r0[0] + cr0[1], s1 = r1[0] + cr1[1], s2 = r2[0] + cr2[1];
    y0 = g * (pm.xx * s0 + pm.yx * s1 + pm.zx * s2);
    y1 = g * (pm.yx * s0 + pm.yy * s1 + pm.zy * s2);
    y2 = g * (pm.zx * s0 + pm.zy * s1 + pm.zz * s2);
    ws.delta(0, m) = y0;
    ws.delta(1, m) = y1;
    ws.delta(2, m) = y2;
  }
  // Back substitution outward from m, the elimination steps in reverse:
  // δ_i = P_i (rhs'_i + A δ_k) = g (v + α N u (u·δ_k) + N (β δ_k)), k the neighbour towards m,
  // A = α u uᵀ + β I the segment between them. Step −1 (node f0 in both lanes) copies lane 0.
  V d0{y0, y0}, d1{y1, y1}, d2{y2, y2};
  for (int k = pairs - 1; k >= (extra ? -1 : 0); --k) {
    const int i0 = m - pairs + k, i1 = k < 0 ? f0 : f1 - k;
    if (k < 0) {
      d0 = V{d0[0], d0[0]};
      d1 = V{d1[0], d1[0]};
      d2 = V{d2[0], d2[0]};
    }
    const S* const in = ws.block_inv.data() + kStepSize * (k + (extra ? 1 : 0));
    const auto q = [&](int j) { return kept(in + 2 * j); };
    const V ud = q(14) * d0 + q(15) * d1 + q(16) * d2;
    const V gb = q(10), t0 = gb * d0, t1 = gb * d1, t2 = gb * d2;
    const V n00 = q(3), n10 = q(4), n20 = q(5), n11 = q(6), n21 = q(7), n22 = q(8), g = q(9);
    d0 = (g * q(0) + q(11) * ud) + (n00 * t0 + n10 * t1 + n20 * t2);
    d1 = (g * q(1) + q(12) * ud) + (n10 * t0 + n11 * t1 + n21 * t2);
    d2 = (g * q(2) + q(13) * ud) + (n20 * t0 + n21 * t1 + n22 * t2);
    put(ws.delta, 0, i0, i1, d0);
    put(ws.delta, 1, i0, i1, d1);
    put(ws.delta, 2, i0, i1, d2);
  }
}

/// Newton direction with a primal–dual active set for the kinks of the axial force (semismooth
/// Newton on T = max(0, EA·max(0, ε) + BA·ε̇), or without the outer max when
/// compressive_damping). Over a Newton correction δ (velocities; positions move by γh δ) a
/// segment's force is a monotone piecewise-linear function of w = u·(δ_{s+1} − δ_s) with three
/// branches: 2 elastic and dashpot (taut), 1 dashpot only (slack), 0 no force (clamped). In the
/// linear model each segment sits on one branch, extended linearly beyond its kink (negative
/// values allowed inside the linear model). The branches start from those at the current point
/// (segments with l_s ≥ (1 − band)·l start taut) and are updated from the predicted extension
/// and stretch rate until they repeat (at most `max_passes` solves). Reads ws.rhs (= −R) and the
/// Jacobian terms of compute_forces<true>; writes ws.delta; ws.rhs and the Jacobian terms are
/// restored.
template <typename Scalar>
void active_set_direction(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws, Scalar gh,
                          Scalar band, int max_passes) {
  const int n = model.segments();
  const int f0 = model.first_free_node(), f1 = model.last_free_node();
  const Scalar l = model.segment_length();
  const Scalar ea_l = model.axial_spring(), ba_l = model.axial_damper();
  const bool clamp = !model.parameters().compressive_damping;
  // Branch of a segment with extension e = l_s − l [m] and stretch rate r [m/s].
  const auto branch_of = [&](Scalar e, Scalar r) {
    const bool elastic = e > Scalar(0);
    if (clamp && !((elastic ? ea_l * e : Scalar(0)) + ba_l * r > Scalar(0))) return Scalar(0);
    return elastic ? Scalar(2) : Scalar(1);
  };
  const auto true_branch = [&](int s) {
    return branch_of(ws.stretched_length(s) - l, ws.seg_rate(s));
  };
  // Updates the branches from the extension and rate predicted by ws.delta; true if any changed.
  const auto update = [&]() {
    bool changed = false;
    for (int s = 0; s < n; ++s) {
      Scalar w(0);
      const auto u = ws.direction.col(s);
      if (s >= f0 && s <= f1) w -= u.dot(ws.delta.col(s));
      if (s + 1 >= f0 && s + 1 <= f1) w += u.dot(ws.delta.col(s + 1));
      const Scalar now = branch_of(ws.stretched_length(s) - l + gh * w, ws.seg_rate(s) + w);
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
    const bool banded = band > Scalar(0) && ws.stretched_length(s) >= (Scalar(1) - band) * l;
    ws.seg_branch(s) = banded ? Scalar(2) : bt;
    if (ws.seg_branch(s) != bt) on_true_branch = false;
  }
  int pass = 0;
  if (on_true_branch) {
    // Common case: plain Newton; done unless the prediction crosses a kink.
    solve_block_tridiagonal(model, ws, Scalar(1), gh, gh * gh);
    if (max_passes <= 1 || !update()) return;
    pass = 1;
  }
  ws.rhs_true = ws.rhs;
  ws.seg_true_k_uu = ws.seg_k_uu;
  ws.seg_true_c_uu = ws.seg_c_uu;
  for (;; ++pass) {
    ws.rhs = ws.rhs_true;
    for (int s = 0; s < n; ++s) {
      ws.seg_k_uu(s) = ws.seg_true_k_uu(s);
      ws.seg_c_uu(s) = ws.seg_true_c_uu(s);
      const Scalar b = ws.seg_branch(s);
      if (b == true_branch(s)) continue;
      // The branch's force at the current point replaces the true one, its slopes the true ones.
      const Scalar e = ws.stretched_length(s) - l, r = ws.seg_rate(s);
      const Scalar tb =
          (b == Scalar(2) ? ea_l * e : Scalar(0)) + (b > Scalar(0) ? ba_l * r : Scalar(0));
      const Vector3<Scalar> df = (gh * (tb - ws.tension(s))) * ws.direction.col(s);
      ws.rhs.col(s) += df;
      ws.rhs.col(s + 1) -= df;
      ws.seg_k_uu(s) = (b == Scalar(2) ? ea_l : Scalar(0)) - ws.seg_k_perp(s);
      ws.seg_c_uu(s) = b > Scalar(0) ? ba_l : Scalar(0);
    }
    solve_block_tridiagonal(model, ws, Scalar(1), gh, gh * gh);
    if (pass + 1 >= max_passes || !update()) break;
  }
  ws.seg_k_uu = ws.seg_true_k_uu;
  ws.seg_c_uu = ws.seg_true_c_uu;
  ws.rhs.swap(ws.rhs_true);
}

template <typename Scalar>
bool all_finite_fast(const Matrix3X<Scalar>& x, const Matrix3X<Scalar>& v) {
  using std::isfinite;
  return isfinite(value_of(x.sum() + v.sum()));
}

/// Commits (x, v) as the state at t + dt if finite; the state before the step becomes the
/// state's history (BDF2, velocity predictor).
template <typename Scalar>
void commit(TetherState<Scalar>& state, Matrix3X<Scalar>& x, Matrix3X<Scalar>& v, double dt,
            const char* who) {
  if (!all_finite_fast(x, v))
    ::kelp::detail::throw_numerical_error(std::string(who) +
                                          ": non-finite node state; the state is unchanged");
  // Three O(1) swaps instead of copies: the old state goes to the history, the new one in, and
  // x, v (workspace scratch) get the old history's buffers.
  state.previous_position.swap(state.position);
  state.previous_velocity.swap(state.velocity);
  state.position.swap(x);
  state.velocity.swap(v);
  state.previous_dt = dt;
  // Kahan summation of the clock (TetherState::time_carry).
  const double step = dt + state.time_carry;
  const double next = state.time + step;
  state.time_carry = step - (next - state.time);
  state.time = next;
}

/// True when the state's history is the step just before it with the same step `dt`.
template <typename Scalar>
bool history_matches(const TetherState<Scalar>& state, double dt) {
  return state.previous_dt == dt;
}

/// Checks the Newton settings. \throws kelp::invalid_argument naming the field.
template <typename Scalar>
void check_implicit_options(const ImplicitOptions<Scalar>& o) {
  KELP_CHECK(o.max_iterations >= 1, "ImplicitOptions::max_iterations must be >= 1");
  check_positive(o.acceleration_tolerance, "ImplicitOptions::acceleration_tolerance");
  check_non_negative(o.slack_band, "ImplicitOptions::slack_band");
  KELP_CHECK(o.max_active_set_passes >= 1, "ImplicitOptions::max_active_set_passes must be >= 1");
  KELP_CHECK(o.max_backtracks >= 0, "ImplicitOptions::max_backtracks must be >= 0");
  KELP_CHECK(o.max_step_halvings >= 0 && o.max_step_halvings <= 30,
             "ImplicitOptions::max_step_halvings must be in [0, 30]");
}

/// Checks a step's inputs, then gives a state whose history buffers do not fit the model (a
/// state assembled by hand) fitting ones and no history: nothing is changed unless all checks
/// pass.
template <typename Scalar>
void check_step_inputs(const TetherModel<Scalar>& model, const TetherWorkspace<Scalar>& ws,
                       TetherState<Scalar>& state, const TetherBoundary<Scalar>& b, double dt) {
  check_positive(dt, "dt");
  check_workspace(model, ws);
  KELP_CHECK(state.position.cols() == model.nodes() && state.velocity.cols() == model.nodes(),
             "state.position and state.velocity must have segments + 1 columns");
  check_boundary(b);
  const bool history_fits = state.previous_position.cols() == model.nodes() &&
                            state.previous_velocity.cols() == model.nodes();
  // One pass over the state; the named checks run only to build the message.
  if (!(all_finite_fast(state.position, state.velocity) && std::isfinite(state.time) &&
        state.previous_dt >= 0.0 &&
        (!history_fits || !state.has_history() ||
         all_finite_fast(state.previous_position, state.previous_velocity)))) {
    check_all_finite(state.position, "state.position");
    check_all_finite(state.velocity, "state.velocity");
    check_finite(state.time, "state.time");
    check_non_negative(state.previous_dt, "state.previous_dt");
    if (history_fits) {
      check_all_finite(state.previous_position, "state.previous_position");
      check_all_finite(state.previous_velocity, "state.previous_velocity");
    }
    ::kelp::detail::throw_invalid_argument("state: the sum of its coordinates overflows");
  }
  if (!history_fits) {
    state.previous_position.setZero(3, model.nodes());
    state.previous_velocity.setZero(3, model.nodes());
    state.previous_dt = 0.0;
  }
}

/// `x` in %g format, for error messages.
inline std::string format_g(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", x);
  return buf;
}

/// Refuses a Newton tolerance that the arithmetic cannot resolve: positions of magnitude |x| are
/// rounded to ε|x| (ε of double), which rounds each segment's axial force EA/l·Δl by about
/// EA/l·ε|x|; when that is above a thousand times the tolerance a_min·acceleration_tolerance on
/// the lightest node, no step can converge (e.g. a 1 cm line cut into 200 segments: EA/l = 2e9 N/m
/// at 5 m depth rounds the force to 2e-6 N against a tolerance of 3e-10 N). |x| is bounded by the
/// end nodes' distance from the origin plus the line's length. O(1).
/// \throws kelp::invalid_argument saying what to change.
template <typename Scalar>
void check_resolvable(const TetherModel<Scalar>& model, const TetherState<Scalar>& state,
                      const ImplicitOptions<Scalar>& options) {
  const int n = model.segments();
  const double reach = std::max(double(value_of(state.position.col(0).norm())),
                                double(value_of(state.position.col(n).norm()))) +
                       double(value_of(model.parameters().length));
  const double rounding =
      double(value_of(model.axial_spring())) * std::numeric_limits<double>::epsilon() * reach;
  const double tolerance =
      double(value_of(model.min_node_mass())) * double(value_of(options.acceleration_tolerance));
  if (rounding > 1000.0 * tolerance)
    ::kelp::detail::throw_invalid_argument(
        "step_implicit: this tether cannot be resolved to the Newton tolerance: segments of " +
        format_g(double(value_of(model.segment_length()))) + " m (EA/l = " +
        format_g(double(value_of(model.axial_spring()))) + " N/m) at coordinates up to " +
        format_g(reach) + " m round the axial force to ~" + format_g(rounding) +
        " N, over 1000 times the tolerance of the lightest node (" + format_g(tolerance) +
        " N); use fewer, longer segments, coordinates nearer the origin, or a larger "
        "ImplicitOptions::acceleration_tolerance");
}

/// Acceleration of every node at (x, v) [boundary already applied] into `acc`.
template <typename Scalar, typename Env>
void derivative(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws, const Env& env,
                double t, const TetherBoundary<Scalar>& b, const Matrix3X<Scalar>& x,
                const Matrix3X<Scalar>& v, Matrix3X<Scalar>& acc) {
  evaluate_forces<false>(model, ws, env, t, x, v, acc.data());
  const int n = model.segments();
  if (model.first_free_node() == 1) acc.col(0) = b.start.acceleration;
  if (model.last_free_node() == n - 1) acc.col(n) = b.end.acceleration;
}

/// Shared start of the explicit steps: checks the inputs and copies the state into x0, v0 with
/// the prescribed end motion at the start of the step applied.
template <typename Scalar>
void begin_explicit_step(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                         TetherState<Scalar>& state, const TetherBoundary<Scalar>& boundary,
                         double dt) {
  check_step_inputs(model, ws, state, boundary, dt);
  ws.x0 = state.position;
  ws.v0 = state.velocity;
  apply_boundary(model, boundary, Scalar(0), ws.x0, ws.v0);
  ws.end_impulse = EndForces<Scalar>{};
}

/// Adds weight × the end forces of the last compute_forces to ws.end_impulse.
template <typename Scalar>
void add_end_impulse(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                     const TetherBoundary<Scalar>& boundary, Scalar weight) {
  const EndForces<Scalar> f = end_forces_from_workspace(model, ws, boundary);
  ws.end_impulse.on_start += weight * f.on_start;
  ws.end_impulse.on_end += weight * f.on_end;
}

}  // namespace detail

/// \brief One semi-implicit (symplectic) Euler step of length `dt` [s]:
/// v_{n+1} = v_n + h M⁻¹F(x_n, v_n), x_{n+1} = x_n + h v_{n+1}. Stable for h ω_max < 2.
/// End forces (`ws.end_forces`) are those at the start of the step.
/// \throws kelp::invalid_argument for bad input; kelp::numerical_error (state unchanged) when
/// the result is not finite.
template <typename Scalar, typename Env>
StepReport<Scalar> step_symplectic_euler(const TetherModel<Scalar>& model,
                                         TetherWorkspace<Scalar>& ws, const Env& env,
                                         TetherState<Scalar>& state,
                                         const TetherBoundary<Scalar>& boundary, double dt) {
  detail::begin_explicit_step(model, ws, state, boundary, dt);
  const double t = state.time;
  const Scalar h = Scalar(dt);
  detail::derivative(model, ws, env, t, boundary, ws.x0, ws.v0, ws.acceleration);
  ws.end_forces = end_forces_from_workspace(model, ws, boundary);
  ws.end_impulse = {h * ws.end_forces.on_start, h * ws.end_forces.on_end};
  ws.v1.noalias() = ws.v0 + h * ws.acceleration;
  ws.x1.noalias() = ws.x0 + h * ws.v1;
  detail::apply_boundary(model, boundary, h, ws.x1, ws.v1);
  detail::commit(state, ws.x1, ws.v1, dt, "step_symplectic_euler");
  StepReport<Scalar> r;
  r.substeps = 1;
  r.force_evaluations = 1;
  return r;
}

/// \brief One explicit-midpoint (RK2) step of length `dt` [s]. End forces are those at the start
/// of the step. \throws as step_symplectic_euler.
template <typename Scalar, typename Env>
StepReport<Scalar> step_rk2(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                            const Env& env, TetherState<Scalar>& state,
                            const TetherBoundary<Scalar>& boundary, double dt) {
  detail::begin_explicit_step(model, ws, state, boundary, dt);
  const double t = state.time;
  const Scalar h = Scalar(dt), h2 = Scalar(0.5) * h;
  detail::derivative(model, ws, env, t, boundary, ws.x0, ws.v0, ws.acceleration);
  ws.end_forces = end_forces_from_workspace(model, ws, boundary);
  ws.xs.noalias() = ws.x0 + h2 * ws.v0;
  ws.vs.noalias() = ws.v0 + h2 * ws.acceleration;
  detail::apply_boundary(model, boundary, h2, ws.xs, ws.vs);
  detail::derivative(model, ws, env, t + 0.5 * dt, boundary, ws.xs, ws.vs, ws.acceleration);
  detail::add_end_impulse(model, ws, boundary, h);
  ws.x1.noalias() = ws.x0 + h * ws.vs;
  ws.v1.noalias() = ws.v0 + h * ws.acceleration;
  detail::apply_boundary(model, boundary, h, ws.x1, ws.v1);
  detail::commit(state, ws.x1, ws.v1, dt, "step_rk2");
  StepReport<Scalar> r;
  r.substeps = 1;
  r.force_evaluations = 2;
  return r;
}

namespace detail {

/// One RK4 stage's state update in one vectorised pass over the flat 3 × (N+1) arrays: with the
/// stage accelerations ws.acceleration at the stage point (·, vs), accumulates x1 += w vs,
/// v1 += w a (the first stage starts them from x0, v0) and, unless this is the last stage, moves
/// the stage point to xs = x0 + ch vs, vs = v0 + ch a. `vs` is ws.v0 (first stage) or ws.vs
/// (updated in place). The kinematic end columns are overwritten by apply_boundary afterwards.
template <typename Scalar>
void rk4_stage_update(TetherWorkspace<Scalar>& ws, const Matrix3X<Scalar>& vs, Scalar w, Scalar ch,
                      bool first, bool last) {
  const Scalar *x0 = ws.x0.data(), *v0 = ws.v0.data(), *a = ws.acceleration.data();
  const Scalar* vin = vs.data();
  Scalar *x1 = ws.x1.data(), *v1 = ws.v1.data(), *xs = ws.xs.data(), *vo = ws.vs.data();
  const auto update = [&](auto lanes, Eigen::Index j) {
    using P = decltype(lanes);
    const P wp = P::all(w), vj = P::load(vin + j), aj = P::load(a + j);
    if (first) {
      (P::load(x0 + j) + wp * vj).store(x1 + j);
      (P::load(v0 + j) + wp * aj).store(v1 + j);
    } else {
      (P::load(x1 + j) + wp * vj).store(x1 + j);
      (P::load(v1 + j) + wp * aj).store(v1 + j);
    }
    if (!last) {
      const P cp = P::all(ch);
      (P::load(x0 + j) + cp * vj).store(xs + j);
      (P::load(v0 + j) + cp * aj).store(vo + j);
    }
  };
  simd::for_each_pack<Scalar>(0, ws.x1.size(), update);
}

}  // namespace detail

/// \brief One classical RK4 step of length `dt` [s]. End forces are those at the start of the
/// step. Four force evaluations (each also giving the accelerations M⁻¹F in its last pass), each
/// followed by one vectorised pass for the stage's state update. \throws as
/// step_symplectic_euler.
template <typename Scalar, typename Env>
StepReport<Scalar> step_rk4(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                            const Env& env, TetherState<Scalar>& state,
                            const TetherBoundary<Scalar>& boundary, double dt) {
  detail::begin_explicit_step(model, ws, state, boundary, dt);
  const double t = state.time;
  const Scalar h = Scalar(dt);
  const Scalar c[4] = {Scalar(0), Scalar(0.5), Scalar(0.5), Scalar(1)};
  const Scalar w[4] = {h / Scalar(6), h / Scalar(3), h / Scalar(3), h / Scalar(6)};
  const double tc[4] = {t, t + 0.5 * dt, t + 0.5 * dt, t + dt};
  for (int k = 0; k < 4; ++k) {
    const Matrix3X<Scalar>& xk = k == 0 ? ws.x0 : ws.xs;
    const Matrix3X<Scalar>& vk = k == 0 ? ws.v0 : ws.vs;
    detail::evaluate_forces<false>(model, ws, env, tc[k], xk, vk, ws.acceleration.data());
    if (k == 0) ws.end_forces = end_forces_from_workspace(model, ws, boundary);
    detail::add_end_impulse(model, ws, boundary, w[k]);
    const bool last = k == 3;
    detail::rk4_stage_update(ws, vk, w[k], last ? Scalar(0) : c[k + 1] * h, k == 0, last);
    if (!last) detail::apply_boundary(model, boundary, c[k + 1] * h, ws.xs, ws.vs);
  }
  detail::apply_boundary(model, boundary, h, ws.x1, ws.v1);
  detail::commit(state, ws.x1, ws.v1, dt, "step_rk4");
  StepReport<Scalar> r;
  r.substeps = 1;
  r.force_evaluations = 4;
  return r;
}

namespace detail {

/// Seabed normal force of every node of `state` into ws.friction_normal (as compute_forces).
template <typename Scalar>
void freeze_friction_normals(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                             Scalar bed, const TetherState<Scalar>& state) {
  const TetherParameters<Scalar>& p = model.parameters();
  const Scalar k = p.seabed_stiffness * p.diameter, c = p.seabed_damping * p.diameter;
  for (int i = 0; i < model.nodes(); ++i) {
    const Scalar pen = state.position(2, i) - bed;
    const Scalar ramp = pen < p.seabed_damping_depth ? pen / p.seabed_damping_depth : Scalar(1);
    const Scalar normal = (pen * k + state.velocity(2, i) * c * ramp) * model.node_length(i);
    ws.friction_normal(i) = pen > Scalar(0) && normal > Scalar(0) ? normal : Scalar(0);
  }
}

/// One attempt at an implicit step of length dt (see step_implicit): commits the new state and
/// returns true when Newton's method converged (or options.check_convergence is false); returns
/// false with the state untouched otherwise. Adds its work to `report`. Inputs already checked.
template <typename Scalar, typename Env>
bool implicit_attempt(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws, const Env& env,
                      TetherState<Scalar>& state, const TetherBoundary<Scalar>& boundary, double dt,
                      bool bdf2, const ImplicitOptions<Scalar>& options,
                      StepReport<Scalar>& report) {
  using std::abs;
  const double t1 = state.time + dt;
  const int f0 = model.first_free_node(), f1 = model.last_free_node();
  // The history (BDF2, velocity predictor) is used only if it is this state's previous step.
  const bool history = history_matches(state, dt);
  const bool use_bdf2 = bdf2 && history;
  const Scalar gamma = use_bdf2 ? Scalar(2) / Scalar(3) : Scalar(1);
  const Scalar gh = gamma * Scalar(dt);
  const Scalar tolerance = options.acceleration_tolerance * Scalar(dt);
  // x̂ (ws.x0) and v̂ (ws.v0); initial guess v1 = v_n (or the BDF2 extrapolation).
  // One vectorised pass over the flat 3 × (N+1) arrays for the history, the predictor and its
  // positions. Predictor: linear extrapolation of the velocity when the last step had the same
  // dt.
  const int cols = model.nodes();
  {
    const Scalar third = Scalar(1) / Scalar(3), four_thirds = Scalar(4) * third;
    const Scalar *xn = state.position.data(), *vn = state.velocity.data();
    const Scalar *xp = state.previous_position.data(), *vp = state.previous_velocity.data();
    Scalar *x0 = ws.x0.data(), *v0 = ws.v0.data(), *x1 = ws.x1.data(), *v1 = ws.v1.data();
    const auto predict = [&](auto lanes, Eigen::Index j) {
      using P = decltype(lanes);
      const P xnj = P::load(xn + j), vnj = P::load(vn + j);
      if (use_bdf2) {
        const P vpj = P::load(vp + j);
        const P xh = P::all(four_thirds) * xnj - P::all(third) * P::load(xp + j);
        const P vg = P::all(Scalar(2)) * vnj - vpj;
        xh.store(x0 + j);
        (P::all(four_thirds) * vnj - P::all(third) * vpj).store(v0 + j);
        vg.store(v1 + j);
        (xh + P::all(gh) * vg).store(x1 + j);
      } else {
        const P vg = history ? P::all(Scalar(2)) * vnj - P::load(vp + j) : vnj;
        xnj.store(x0 + j);
        vnj.store(v0 + j);
        vg.store(v1 + j);
        (xnj + P::all(gh) * vg).store(x1 + j);
      }
    };
    simd::for_each_pack<Scalar>(0, 3 * Eigen::Index(cols), predict);
  }
  apply_boundary(model, boundary, Scalar(dt), ws.x1, ws.v1);
  // Seabed friction limit from the normal force at the start of the step, for the whole Newton
  // iteration (TetherWorkspace::frozen_friction); reset on every exit.
  struct FrictionGuard {
    TetherWorkspace<Scalar>& w;
    ~FrictionGuard() { w.frozen_friction = false; }
  } friction_guard{ws};
  if (model.parameters().seabed_friction > Scalar(0)) {
    freeze_friction_normals(model, ws, Scalar(env.seabed_depth()), state);
    ws.frozen_friction = true;
  }
  bool converged = false;
  Scalar res(0);
  // Evaluates F at (x, v), writes rhs = −R = γh F − M (v − v̂) on the free nodes and sets `res`
  // to the scaled max-norm max_i |R_i|/a_i.
  const auto evaluate = [&](const Matrix3X<Scalar>& x, const Matrix3X<Scalar>& v, Scalar& r_max,
                            bool with_jacobian) {
    if (with_jacobian)
      compute_forces<true>(model, ws, env, t1, x, v);
    else
      compute_forces<false>(model, ws, env, t1, x, v);
    ++report.force_evaluations;
    // One vectorised pass over the free nodes: rhs = −R, its scaled max-norm and (for the
    // finiteness test below) its sum.
    const auto residual = [&](auto lanes, int i, auto& r_lanes, auto& sum_lanes) {
      using P = decltype(lanes);
      const Scalar *vi = v.data() + 3 * i, *v0 = ws.v0.data() + 3 * i;
      const Scalar *qi = ws.tangent.data() + 3 * i, *fi = ws.force.data() + 3 * i;
      const P d0 = P::gather(vi, 3) - P::gather(v0, 3);
      const P d1 = P::gather(vi + 1, 3) - P::gather(v0 + 1, 3);
      const P d2 = P::gather(vi + 2, 3) - P::gather(v0 + 2, 3);
      const P q0 = P::gather(qi, 3), q1 = P::gather(qi + 1, 3), q2 = P::gather(qi + 2, 3);
      const P a = P::load(&ws.mass_iso(i));
      const P bqd = P::load(&ws.mass_tan(i)) * ((q0 * d0 + q1 * d1) + q2 * d2);
      const P g = P::all(gh);
      const P r0 = g * P::gather(fi, 3) - (a * d0 + bqd * q0);
      const P r1 = g * P::gather(fi + 1, 3) - (a * d1 + bqd * q1);
      const P r2 = g * P::gather(fi + 2, 3) - (a * d2 + bqd * q2);
      Scalar* out = ws.rhs.data() + 3 * i;
      r0.scatter(out, 3);
      r1.scatter(out + 1, 3);
      r2.scatter(out + 2, 3);
      r_lanes = max(r_lanes, max(max(abs(r0), abs(r1)), abs(r2)) * P::load(&ws.mass_iso_inv(i)));
      sum_lanes += (r0 + r1) + r2;
    };
    using Wide = simd::Pack<Scalar, true>;
    using One = simd::Pack<Scalar, false>;
    Wide r_wide = Wide::all(Scalar(0)), sum_wide = Wide::all(Scalar(0));
    One r_one = One::all(Scalar(0)), sum_one = One::all(Scalar(0));
    int i = f0;
    for (; i + Wide::lanes <= f1 + 1; i += Wide::lanes) residual(Wide(), i, r_wide, sum_wide);
    for (; i <= f1; ++i) residual(One(), i, r_one, sum_one);
    r_max = std::max(r_wide.max_lane(), r_one.max_lane());
    const Scalar sum = sum_wide.sum() + sum_one.sum();
    // NaN fails every comparison and std::max keeps its first argument: test the sum instead.
    if (!is_finite(sum))
      ::kelp::detail::throw_numerical_error(
          "step_implicit: non-finite residual; the state is unchanged");
  };
  // Water and free surface: sampled by the first evaluation (at the predictor), then held.
  struct WaterGuard {
    TetherWorkspace<Scalar>& w;
    ~WaterGuard() { w.water_frozen = false; }
  } water_guard{ws};
  ws.water_frozen = false;
  evaluate(ws.x1, ws.v1, res, true);
  ws.water_frozen = !options.resample_water;
  // The trial iterates take the kinematic end nodes from here (the free ones are overwritten).
  for (int i = 0; i < cols; ++i) {
    if (i >= f0 && i <= f1) {
      i = f1;
      continue;
    }
    ws.xs.col(i) = ws.x1.col(i);
    ws.vs.col(i) = ws.v1.col(i);
  }
  for (int it = 0;; ++it) {
    // At least one correction: the predictor alone never makes a step.
    if (it >= 1 && res <= tolerance) {
      converged = true;
      break;
    }
    if (it >= options.max_iterations) break;
    active_set_direction(model, ws, gh, options.slack_band, options.max_active_set_passes);
    ++report.newton_iterations;
    if (!options.check_convergence && it + 1 >= options.max_iterations) {
      // Take the last correction unchecked; extrapolate the end forces with the Jacobian of the
      // end segments: ΔF = (γh K_s + C_s) δv of the neighbouring free node.
      for (int i = f0; i <= f1; ++i) {
        ws.v1.col(i) += ws.delta.col(i);
        ws.x1.col(i) = ws.x0.col(i) + gh * ws.v1.col(i);
      }
      ws.end_forces = end_forces_from_workspace(model, ws, boundary);
      const int n = model.segments();
      if (f0 == 1 && n >= 2)
        ws.end_forces.on_start += segment_block(ws, 0, Scalar(1), gh) * ws.delta.col(1);
      if (f1 == n - 1 && n >= 2)
        ws.end_forces.on_end += segment_block(ws, n - 1, Scalar(1), gh) * ws.delta.col(n - 1);
      commit(state, ws.x1, ws.v1, dt, "step_implicit");
      ws.end_impulse.on_start += Scalar(dt) * ws.end_forces.on_start;
      ws.end_impulse.on_end += Scalar(dt) * ws.end_forces.on_end;
      report.residual = std::max(report.residual, res);
      ++report.substeps;
      return true;
    }
    // Line search. R is the gradient of the step's incremental potential
    // Φ(v) = ½(v − v̂)ᵀM(v − v̂) + U(x̂ + γh v) + γh·(dissipation potential), which is convex for
    // this model up to the tangent dependence of drag and added mass (elastic energy
    // ½EA/l·max(0, l_s − l)² is convex in x). Along x(α) = x + αδ the slope φ'(α) = R(α)·δ is
    // therefore increasing, with φ'(0) = −δᵀJδ < 0. The full Newton step is kept unless it
    // overshoots the minimum along δ (φ'(1) > ½|φ'(0)|, e.g. across the kink of the tension at
    // l_s = l, where plain Newton can cycle between the slack and the taut branch); then secant
    // steps on φ' home in on the minimum. Each trial costs one force evaluation.
    const Eigen::Index nf = f1 - f0 + 1;
    const auto slope = [&]() {
      return Scalar(-ws.rhs.middleCols(f0, nf).cwiseProduct(ws.delta.middleCols(f0, nf)).sum());
    };
    const Scalar g0 = slope();
    const Scalar a_lo(0), g_lo = g0;
    Scalar alpha(1), trial_res(0);
    for (int ls = 0;; ++ls) {
      ws.vs.middleCols(f0, nf).noalias() =
          ws.v1.middleCols(f0, nf) + alpha * ws.delta.middleCols(f0, nf);
      ws.xs.middleCols(f0, nf).noalias() = ws.x0.middleCols(f0, nf) + gh * ws.vs.middleCols(f0, nf);
      // The trial carries its Jacobian terms: when another Newton iteration follows (half the
      // steps of a line near the surface) they are needed at this point, and filling them costs
      // less than a second evaluation there (−6 % instructions per system step).
      evaluate(ws.xs, ws.vs, trial_res, true);
      if (ls >= options.max_backtracks || !(g0 < Scalar(0))) break;
      const Scalar g = slope();
      if (g <= Scalar(-0.5) * g0) break;
      // Secant on φ' between (a_lo, g_lo < 0) and (alpha, g > 0).
      const Scalar a_new = a_lo + (alpha - a_lo) * (-g_lo) / (g - g_lo);
      if (!(a_new > a_lo && a_new < alpha)) break;
      alpha = a_new;
    }
    ws.x1.swap(ws.xs);
    ws.v1.swap(ws.vs);
    res = trial_res;
  }
  if (!converged) {
    report.rejected_residual = std::max(report.rejected_residual, res);
    return false;
  }
  ws.end_forces = end_forces_from_workspace(model, ws, boundary);
  // commit() turns the pre-step state into the history.
  commit(state, ws.x1, ws.v1, dt, "step_implicit");
  ws.end_impulse.on_start += Scalar(dt) * ws.end_forces.on_start;
  ws.end_impulse.on_end += Scalar(dt) * ws.end_forces.on_end;
  report.residual = std::max(report.residual, res);
  ++report.substeps;
  return true;
}

/// implicit_attempt, with a non-finite iterate (numerical_error) counted as not converged: a
/// shorter step may well succeed. Nothing is committed when it returns false.
template <typename Scalar, typename Env>
bool try_implicit(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws, const Env& env,
                  TetherState<Scalar>& state, const TetherBoundary<Scalar>& boundary, double dt,
                  bool bdf2, const ImplicitOptions<Scalar>& options, StepReport<Scalar>& report) {
  try {
    return implicit_attempt(model, ws, env, state, boundary, dt, bdf2, options, report);
  } catch (const kelp::numerical_error&) {
    report.rejected_residual = std::numeric_limits<Scalar>::infinity();
    return false;
  }
}

/// Step of length dt split into two halves, each retried in halves again up to `depth_left`
/// more times; the boundary motion is the step's, taken τ into it. True when all were committed.
template <typename Scalar, typename Env>
bool implicit_halves(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws, const Env& env,
                     TetherState<Scalar>& state, const TetherBoundary<Scalar>& boundary, double tau,
                     double dt, bool bdf2, const ImplicitOptions<Scalar>& options, int depth_left,
                     StepReport<Scalar>& report) {
  const double half = 0.5 * dt;
  for (int k = 0; k < 2; ++k) {
    const double t_k = tau + k * half;
    const TetherBoundary<Scalar> b = boundary.after(Scalar(t_k));
    if (try_implicit(model, ws, env, state, b, half, bdf2, options, report)) continue;
    if (depth_left <= 0) return false;
    ++report.retries;
    if (!implicit_halves(model, ws, env, state, boundary, t_k, half, bdf2, options, depth_left - 1,
                         report))
      return false;
  }
  return true;
}

}  // namespace detail

/// \brief One implicit step (backward Euler, or BDF2 when `bdf2` is true and the state's previous
/// step had the same dt) solved by Newton's method.
///
/// With x = x̂ + γh v (backward Euler: γ = 1, x̂ = x_n, v̂ = v_n; BDF2: γ = 2/3,
/// x̂ = (4x_n − x_{n−1})/3, v̂ = (4v_n − v_{n−1})/3) the unknown node velocities solve
/// R(v) = M (v − v̂) − γh F(x̂ + γh v, v) = 0. The Jacobian J = M + γh D_v + (γh)² D_x
/// (D_v = −∂F/∂v: internal damping exactly, drag linearised, seabed damping and friction;
/// D_x = −∂F/∂x: axial plus geometric stiffness exactly, seabed stiffness; M, with its added
/// mass, at the current iterate) is block tridiagonal, symmetric positive definite, and solved
/// in O(N) by block-Thomas elimination (no dense N×N). Left out of J, so converging linearly
/// rather than quadratically when they dominate: the tangent dependence of drag and added mass,
/// the added-mass rate terms, the direction dependence of the dashpot, bending (EI). Each Newton
/// direction settles which segments are taut, slack or clamped with a primal–dual active set
/// (detail::active_set_direction) and is shortened by a secant line search on the slope R·δ
/// when it overshoots. The initial guess extrapolates the velocity (2v_n − v_{n−1}) when the
/// previous step had the same dt. At least one and up to `options.max_iterations` corrections,
/// until max_i |R_i|/a_i ≤ acceleration_tolerance · dt. A step that does not converge is not
/// committed: it is retried as two half steps, each halved again if needed, at most
/// `options.max_step_halvings` times (BDF2 restarts with backward Euler after a change of step);
/// if even that fails, kelp::numerical_error is thrown with the state unchanged. End forces
/// (`ws.end_forces`) are those of the final iterate, at t + dt.
/// \returns the work done (sub-steps, Newton iterations, worst residual, retries).
/// \throws kelp::invalid_argument for bad input; kelp::numerical_error (state unchanged) when
/// the result is not finite or Newton's method does not converge.
template <typename Scalar, typename Env>
StepReport<Scalar> step_implicit(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                                 const Env& env, TetherState<Scalar>& state,
                                 const TetherBoundary<Scalar>& boundary, double dt,
                                 bool bdf2 = false, const ImplicitOptions<Scalar>& options = {}) {
  detail::check_step_inputs(model, ws, state, boundary, dt);
  detail::check_implicit_options(options);
  detail::check_resolvable(model, state, options);
  ws.end_impulse = EndForces<Scalar>{};
  StepReport<Scalar> report;
  if (detail::try_implicit(model, ws, env, state, boundary, dt, bdf2, options, report))
    return report;
  // Not converged, nothing committed: retry in halves from a backup.
  ws.retry_backup.save(state);
  bool done = false;
  if (options.max_step_halvings > 0) {
    ++report.retries;
    done = detail::implicit_halves(model, ws, env, state, boundary, 0.0, dt, bdf2, options,
                                   options.max_step_halvings - 1, report);
  }
  if (!done) {
    ws.retry_backup.restore(state);
    ::kelp::detail::throw_numerical_error(
        "step_implicit: Newton's method did not converge at dt = " + detail::format_g(dt) +
        " s, nor in sub-steps down to dt/2^" + std::to_string(options.max_step_halvings) +
        " (worst residual " + detail::format_g(double(value_of(report.rejected_residual))) +
        " m/s); the state is unchanged");
  }
  return report;
}

/// \brief One step of length `dt` [s] with the chosen integrator (dispatch).
/// \throws as the individual steps; kelp::invalid_argument for an Integrator value outside the
/// enumeration.
template <typename Scalar, typename Env>
StepReport<Scalar> step(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                        const Env& env, TetherState<Scalar>& state,
                        const TetherBoundary<Scalar>& boundary, double dt, Integrator integrator,
                        const ImplicitOptions<Scalar>& options = {}) {
  switch (integrator) {
    case Integrator::symplectic_euler:
      return step_symplectic_euler(model, ws, env, state, boundary, dt);
    case Integrator::rk2:
      return step_rk2(model, ws, env, state, boundary, dt);
    case Integrator::rk4:
      return step_rk4(model, ws, env, state, boundary, dt);
    case Integrator::implicit_euler:
      return step_implicit(model, ws, env, state, boundary, dt, false, options);
    case Integrator::bdf2:
      return step_implicit(model, ws, env, state, boundary, dt, true, options);
  }
  ::kelp::detail::throw_invalid_argument("integrator is not a kelp::tether::Integrator value");
}

namespace detail {

/// Number of segment springs on node i of a line of n segments (1 at an end, else 2).
inline int node_springs(int i, int n) { return (i > 0 ? 1 : 0) + (i < n ? 1 : 0); }

/// Water densities from 0 (air, vacuum) to the environment's `limits::max_fluid_density` (1e5
/// kg/m³, seven times mercury's); NaN and Inf refused.
template <typename Scalar>
void check_water_density(const Scalar& rho) {
  check_non_negative(rho, "water_density");
  check_at_most(rho, ::kelp::environment::limits::max_fluid_density, "water_density");
}

/// Axial mass of node i [kg]: structural plus tangential added mass, the node taken as
/// submerged in water of density ρ [kg/m³].
template <typename Scalar>
Scalar axial_node_mass(const TetherModel<Scalar>& model, int i, Scalar water_density) {
  return model.node_mass(i) +
         water_density * model.node_volume(i) * model.parameters().tangential_added_mass;
}

}  // namespace detail

/// \brief Largest angular frequency of the line [rad/s], bounded by Gershgorin's theorem.
/// Axial chain: ω²_a ≤ max_i Σ_j |K_ij| / m_i = max_i 2 k_i / m_i, with k_i the sum of the segment
/// spring constants EA/l on free node i and m_i its axial mass (structural plus tangential added
/// mass, nodes taken as submerged). Bending (EI > 0): the discrete bending stiffness is
/// (EI/l³)·DᵀD with D the second difference (‖DᵀD‖ ≤ 16), so ω²_b ≤ 16 EI/(l³ m_n) with m_n the
/// normal (added-mass) node mass. Returns √(ω²_a + ω²_b).
/// \throws kelp::invalid_argument for a water density ρ outside [0, 1e5] kg/m³ or NaN.
template <typename Scalar>
Scalar highest_axial_frequency(const TetherModel<Scalar>& model, Scalar water_density) {
  using std::sqrt;
  detail::check_water_density(water_density);
  const int n = model.segments();
  const TetherParameters<Scalar>& p = model.parameters();
  const Scalar l = model.segment_length();
  Scalar w2(0);
  for (int i = model.first_free_node(); i <= model.last_free_node(); ++i) {
    const int springs = detail::node_springs(i, n);
    const Scalar rv = water_density * model.node_volume(i);
    const Scalar m = detail::axial_node_mass(model, i, water_density);
    Scalar wi = Scalar(2) * Scalar(springs) * model.axial_spring() / m;
    if (p.bending_stiffness > Scalar(0))
      wi += Scalar(16) * p.bending_stiffness /
            (l * l * l * (model.node_mass(i) + rv * p.normal_added_mass));
    w2 = std::max(w2, wi);
  }
  return sqrt(w2);
}

/// \brief Estimated largest stable explicit time step [s]: `safety` × h_max with
/// h_max ω_max = 2 (symplectic Euler), 1 (RK2, which is only stabilised by damping on the
/// imaginary axis; MoorDyn's CFL rule), 2√2 (RK4), reduced for internal damping by the
/// central-difference factor √(1 + ζ²) − ζ (ζ = c/(2 m ω_max), c = 2·(springs)·BA/l the
/// Gershgorin bound of the node's dashpots; Bathe, Finite Element Procedures, §9.4), which keeps
/// a heavily damped segment inside the negative-real-axis limit. Drag and seabed damping are
/// not included. Implicit schemes: +infinity (unconditionally stable for the linearised line;
/// choose dt for accuracy, e.g. 10 ms).
/// \param[in] water_density ρ [kg/m³] for the added mass (0: in air).
/// \param[in] safety factor in (0, 1] on the stability limit.
/// \throws kelp::invalid_argument for ρ outside [0, 1e5] kg/m³ or NaN, a safety factor outside
/// (0, 1], or an Integrator value outside the enumeration.
template <typename Scalar>
Scalar estimate_stable_dt(const TetherModel<Scalar>& model, Integrator integrator,
                          Scalar water_density = Scalar(kelp::seawater_density),
                          Scalar safety = Scalar(0.8)) {
  using std::sqrt;
  check_positive(safety, "safety");
  check_at_most(safety, 1.0, "safety");
  detail::check_water_density(water_density);
  KELP_CHECK(is_valid(integrator), "integrator is not a kelp::tether::Integrator value");
  if (is_implicit(integrator)) return std::numeric_limits<Scalar>::infinity();
  const Scalar w = highest_axial_frequency(model, water_density);
  if (!(w > Scalar(0))) return std::numeric_limits<Scalar>::infinity();
  Scalar limit(2);
  if (integrator == Integrator::rk2) limit = Scalar(1);
  if (integrator == Integrator::rk4) limit = Scalar(2.8284271247461903);
  // Largest damping ratio over the free nodes.
  Scalar zeta(0);
  const int n = model.segments();
  for (int i = model.first_free_node(); i <= model.last_free_node(); ++i) {
    const int springs = detail::node_springs(i, n);
    const Scalar m = detail::axial_node_mass(model, i, water_density);
    zeta = std::max(zeta, Scalar(2) * Scalar(springs) * model.axial_damper() / (Scalar(2) * m * w));
  }
  return safety * limit / w * (sqrt(Scalar(1) + zeta * zeta) - zeta);
}

/// \brief Sub-stepping driver: advances `state` by `duration` [s] in n = ⌈duration/max_dt⌉ equal
/// steps of the chosen integrator; the kinematic ends follow `boundary` (given at the current
/// time) through the interval. `ws.end_forces` holds the forces of the last sub-step,
/// `ws.end_impulse` the impulse on the ends summed over all of them. If any
/// sub-step fails (after its own retries, for the implicit schemes) or throws for any other reason
/// the state is restored to its value at entry, history included, and the error rethrown. No heap
/// allocation. \returns the sum of the sub-steps' reports (committed steps, Newton iterations,
/// worst residual, retries).
template <typename Scalar, typename Env>
StepReport<Scalar> advance(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                           const Env& env, TetherState<Scalar>& state,
                           const TetherBoundary<Scalar>& boundary, double duration, double max_dt,
                           Integrator integrator, const ImplicitOptions<Scalar>& options = {}) {
  check_positive(duration, "duration");
  check_positive(max_dt, "max_dt");
  const double ratio = std::ceil(duration / max_dt);
  KELP_CHECK(ratio <= double(std::numeric_limits<int>::max()),
             "max_dt too small for duration: more than INT_MAX sub-steps");
  const int n = std::max(1, static_cast<int>(ratio));
  const double h = duration / n;
  ws.entry_backup.save(state);
  StepReport<Scalar> report;
  EndForces<Scalar> impulse;
  try {
    for (int k = 0; k < n; ++k) {
      report += step(model, ws, env, state, boundary.after(Scalar(k * h)), h, integrator, options);
      impulse.on_start += ws.end_impulse.on_start;
      impulse.on_end += ws.end_impulse.on_end;
    }
  } catch (...) {
    ws.entry_backup.restore(state);
    throw;
  }
  ws.end_impulse = impulse;
  return report;
}

/// \brief Settings of the static-equilibrium solve.
template <typename Scalar>
struct StaticOptions {
  /// Converged when max_i |F_i| ≤ this [N]; ≤ 0 selects 1e-7 × the line's weight in air.
  Scalar force_tolerance = Scalar(0);
  /// Maximum pseudo steps (each one implicit step solved by Newton). A line that settles in a few
  /// dozen takes a few dozen; a buoyant line floating at the surface, whose nodes land there one
  /// by one, can take several hundred (a 15 m ROV tether: ~650).
  int max_iterations = 1000;
  /// First pseudo time step h [s] of the regularisation M/h² (grows as the residual falls).
  Scalar initial_pseudo_dt = Scalar(0.05);
};

/// \brief Outcome of the static-equilibrium solve.
template <typename Scalar>
struct StaticResult {
  bool converged = false;       ///< residual below tolerance
  int iterations = 0;           ///< Newton iterations used
  Scalar residual = Scalar(0);  ///< final max_i |F_i| over free nodes [N]
};

/// \brief Static equilibrium F(x) = 0 of the free nodes (velocities zero, ends held at the
/// boundary positions) by pseudo-transient continuation: repeated backward-Euler steps (each
/// solved by Newton with the analytic block-tridiagonal Jacobian) with the velocities reset to
/// zero after every step, so that each step solves (M/h² + D_x + D_v/h) Δx = F(x + Δx) — the
/// mass term regularises slack and contact nonlinearities while h is small, and the iteration
/// becomes Newton's method on F(x) = 0 as h grows (doubling after every easy step, quartered and
/// retried after a step whose Newton solve did not converge). Drag from a current enters F.
/// Starts from `state` (e.g. the catenary); `state` ends at the last iterate with zero velocity
/// and unchanged time; `ws.end_forces` holds the static end forces.
/// \throws kelp::invalid_argument for bad input (a workspace not built for the model, a state or
/// boundary that does not fit or is not finite, StaticOptions with a NaN or infinite
/// force_tolerance, an initial_pseudo_dt not finite and > 0, max_iterations < 1), before the
/// state is touched; kelp::numerical_error if the iteration produces non-finite values (state
/// unchanged).
template <typename Scalar, typename Env>
[[nodiscard]] StaticResult<Scalar> solve_static_equilibrium(
    const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws, const Env& env,
    TetherState<Scalar>& state, const TetherBoundary<Scalar>& boundary,
    const StaticOptions<Scalar>& options = {}) {
  // Every check before the state is touched.
  detail::check_workspace(model, ws);
  check_state(model, state);
  check_boundary(boundary);
  check_finite(options.force_tolerance, "StaticOptions::force_tolerance");
  check_positive(options.initial_pseudo_dt, "StaticOptions::initial_pseudo_dt");
  KELP_CHECK(options.max_iterations >= 1, "StaticOptions::max_iterations must be >= 1");
  const int f0 = model.first_free_node(), f1 = model.last_free_node();
  Scalar tol = options.force_tolerance;
  if (!(tol > Scalar(0)))
    tol = Scalar(1e-7) * model.parameters().mass_per_length * model.parameters().length *
          Scalar(env.gravity());
  ImplicitOptions<Scalar> inner;
  inner.max_iterations = 6;
  const Scalar m_ref = model.node_mass(model.segments() / 2);
  // The inner residual is max_i h·|F_i|/a_i [m/s], a_i the node's isotropic mass (structural
  // plus added mass), not m_ref: this tolerance asks for |F_i| ≤ ½·tol·a_i/m_ref, half the
  // force tolerance for an interior node in air, looser where added mass or a point mass
  // makes a_i > m_ref (the outer loop checks |F_i| ≤ tol itself).
  // (acceleration_tolerance · h is the inner velocity tolerance.)
  inner.acceleration_tolerance = Scalar(0.5) * tol / m_ref;
  detail::check_implicit_options(inner);
  TetherBoundary<Scalar> b = boundary;
  b.start.velocity.setZero();
  b.end.velocity.setZero();
  b.start.acceleration.setZero();
  b.end.acceleration.setZero();
  // Keep the entry state (no single step uses that backup) and iterate on `state` itself,
  // restoring it on error.
  ws.entry_backup.save(state);
  const double t_entry = state.time, carry_entry = state.time_carry;
  state.velocity.setZero();
  state.clear_history();
  detail::apply_boundary(model, b, Scalar(0), state.position, state.velocity);
  StaticResult<Scalar> result;
  Scalar h = options.initial_pseudo_dt;
  const Scalar h_max(1e6);
  try {
    for (int it = 0;; ++it) {
      compute_forces<false>(model, ws, env, t_entry, state.position, state.velocity);
      Scalar res(0);
      for (int i = f0; i <= f1; ++i) res = std::max(res, ws.force.col(i).cwiseAbs().maxCoeff());
      if (!(res == res))
        ::kelp::detail::throw_numerical_error("solve_static_equilibrium: non-finite force");
      result.residual = res;
      result.iterations = it;
      if (res <= tol) {
        result.converged = true;
        break;
      }
      if (it >= options.max_iterations) break;
      StepReport<Scalar> r;
      // A pseudo step that does not converge is not committed: retry it shorter.
      const bool taken =
          detail::try_implicit(model, ws, env, state, b, double(value_of(h)), false, inner, r);
      state.time = t_entry;
      state.time_carry = carry_entry;
      state.velocity.setZero();
      state.clear_history();
      if (!taken) {
        if (!(h > options.initial_pseudo_dt * Scalar(1e-6)))
          ::kelp::detail::throw_numerical_error(
              "solve_static_equilibrium: no pseudo step converges; the state is unchanged");
        h *= Scalar(0.25);
      } else if (r.newton_iterations <= 5) {  // an easy step: lengthen the next
        h = std::min(h_max, h * Scalar(2));
      }
    }
  } catch (...) {
    ws.entry_backup.restore(state);
    throw;
  }
  ws.end_forces = end_forces_from_workspace(model, ws, b);
  return result;
}

using StepReportd = StepReport<double>;            ///< StepReport<double>
using StepReportf = StepReport<float>;             ///< StepReport<float>
using ImplicitOptionsd = ImplicitOptions<double>;  ///< ImplicitOptions<double>
using ImplicitOptionsf = ImplicitOptions<float>;   ///< ImplicitOptions<float>
using StaticOptionsd = StaticOptions<double>;      ///< StaticOptions<double>
using StaticOptionsf = StaticOptions<float>;       ///< StaticOptions<float>
using StaticResultd = StaticResult<double>;        ///< StaticResult<double>
using StaticResultf = StaticResult<float>;         ///< StaticResult<float>

}  // namespace kelp::tether
