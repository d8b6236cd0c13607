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
/// state only when it is finite: a failed step throws `kelp::numerical_error` and leaves the state
/// as it was.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
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

/// \brief True for the Newton-solved schemes.
inline bool is_implicit(Integrator i) {
  return i == Integrator::implicit_euler || i == Integrator::bdf2;
}

/// \brief Newton settings of the implicit schemes.
template <typename Scalar>
struct ImplicitOptions {
  /// Maximum Newton corrections per step (each: one Jacobian factorisation and solve).
  int max_iterations = 8;
  /// Convergence when max_i |R_i| / a_i ≤ this [m/s], R_i the momentum residual of node i and
  /// a_i its isotropic mass (an error ΔF in the node force shows up as γh ΔF / a_i). Default
  /// 1.5e-6 m/s in double; 1e-3 m/s in single precision, whose rounding of ~10 m coordinates
  /// already costs EA/l · 6e-7 m of tension (use a softer line or double for stiff tethers).
  Scalar velocity_tolerance =
      Scalar(std::numeric_limits<Scalar>::epsilon() > Scalar(1e-10) ? 1e-3 : 1.5e-6);
  /// Segments at least (1 − band)·l long start each Newton iteration's active set in the taut
  /// branch (see detail::active_set_direction); 0 starts from the stretched segments.
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
};

/// \brief What one step did.
template <typename Scalar>
struct StepReport {
  /// Force evaluations used.
  int force_evaluations = 0;
  /// Newton corrections (0 for explicit schemes).
  int newton_iterations = 0;
  /// Final scaled Newton residual max_i |R_i|/a_i [m/s] (0 for explicit schemes).
  Scalar residual = Scalar(0);
  /// False when an implicit step hit `max_iterations` before meeting the tolerance (the step is
  /// still taken).
  bool converged = true;
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

/// Solves J δ = rhs over the free nodes, J = c_m M + c_v (−∂F/∂v) + c_x (−∂F/∂x), block
/// tridiagonal and symmetric positive definite, by block-Thomas elimination (block LDLᵀ). The
/// off-diagonal block of segment s is −A_s with A_s = α_s u uᵀ + β_s I (α = c_v BA/l + c_x k_uu,
/// β = c_x k_perp), so the Schur complements D'_i = D_i − A_{i−1} D'⁻¹_{i−1} A_{i−1} and the
/// back substitution δ_i = z_i + D'⁻¹_i A_i δ_{i+1} are written with symmetric 3×3 algebra
/// (6 stored entries, closed-form SPD inverse). Reads the Jacobian ingredients of the last
/// compute_forces<true>; writes ws.delta (and ws.block_inv). O(N), no heap allocation.
template <typename Scalar>
void solve_block_tridiagonal(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                             Scalar c_m, Scalar c_v, Scalar c_x) {
  using S = Scalar;
  const int n = model.segments();
  const int f0 = model.first_free_node(), f1 = model.last_free_node();
  // Segment coupling A_s = al u uᵀ + be I.
  const auto seg = [&](int s, S& al, S& be, S& ux, S& uy, S& uz) {
    al = c_v * ws.seg_c_uu(s) + c_x * ws.seg_k_uu(s);
    be = c_x * ws.seg_k_perp(s);
    ux = ws.direction(0, s);
    uy = ws.direction(1, s);
    uz = ws.direction(2, s);
  };
  // Previous node's inverse (symmetric: 00 10 20 11 21 22) and segment i−1.
  S p00(0), p10(0), p20(0), p11(0), p21(0), p22(0);
  S al_p(0), be_p(0), ux_p(0), uy_p(0), uz_p(0);
  if (f0 > 0) seg(f0 - 1, al_p, be_p, ux_p, uy_p, uz_p);
  for (int i = f0; i <= f1; ++i) {
    // D = c_m (a I + b q qᵀ) + c_v D_v + c_x kz e_z e_zᵀ.
    const S a = c_m * ws.mass_iso(i), bq = c_m * ws.mass_tan(i);
    const S qx = ws.tangent(0, i), qy = ws.tangent(1, i), qz = ws.tangent(2, i);
    const auto dv = ws.node_dv.col(i);
    S d00 = a + bq * qx * qx + c_v * dv(0);
    S d10 = bq * qy * qx + c_v * dv(1);
    S d20 = bq * qz * qx + c_v * dv(2);
    S d11 = a + bq * qy * qy + c_v * dv(3);
    S d21 = bq * qz * qy + c_v * dv(4);
    S d22 = a + bq * qz * qz + c_v * dv(5) + c_x * ws.node_kz(i);
    S r0 = ws.rhs(0, i), r1 = ws.rhs(1, i), r2 = ws.rhs(2, i);
    // + A_{i−1} − A_{i−1} P A_{i−1} with P = D'⁻¹_{i−1} (zero, as are α, β and u before the
    // first segment, when node i − 1 is not eliminated): with w = P u, σ = u·w,
    // A − A P A = u yᵀ + y uᵀ + β I − β² P, y = ½(α − α² σ) u − αβ w.
    {
      const S wx = p00 * ux_p + p10 * uy_p + p20 * uz_p;
      const S wy = p10 * ux_p + p11 * uy_p + p21 * uz_p;
      const S wz = p20 * ux_p + p21 * uy_p + p22 * uz_p;
      const S sig = ux_p * wx + uy_p * wy + uz_p * wz;
      const S cu = S(0.5) * al_p * (S(1) - al_p * sig), ab = al_p * be_p, bb = be_p * be_p;
      const S yx = cu * ux_p - ab * wx, yy = cu * uy_p - ab * wy, yz = cu * uz_p - ab * wz;
      d00 += S(2) * ux_p * yx + (be_p - bb * p00);
      d10 += uy_p * yx + yy * ux_p - bb * p10;
      d20 += uz_p * yx + yz * ux_p - bb * p20;
      d11 += S(2) * uy_p * yy + (be_p - bb * p11);
      d21 += uz_p * yy + yz * uy_p - bb * p21;
      d22 += S(2) * uz_p * yz + (be_p - bb * p22);
    }
    if (i > f0) {
      // r += A z_{i−1}
      const S z0 = ws.delta(0, i - 1), z1 = ws.delta(1, i - 1), z2 = ws.delta(2, i - 1);
      const S uz_dot = al_p * (ux_p * z0 + uy_p * z1 + uz_p * z2);
      r0 += uz_dot * ux_p + be_p * z0;
      r1 += uz_dot * uy_p + be_p * z1;
      r2 += uz_dot * uz_p + be_p * z2;
    }
    S al(0), be(0), ux(0), uy(0), uz(0);
    if (i < n) {
      seg(i, al, be, ux, uy, uz);
      d00 += al * ux * ux + be;
      d10 += al * uy * ux;
      d20 += al * uz * ux;
      d11 += al * uy * uy + be;
      d21 += al * uz * uy;
      d22 += al * uz * uz + be;
    }
    // Closed-form inverse of the SPD block (Sylvester's criterion checked).
    const S c00 = d11 * d22 - d21 * d21, c01 = d20 * d21 - d10 * d22, c02 = d10 * d21 - d20 * d11;
    const S minor2 = d00 * d11 - d10 * d10;
    const S det = d00 * c00 + d10 * c01 + d20 * c02;
    if (!(d00 > S(0) && minor2 > S(0) && det > S(0)))
      ::kelp::detail::throw_numerical_error(
          "tether Newton step: Jacobian block not positive definite; the state is unchanged");
    const S k = S(1) / det;
    p00 = c00 * k;
    p10 = c01 * k;
    p20 = c02 * k;
    p11 = (d00 * d22 - d20 * d20) * k;
    p21 = (d10 * d20 - d00 * d21) * k;
    p22 = minor2 * k;
    ws.delta(0, i) = p00 * r0 + p10 * r1 + p20 * r2;
    ws.delta(1, i) = p10 * r0 + p11 * r1 + p21 * r2;
    ws.delta(2, i) = p20 * r0 + p21 * r1 + p22 * r2;
    auto inv = ws.block_inv.col(i);
    inv(0) = p00;
    inv(1) = p10;
    inv(2) = p20;
    inv(3) = p11;
    inv(4) = p21;
    inv(5) = p22;
    al_p = al;
    be_p = be;
    ux_p = ux;
    uy_p = uy;
    uz_p = uz;
  }
  // Back substitution: δ_i += P_i A_i δ_{i+1}.
  for (int i = f1 - 1; i >= f0; --i) {
    S al, be, ux, uy, uz;
    seg(i, al, be, ux, uy, uz);
    const S y0 = ws.delta(0, i + 1), y1 = ws.delta(1, i + 1), y2 = ws.delta(2, i + 1);
    const S ud = al * (ux * y0 + uy * y1 + uz * y2);
    const S t0 = ud * ux + be * y0, t1 = ud * uy + be * y1, t2 = ud * uz + be * y2;
    const auto p = ws.block_inv.col(i);
    ws.delta(0, i) += p(0) * t0 + p(1) * t1 + p(2) * t2;
    ws.delta(1, i) += p(1) * t0 + p(3) * t1 + p(4) * t2;
    ws.delta(2, i) += p(2) * t0 + p(4) * t1 + p(5) * t2;
  }
}

/// Newton direction with a primal–dual active set for the kink of the elastic tension at
/// l_s = l (semismooth Newton on T_el = EA·max(0, ε)): in the linear model each segment's elastic
/// part is either on — T_el ≈ EA ε + (EA/l) u·Δδx, negative values allowed inside the linear
/// model — or off. The set starts from the segments with l_s ≥ (1 − band)·l, and is updated from
/// the predicted lengths until it repeats (at most `max_passes` solves). Reads ws.rhs (= −R) and
/// the Jacobian terms of compute_forces<true>; writes ws.delta; ws.rhs is restored.
template <typename Scalar>
void active_set_direction(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws, Scalar gh,
                          Scalar band, int max_passes) {
  const int n = model.segments();
  const int f0 = model.first_free_node(), f1 = model.last_free_node();
  const Scalar l = model.segment_length(), inv_l = model.inverse_segment_length();
  const Scalar ea = model.parameters().axial_stiffness, ea_l = model.axial_spring();
  // Updates the active set from the lengths predicted by ws.delta; true if it changed.
  const auto update = [&]() {
    bool changed = false;
    for (int s = 0; s < n; ++s) {
      Scalar dl(0);
      const auto u = ws.direction.col(s);
      if (s >= f0 && s <= f1) dl -= gh * u.dot(ws.delta.col(s));
      if (s + 1 >= f0 && s + 1 <= f1) dl += gh * u.dot(ws.delta.col(s + 1));
      const bool now = ws.stretched_length(s) + dl > l;
      if (now != (ws.seg_active(s) > Scalar(0))) {
        changed = true;
        ws.seg_active(s) = now ? Scalar(1) : Scalar(0);
      }
    }
    return changed;
  };
  bool on_true_branch = true;
  for (int s = 0; s < n; ++s) {
    const bool active = ws.stretched_length(s) >= (Scalar(1) - band) * l;
    ws.seg_active(s) = active ? Scalar(1) : Scalar(0);
    if (active != (ws.stretched_length(s) > l)) on_true_branch = false;
  }
  int pass = 0;
  if (on_true_branch) {
    // Common case: plain Newton; done unless the predicted lengths cross l.
    solve_block_tridiagonal(model, ws, Scalar(1), gh, gh * gh);
    if (max_passes <= 1 || !update()) return;
    pass = 1;
  }
  ws.rhs_true = ws.rhs;
  ws.seg_true_k_uu = ws.seg_k_uu;
  for (;; ++pass) {
    ws.rhs = ws.rhs_true;
    for (int s = 0; s < n; ++s) {
      const bool stretched = ws.stretched_length(s) > l;
      const bool active = ws.seg_active(s) > Scalar(0);
      ws.seg_k_uu(s) = ws.seg_true_k_uu(s);
      if (active == stretched) continue;
      const auto u = ws.direction.col(s);
      // Elastic force of the taut branch at the current point (negative when slack).
      const Scalar te = ea * (ws.stretched_length(s) - l) * inv_l;
      if (active) {  // slack, modelled taut: add the (compressive) branch value and stiffness
        ws.rhs.col(s) += (gh * te) * u;
        ws.rhs.col(s + 1) -= (gh * te) * u;
        ws.seg_k_uu(s) += ea_l;
      } else {  // stretched, modelled slack: remove its elastic force and stiffness
        ws.rhs.col(s) -= (gh * te) * u;
        ws.rhs.col(s + 1) += (gh * te) * u;
        ws.seg_k_uu(s) -= ea_l;
      }
    }
    solve_block_tridiagonal(model, ws, Scalar(1), gh, gh * gh);
    if (pass + 1 >= max_passes || !update()) break;
  }
  ws.seg_k_uu = ws.seg_true_k_uu;
  ws.rhs.swap(ws.rhs_true);
}

template <typename Scalar>
bool all_finite_fast(const Matrix3X<Scalar>& x, const Matrix3X<Scalar>& v) {
  using std::isfinite;
  return isfinite(value_of(x.sum() + v.sum()));
}

/// Commits (x, v) as the state at t + dt if finite; keeps the state before the step in
/// ws.x_prev / ws.v_prev (BDF2 history, and the undo point of solve_static_equilibrium) with its
/// step and the time of the committed state, so that a later step can tell whether the history
/// belongs to the state it is given (see history_matches).
template <typename Scalar>
void commit(TetherWorkspace<Scalar>& ws, TetherState<Scalar>& state, const Matrix3X<Scalar>& x,
            const Matrix3X<Scalar>& v, Scalar dt, const char* who) {
  if (!all_finite_fast(x, v))
    ::kelp::detail::throw_numerical_error(std::string(who) +
                                          ": non-finite node state; the state is unchanged");
  ws.x_prev = state.position;
  ws.v_prev = state.velocity;
  ws.previous_dt = dt;
  ws.has_previous = true;
  state.position = x;
  state.velocity = v;
  state.time += dt;
  ws.history_time = state.time;
}

/// True when the workspace's history (x_prev, v_prev) is the step just before `state` with the
/// same step `dt`: it was committed by the last step and the state's time is still the time of
/// that commit (a state reset, or a workspace shared between states, fails the test).
template <typename Scalar>
bool history_matches(const TetherWorkspace<Scalar>& ws, const TetherState<Scalar>& state,
                     Scalar dt) {
  return ws.has_previous && ws.previous_dt == dt && state.time == ws.history_time;
}

/// Checks the Newton settings. \throws kelp::invalid_argument naming the field.
template <typename Scalar>
void check_implicit_options(const ImplicitOptions<Scalar>& o) {
  KELP_CHECK(o.max_iterations >= 1, "ImplicitOptions::max_iterations must be >= 1");
  check_positive(o.velocity_tolerance, "ImplicitOptions::velocity_tolerance");
  check_non_negative(o.slack_band, "ImplicitOptions::slack_band");
  KELP_CHECK(o.max_active_set_passes >= 1, "ImplicitOptions::max_active_set_passes must be >= 1");
  KELP_CHECK(o.max_backtracks >= 0, "ImplicitOptions::max_backtracks must be >= 0");
}

template <typename Scalar>
void check_step_inputs(const TetherModel<Scalar>& model, const TetherWorkspace<Scalar>& ws,
                       const TetherState<Scalar>& state, const TetherBoundary<Scalar>& b,
                       Scalar dt) {
  check_positive(dt, "dt");
  KELP_CHECK(ws.force.cols() == model.nodes(), "workspace was built for a different tether");
  KELP_CHECK(state.position.cols() == model.nodes() && state.velocity.cols() == model.nodes(),
             "state.position and state.velocity must have segments + 1 columns");
  // One pass over the state; the named check runs only to build the message.
  if (!(all_finite_fast(state.position, state.velocity) && is_finite(state.time)))
    check_state(model, state);
  check_boundary(b);
}

/// Acceleration of every node at (x, v) [boundary already applied] into `acc`.
template <typename Scalar, typename Env>
void derivative(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws, const Env& env,
                Scalar t, const TetherBoundary<Scalar>& b, const Matrix3X<Scalar>& x,
                const Matrix3X<Scalar>& v, Matrix3X<Scalar>& acc) {
  compute_forces<false>(model, ws, env, t, x, v);
  accelerations_from_forces(model, ws, b.start.acceleration, b.end.acceleration, acc);
}

/// Shared start of the explicit steps: checks the inputs and copies the state into x0, v0 with
/// the prescribed end motion at the start of the step applied.
template <typename Scalar>
void begin_explicit_step(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                         const TetherState<Scalar>& state, const TetherBoundary<Scalar>& boundary,
                         Scalar dt) {
  check_step_inputs(model, ws, state, boundary, dt);
  ws.x0 = state.position;
  ws.v0 = state.velocity;
  apply_boundary(model, boundary, Scalar(0), ws.x0, ws.v0);
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
                                         const TetherBoundary<Scalar>& boundary, Scalar dt) {
  detail::begin_explicit_step(model, ws, state, boundary, dt);
  const Scalar t = state.time;
  detail::derivative(model, ws, env, t, boundary, ws.x0, ws.v0, ws.acceleration);
  ws.end_forces = end_forces_from_workspace(model, ws, boundary);
  ws.v1.noalias() = ws.v0 + dt * ws.acceleration;
  ws.x1.noalias() = ws.x0 + dt * ws.v1;
  detail::apply_boundary(model, boundary, dt, ws.x1, ws.v1);
  detail::commit(ws, state, ws.x1, ws.v1, dt, "step_symplectic_euler");
  StepReport<Scalar> r;
  r.force_evaluations = 1;
  return r;
}

/// \brief One explicit-midpoint (RK2) step of length `dt` [s]. End forces are those at the start
/// of the step. \throws as step_symplectic_euler.
template <typename Scalar, typename Env>
StepReport<Scalar> step_rk2(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                            const Env& env, TetherState<Scalar>& state,
                            const TetherBoundary<Scalar>& boundary, Scalar dt) {
  detail::begin_explicit_step(model, ws, state, boundary, dt);
  const Scalar t = state.time, h2 = Scalar(0.5) * dt;
  detail::derivative(model, ws, env, t, boundary, ws.x0, ws.v0, ws.acceleration);
  ws.end_forces = end_forces_from_workspace(model, ws, boundary);
  ws.xs.noalias() = ws.x0 + h2 * ws.v0;
  ws.vs.noalias() = ws.v0 + h2 * ws.acceleration;
  detail::apply_boundary(model, boundary, h2, ws.xs, ws.vs);
  detail::derivative(model, ws, env, t + h2, boundary, ws.xs, ws.vs, ws.acceleration);
  ws.x1.noalias() = ws.x0 + dt * ws.vs;
  ws.v1.noalias() = ws.v0 + dt * ws.acceleration;
  detail::apply_boundary(model, boundary, dt, ws.x1, ws.v1);
  detail::commit(ws, state, ws.x1, ws.v1, dt, "step_rk2");
  StepReport<Scalar> r;
  r.force_evaluations = 2;
  return r;
}

/// \brief One classical RK4 step of length `dt` [s]. End forces are those at the start of the
/// step. \throws as step_symplectic_euler.
template <typename Scalar, typename Env>
StepReport<Scalar> step_rk4(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                            const Env& env, TetherState<Scalar>& state,
                            const TetherBoundary<Scalar>& boundary, Scalar dt) {
  detail::begin_explicit_step(model, ws, state, boundary, dt);
  const Scalar t = state.time;
  ws.xs = ws.x0;
  ws.vs = ws.v0;
  ws.x1 = ws.x0;
  ws.v1 = ws.v0;
  const Scalar c[4] = {Scalar(0), Scalar(0.5), Scalar(0.5), Scalar(1)};
  const Scalar w[4] = {dt / Scalar(6), dt / Scalar(3), dt / Scalar(3), dt / Scalar(6)};
  for (int k = 0; k < 4; ++k) {
    detail::derivative(model, ws, env, t + c[k] * dt, boundary, ws.xs, ws.vs, ws.acceleration);
    if (k == 0) ws.end_forces = end_forces_from_workspace(model, ws, boundary);
    ws.x1.noalias() += w[k] * ws.vs;
    ws.v1.noalias() += w[k] * ws.acceleration;
    if (k < 3) {
      const Scalar ch = c[k + 1] * dt;
      ws.xs.noalias() = ws.x0 + ch * ws.vs;
      ws.vs.noalias() = ws.v0 + ch * ws.acceleration;
      detail::apply_boundary(model, boundary, ch, ws.xs, ws.vs);
    }
  }
  detail::apply_boundary(model, boundary, dt, ws.x1, ws.v1);
  detail::commit(ws, state, ws.x1, ws.v1, dt, "step_rk4");
  StepReport<Scalar> r;
  r.force_evaluations = 4;
  return r;
}

/// \brief One implicit step (backward Euler, or BDF2 when `bdf2` is true and the previous step
/// had the same dt) solved by Newton's method.
///
/// With x = x̂ + γh v (backward Euler: γ = 1, x̂ = x_n, v̂ = v_n; BDF2: γ = 2/3,
/// x̂ = (4x_n − x_{n−1})/3, v̂ = (4v_n − v_{n−1})/3) the unknown node velocities solve
/// R(v) = M (v − v̂) − γh F(x̂ + γh v, v) = 0. The Jacobian J = M + γh D_v + (γh)² D_x
/// (D_v = −∂F/∂v: internal damping exactly, drag linearised, seabed damping and friction;
/// D_x = −∂F/∂x: axial plus geometric stiffness exactly, seabed stiffness; M, with its added
/// mass, at the current iterate) is block tridiagonal, symmetric positive definite, and solved
/// in O(N) by block-Thomas elimination (no dense N×N). Left out of J, so converging linearly
/// rather than quadratically when they dominate: the tangent dependence of drag and added mass,
/// the direction dependence of the dashpot, bending (EI). Each Newton direction settles which
/// segments are taut with a primal–dual active set (detail::active_set_direction) and is
/// shortened by a secant line search on the slope R·δ when it overshoots. The initial guess
/// extrapolates the velocity (2v_n − v_{n−1}) when the previous step had the same dt. Up to
/// `options.max_iterations` corrections; the step is taken even if the tolerance is not met
/// (see StepReport::converged). End forces are those of the final iterate, at t + dt.
/// \throws kelp::invalid_argument for bad input; kelp::numerical_error (state unchanged) when
/// the result is not finite.
template <typename Scalar, typename Env>
StepReport<Scalar> step_implicit(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                                 const Env& env, TetherState<Scalar>& state,
                                 const TetherBoundary<Scalar>& boundary, Scalar dt,
                                 bool bdf2 = false, const ImplicitOptions<Scalar>& options = {}) {
  using std::abs;
  detail::check_step_inputs(model, ws, state, boundary, dt);
  detail::check_implicit_options(options);
  const Scalar t1 = state.time + dt;
  const int f0 = model.first_free_node(), f1 = model.last_free_node();
  // The history (BDF2, velocity predictor) is used only if it is this state's previous step.
  const bool history = detail::history_matches(ws, state, dt);
  const bool use_bdf2 = bdf2 && history;
  const Scalar gamma = use_bdf2 ? Scalar(2) / Scalar(3) : Scalar(1);
  const Scalar gh = gamma * dt;
  // x̂ (ws.x0) and v̂ (ws.v0); initial guess v1 = v_n (or the BDF2 extrapolation).
  // One pass over the nodes for the history, the predictor and its positions.
  const int cols = model.nodes();
  if (use_bdf2) {
    const Scalar third = Scalar(1) / Scalar(3), four_thirds = Scalar(4) * third;
    for (int i = 0; i < cols; ++i) {
      const Vector3<Scalar> xn = state.position.col(i), vn = state.velocity.col(i);
      const Vector3<Scalar> xp = ws.x_prev.col(i), vp = ws.v_prev.col(i);
      const Vector3<Scalar> xh = four_thirds * xn - third * xp;
      const Vector3<Scalar> v1 = Scalar(2) * vn - vp;
      ws.x0.col(i) = xh;
      ws.v0.col(i) = four_thirds * vn - third * vp;
      ws.v1.col(i) = v1;
      ws.x1.col(i) = xh + gh * v1;
    }
  } else {
    // Predictor: linear extrapolation of the velocity when the last step had the same dt.
    const bool extrapolate = history;
    for (int i = 0; i < cols; ++i) {
      const Vector3<Scalar> xn = state.position.col(i), vn = state.velocity.col(i);
      const Vector3<Scalar> v1 =
          extrapolate ? Vector3<Scalar>(Scalar(2) * vn - ws.v_prev.col(i)) : vn;
      ws.x0.col(i) = xn;
      ws.v0.col(i) = vn;
      ws.v1.col(i) = v1;
      ws.x1.col(i) = xn + gh * v1;
    }
  }
  detail::apply_boundary(model, boundary, dt, ws.x1, ws.v1);

  StepReport<Scalar> report;
  report.converged = false;
  // Evaluates F at (x, v), writes rhs = −R = γh F − M (v − v̂) on the free nodes and sets `res`
  // to the scaled max-norm max_i |R_i|/a_i.
  const auto evaluate = [&](const Matrix3X<Scalar>& x, const Matrix3X<Scalar>& v, Scalar& res,
                            bool with_jacobian) {
    if (with_jacobian)
      compute_forces<true>(model, ws, env, t1, x, v);
    else
      compute_forces<false>(model, ws, env, t1, x, v);
    ++report.force_evaluations;
    res = Scalar(0);
    Scalar sum(0);
    using std::abs;
    for (int i = f0; i <= f1; ++i) {
      const Scalar d0 = v(0, i) - ws.v0(0, i), d1 = v(1, i) - ws.v0(1, i),
                   d2 = v(2, i) - ws.v0(2, i);
      const Scalar q0 = ws.tangent(0, i), q1 = ws.tangent(1, i), q2 = ws.tangent(2, i);
      const Scalar a = ws.mass_iso(i), bqd = ws.mass_tan(i) * (q0 * d0 + q1 * d1 + q2 * d2);
      const Scalar r0 = gh * ws.force(0, i) - (a * d0 + bqd * q0);
      const Scalar r1 = gh * ws.force(1, i) - (a * d1 + bqd * q1);
      const Scalar r2 = gh * ws.force(2, i) - (a * d2 + bqd * q2);
      ws.rhs(0, i) = r0;
      ws.rhs(1, i) = r1;
      ws.rhs(2, i) = r2;
      res = std::max(res, Scalar(std::max(std::max(abs(r0), abs(r1)), abs(r2)) / a));
      sum += (r0 + r1) + r2;
    }
    // NaN fails every comparison and std::max keeps its first argument: test the sum instead.
    if (!is_finite(sum))
      ::kelp::detail::throw_numerical_error(
          "step_implicit: non-finite residual; the state is unchanged");
  };
  Scalar res(0);
  evaluate(ws.x1, ws.v1, res, true);
  bool have_jacobian = true;
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
    report.residual = res;
    if (res <= options.velocity_tolerance) {
      report.converged = true;
      break;
    }
    if (it >= options.max_iterations) break;
    if (!have_jacobian) {  // the last trial was evaluated without the Jacobian terms
      evaluate(ws.x1, ws.v1, res, true);
      have_jacobian = true;
    }
    detail::active_set_direction(model, ws, gh, options.slack_band, options.max_active_set_passes);
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
        ws.end_forces.on_start += detail::segment_block(ws, 0, Scalar(1), gh) * ws.delta.col(1);
      if (f1 == n - 1 && n >= 2)
        ws.end_forces.on_end +=
            detail::segment_block(ws, n - 1, Scalar(1), gh) * ws.delta.col(n - 1);
      detail::commit(ws, state, ws.x1, ws.v1, dt, "step_implicit");
      return report;
    }
    // Line search. R is the gradient of the step's incremental potential
    // Φ(v) = ½(v − v̂)ᵀM(v − v̂) + U(x̂ + γh v) + γh·(dissipation potential), which is convex for
    // this model up to the tangent dependence of drag and added mass (elastic energy
    // ½EA/l·max(0, l_s − l)² is convex in x). Along x(α) = x + αδ the slope φ'(α) = R(α)·δ is
    // therefore increasing, with φ'(0) = −δᵀJδ < 0. The full Newton step is kept unless it
    // overshoots the minimum along δ (φ'(1) > ½|φ'(0)|, e.g. across the kink of the tension at
    // l_s = l, where plain Newton can cycle between the slack and the taut branch); then secant
    // steps on φ' home in on the minimum. Each trial costs one force evaluation.
    const auto slope = [&]() {
      Scalar g(0);
      for (int i = f0; i <= f1; ++i) g -= ws.rhs.col(i).dot(ws.delta.col(i));
      return g;
    };
    const Scalar g0 = slope();
    const Scalar a_lo(0), g_lo = g0;
    Scalar alpha(1), trial_res(0);
    for (int ls = 0;; ++ls) {
      for (int i = f0; i <= f1; ++i) {
        ws.vs.col(i) = ws.v1.col(i) + alpha * ws.delta.col(i);
        ws.xs.col(i) = ws.x0.col(i) + gh * ws.vs.col(i);
      }
      // The trial is usually the converged point, so its Jacobian terms are skipped (they are
      // recomputed, one evaluation more, only if another Newton iteration follows).
      evaluate(ws.xs, ws.vs, trial_res, false);
      have_jacobian = false;
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
  ws.end_forces = end_forces_from_workspace(model, ws, boundary);
  // commit() stores the pre-step state as BDF2 history.
  detail::commit(ws, state, ws.x1, ws.v1, dt, "step_implicit");
  return report;
}

/// \brief One step with the chosen integrator (dispatch). \throws as the individual steps.
template <typename Scalar, typename Env>
StepReport<Scalar> step(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                        const Env& env, TetherState<Scalar>& state,
                        const TetherBoundary<Scalar>& boundary, Scalar dt, Integrator integrator,
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
  return {};
}

namespace detail {

/// Number of segment springs on node i of a line of n segments (1 at an end, else 2).
inline int node_springs(int i, int n) { return (i > 0 ? 1 : 0) + (i < n ? 1 : 0); }

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
template <typename Scalar>
Scalar highest_axial_frequency(const TetherModel<Scalar>& model, Scalar water_density) {
  using std::sqrt;
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
/// \param[in] water_density ρ [kg/m³] for the added mass.
template <typename Scalar>
Scalar estimate_stable_dt(const TetherModel<Scalar>& model, Integrator integrator,
                          Scalar water_density = Scalar(kelp::seawater_density),
                          Scalar safety = Scalar(0.8)) {
  using std::sqrt;
  check_positive(safety, "safety");
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
/// time) through the interval. `ws.end_forces` holds the forces of the last sub-step. If any
/// sub-step fails the state is restored to its value at entry. No heap allocation.
/// \returns the number of sub-steps taken.
template <typename Scalar, typename Env>
int advance(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws, const Env& env,
            TetherState<Scalar>& state, const TetherBoundary<Scalar>& boundary, Scalar duration,
            Scalar max_dt, Integrator integrator, const ImplicitOptions<Scalar>& options = {}) {
  using std::ceil;
  check_positive(duration, "duration");
  check_positive(max_dt, "max_dt");
  const double ratio = ceil(value_of(duration / max_dt));
  KELP_CHECK(ratio <= double(std::numeric_limits<int>::max()),
             "max_dt too small for duration: more than INT_MAX sub-steps");
  const int n = std::max(1, static_cast<int>(ratio));
  const Scalar h = duration / Scalar(n);
  // Entry backup in kx/kv (no single step uses them).
  ws.kx = state.position;
  ws.kv = state.velocity;
  const Scalar t_entry = state.time;
  try {
    for (int k = 0; k < n; ++k) {
      const Scalar tau = Scalar(k) * h;
      TetherBoundary<Scalar> b = boundary;
      b.start.position = boundary.start.position_at(tau);
      b.start.velocity = boundary.start.velocity_at(tau);
      b.end.position = boundary.end.position_at(tau);
      b.end.velocity = boundary.end.velocity_at(tau);
      step(model, ws, env, state, b, h, integrator, options);
    }
  } catch (const kelp::numerical_error&) {
    state.position = ws.kx;
    state.velocity = ws.kv;
    state.time = t_entry;
    ws.has_previous = false;
    throw;
  }
  return n;
}

/// \brief Settings of the static-equilibrium solve.
template <typename Scalar>
struct StaticOptions {
  /// Converged when max_i |F_i| ≤ this [N]; ≤ 0 selects 1e-7 × the line's weight in air.
  Scalar force_tolerance = Scalar(0);
  /// Maximum (pseudo-transient) Newton iterations.
  int max_iterations = 200;
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
/// \throws kelp::invalid_argument for bad input; kelp::numerical_error if the iteration produces
/// non-finite values (state unchanged).
template <typename Scalar, typename Env>
StaticResult<Scalar> solve_static_equilibrium(const TetherModel<Scalar>& model,
                                              TetherWorkspace<Scalar>& ws, const Env& env,
                                              TetherState<Scalar>& state,
                                              const TetherBoundary<Scalar>& boundary,
                                              const StaticOptions<Scalar>& options = {}) {
  check_state(model, state);
  check_boundary(boundary);
  check_positive(options.initial_pseudo_dt, "initial_pseudo_dt");
  KELP_CHECK(options.max_iterations >= 1, "max_iterations must be >= 1");
  const int f0 = model.first_free_node(), f1 = model.last_free_node();
  Scalar tol = options.force_tolerance;
  if (!(tol > Scalar(0)))
    tol = Scalar(1e-7) * model.parameters().mass_per_length * model.parameters().length *
          Scalar(env.gravity());
  TetherBoundary<Scalar> b = boundary;
  b.start.velocity.setZero();
  b.end.velocity.setZero();
  b.start.acceleration.setZero();
  b.end.acceleration.setZero();
  // Keep the entry state in kx/kv (no single step uses them) and iterate on `state` itself,
  // restoring it on error.
  ws.kx = state.position;
  ws.kv = state.velocity;
  const Scalar t_entry = state.time;
  state.velocity.setZero();
  detail::apply_boundary(model, b, Scalar(0), state.position, state.velocity);
  ImplicitOptions<Scalar> inner;
  inner.max_iterations = 6;
  const Scalar m_ref = model.node_mass(model.segments() / 2);
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
      // The inner residual is max_i h·|F_i|/a_i [m/s], a_i the node's isotropic mass (structural
      // plus added mass), not m_ref: this tolerance asks for |F_i| ≤ ½·tol·a_i/m_ref, half the
      // force tolerance for an interior node in air, looser where added mass or a point mass
      // makes a_i > m_ref (the outer loop checks |F_i| ≤ tol itself).
      inner.velocity_tolerance = Scalar(0.5) * tol * h / m_ref;
      const StepReport<Scalar> r = step_implicit(model, ws, env, state, b, h, false, inner);
      state.time = t_entry;
      state.velocity.setZero();
      if (!r.converged && h > options.initial_pseudo_dt * Scalar(1e-6)) {
        // Undo: commit() kept the position before the step in ws.x_prev, a buffer the Newton
        // iteration does not touch (its trial buffers xs/vs do not survive the step).
        state.position = ws.x_prev;
        h *= Scalar(0.25);
      } else if (r.newton_iterations <= 3) {
        h = std::min(h_max, h * Scalar(2));
      }
    }
  } catch (const kelp::numerical_error&) {
    state.position = ws.kx;
    state.velocity = ws.kv;
    state.time = t_entry;
    ws.has_previous = false;
    throw;
  }
  ws.end_forces = end_forces_from_workspace(model, ws, b);
  ws.has_previous = false;
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
