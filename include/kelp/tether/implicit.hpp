/// \file
/// \brief The implicit tether steps: backward Euler and BDF2, solved by a simplified Newton
/// method (the factored Newton matrix kept in the state and reused across iterations and steps
/// while it serves) or by Newton's method, with the analytic block-tridiagonal symmetric
/// Jacobian (kelp/tether/block_solve.hpp) and, where it does not serve, the whole Jacobian
/// (kelp/tether/whole_newton.hpp), backtracking and step halving; a step that cannot be
/// completed throws and leaves the state as it was. End forces are those at the end of the step.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/simd.hpp"
#include "kelp/core/types.hpp"

#include "kelp/tether/block_solve.hpp"
#include "kelp/tether/forces.hpp"
#include "kelp/tether/model.hpp"
#include "kelp/tether/state.hpp"
#include "kelp/tether/stepping.hpp"
#include "kelp/tether/whole_newton.hpp"

namespace kelp::tether {

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
    const Scalar normal =
        (pen * k + state.velocity(2, i) * c * ramp) * node_length_at(model, ws, i);
    ws.friction_normal(i) = pen > Scalar(0) && normal > Scalar(0) ? normal : Scalar(0);
  }
}

/// True when every segment's taut/slack/clamped branch at the last force evaluation (from its
/// length and its clamped axial force, which compute_forces fills with or without the Jacobian
/// terms) is `branch`'s (see active_set_direction).
/// Segments at least (1 − band)·l long count as taut, as active_set_direction starts them.
template <typename Scalar>
bool branches_are(const TetherModel<Scalar>& model, const TetherWorkspace<Scalar>& ws,
                  const VectorX<Scalar>& branch, Scalar band) {
  const bool clamp = !model.parameters().compressive_damping;
  const int n = model.segments();
  const bool banded = band > Scalar(0);
  const auto code = [&](int s, Scalar l) {
    const Scalar ls = ws.stretched_length(s);
    if (ws.is_parted(s)) return Scalar(0);
    if (banded && ls >= (Scalar(1) - band) * l) return Scalar(2);
    if (clamp && !(ws.tension(s) > Scalar(0))) return Scalar(0);
    return ls > l ? Scalar(2) : Scalar(1);
  };
  // The segments' rest length (segment 0's own at a winch).
  const Scalar l_rest = model.segment_length();
  if (code(0, segment_springs(model, ws, 0).l) != branch(0)) return false;
  if (ws.any_parted) {
    for (int s = 1; s < n; ++s)
      if (code(s, l_rest) != branch(s)) return false;
    return true;
  }
  // The others in packets (step_pass_body.hpp's branch_pass: the same codes).
  return branches_all(BranchArrays<Scalar>{1, n, l_rest, (Scalar(1) - band) * l_rest, banded, clamp,
                                           ws.stretched_length.data(), ws.tension.data(),
                                           branch.data()});
}

/// One attempt at an implicit step of length dt (see step_implicit_euler / step_bdf2): commits the
/// new state and returns true when Newton's method converged (or options.check_convergence is
/// false); returns false with the state untouched otherwise. Adds its work to `report`. Inputs
/// already checked. With NewtonMethod::simplified, `fresh_matrices` forms the Newton matrix at
/// every iteration (Newton's method, the matrix kept for the next steps) instead of reusing the
/// kept one; `reused` says whether a kept matrix was reused. With `whole`, every iteration
/// forms and factors the whole Jacobian (kelp/tether/whole_newton.hpp: exact Newton) and the
/// line search works on the residual's norm. With `may_switch`, the attempt turns to the whole
/// Jacobian once a symmetric matrix formed at the iterate contracts the residual by less than
/// options.max_contraction (JacobianKind::adaptive).
template <typename Scalar, typename Env>
bool implicit_attempt(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws, const Env& env,
                      TetherState<Scalar>& state, const TetherBoundary<Scalar>& boundary, double dt,
                      bool bdf2, const ImplicitOptions<Scalar>& options, StepReport<Scalar>& report,
                      bool fresh_matrices, bool whole_from_start, bool may_switch, bool& reused) {
  using std::abs;
  using std::pow;
  const double t1 = state.time + dt;
  const int f0 = model.first_free_node(), f1 = model.last_free_node();
  // The history (BDF2, velocity predictor) is used only if it is this state's previous step.
  const bool history = history_matches(state, dt);
  const bool use_bdf2 = bdf2 && history;
  const Scalar gamma = use_bdf2 ? Scalar(2) / Scalar(3) : Scalar(1);
  const Scalar gh = gamma * Scalar(dt);
  const Scalar tolerance = options.acceleration_tolerance * Scalar(dt);
  // x̂ (ws.x0) and v̂ (ws.v0); initial guess v1 = v_n (or an extrapolation).
  // One vectorised pass over the flat 3 × (N+1) arrays for the history, the predictor and its
  // positions. Predictor, when the last step had the same dt: BDF2, v_{n−1} + 2h a_n from the
  // accelerations the last implicit step left (TetherState::acceleration; the leapfrog formula,
  // exact for a velocity quadratic in time: error O(h³)), else the linear extrapolation
  // 2v_n − v_{n−1} (error O(h²); what the leapfrog gives after a backward Euler step, whose
  // a_n = (v_n − v_{n−1})/h), whichever came closer to the last BDF2 step's solution
  // (TetherState::predict_from_acceleration; the accelerations' overshoots where stiff modes
  // ring, ωh ≳ 1). A kept Newton matrix then serves many more steps (its first correction
  // starts closer: on the benchmark line at N = 100, 28 steps per matrix instead of 3).
  const int cols = model.nodes();
  {
    // One pass (step_pass_body.hpp's predict_pass).
    const Scalar third = Scalar(1) / Scalar(3), four_thirds = Scalar(4) * third;
    const Eigen::Index len = 3 * Eigen::Index(cols);
    const int mode = use_bdf2 ? (state.has_acceleration && state.predict_from_acceleration ? 3 : 2)
                              : (history ? 1 : 0);
    predict_all(PredictArrays<Scalar>{
        len, mode, four_thirds, third, gh, Scalar(2 * dt), state.position.data(),
        state.velocity.data(), state.previous_position.data(), state.previous_velocity.data(),
        state.acceleration.data(), ws.x0.data(), ws.v0.data(), ws.x1.data(), ws.v1.data()});
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
  // The Newton matrix. Exact: formed at every iteration in ws.block_inv. Simplified: the one
  // the state keeps (TetherState::newton) while it fits this step's γh and is young enough,
  // else one formed in this attempt (ws.newton_factor, its branches in ws.newton_branch),
  // which commit() hands to the state.
  const bool simplified = options.newton == NewtonMethod::simplified && options.check_convergence;
  bool whole = whole_from_start;
  const bool form_always = !simplified || fresh_matrices || whole;
  // JacobianKind::adaptive: the correction before came from a symmetric matrix formed at that
  // iterate (not a kept one).
  bool fresh_symmetric = false;
  // A whole matrix the block LU refused (a numerically singular pivot block, e.g. (γh)² EA/l
  // dwarfing the mass at a very long step, where the symmetric elimination floors its pivots):
  // the attempt goes on with symmetric matrices.
  bool whole_refused = false;
  const Scalar* matrix = nullptr;
  const VectorX<Scalar>* matrix_branch = nullptr;
  reused = false;
  if (!form_always && state.newton.pause == 0 && state.newton.holds(cols) &&
      state.newton.gh == gh && state.newton.age < options.max_matrix_age) {
    matrix = state.newton.factor.data();
    matrix_branch = &state.newton.branch;
  }
  Scalar first_residual(0);   // scaled residual after the first correction
  bool first_reused = false;  // the first correction reused a kept matrix
  // Takes the iterate (ws.x1, ws.v1) with ws.end_forces: commit() turns the pre-step state into
  // the history; the end forces' impulse over dt and the residual go to the report.
  const auto accept = [&]() {
    const int age = state.newton.age;
    int pause = std::max(state.newton.pause - 1, 0), backoff = state.newton.backoff;
    using std::max;
    if (first_reused && first_residual > max(options.refresh_residual, Scalar(1)) * tolerance) {
      // The kept matrix could not make this step in one correction: form a new one at the
      // predictor for the next 1, 3, 7, … 31 steps before trying one again (a second
      // correction with a kept matrix costs about as much as forming a new one).
      backoff = std::min(2 * backoff + 1, 31);
      pause = backoff;
    } else if (first_reused) {
      backoff = 0;
    }
    // The accelerations at the new state, (v − v̂)/(γh), into ws.xs (scratch now: the trial
    // iterates are done), handed to the state after the commit; and, after a BDF2 step that had
    // both predictors and was not made by one correction with the kept matrix (the predictor
    // served: nothing to choose), which of them came closer to its solution on the free nodes:
    // the next steps start from that one (TetherState::predict_from_acceleration).
    const bool served = first_reused && first_residual <= options.refresh_residual * tolerance;
    const bool compare = use_bdf2 && state.has_acceleration && !served;
    AccelerationArrays<Scalar> acc{3 * Eigen::Index(cols),
                                   3 * Eigen::Index(f0),
                                   3 * Eigen::Index(f1 + 1),
                                   compare,
                                   Scalar(1) / gh,
                                   Scalar(2 * dt),
                                   state.velocity.data(),
                                   state.previous_velocity.data(),
                                   state.acceleration.data(),
                                   ws.v0.data(),
                                   ws.v1.data(),
                                   ws.xs.data()};
    accelerations_all(acc);
    const bool from_acceleration = compare ? acc.leap < acc.lin : state.predict_from_acceleration;
    commit(state, ws.x1, ws.v1, dt, "step_implicit");  // drops the kept matrix
    state.acceleration.swap(ws.xs);
    state.has_acceleration = true;
    state.predict_from_acceleration = from_acceleration;
    if (simplified) {
      state.newton.pause = pause;
      state.newton.backoff = backoff;
    }
    if (simplified && matrix == ws.newton_factor.data()) {
      state.newton.factor.swap(ws.newton_factor);
      state.newton.branch.swap(ws.newton_branch);
      state.newton.gh = gh;
      state.newton.age = 1;
    } else if (simplified && matrix &&
               !(first_reused && first_residual > options.refresh_residual * tolerance)) {
      // The residual the kept matrix leaves after one correction grows with its age: once above
      // refresh_residual · tolerance, the next step would need a second correction, which costs
      // more than forming the matrix anew (Hairer & Wanner's κ · Tol): then it is dropped.
      state.newton.gh = gh;
      state.newton.age = age + 1;
    }
    ws.end_impulse.on_start += Scalar(dt) * ws.end_forces.on_start;
    ws.end_impulse.on_end += Scalar(dt) * ws.end_forces.on_end;
    report.residual = std::max(report.residual, res);
    ++report.substeps;
  };
  // Evaluates F at (x, v), writes rhs = −R = γh F − M (v − v̂) on the free nodes and sets `res`
  // to the scaled max-norm max_i |R_i|/a_i: the force passes form the residual in their last
  // loop (ImplicitResidual).
  const auto evaluate = [&](const Matrix3X<Scalar>& x, const Matrix3X<Scalar>& v, Scalar& r_max,
                            bool with_jacobian) {
    // The evaluation behind compute_forces, without its checks: the workspace and the state
    // were checked once for the step, and a non-finite iterate shows in the residual's sum
    // below (numerical_error: the step is retried).
    ImplicitResidual<Scalar> residual{ws.v0.data(), gh, f0, f1, ws.rhs.data()};
    if (with_jacobian)
      evaluate_forces<true>(model, ws, env, t1, x, v, static_cast<Scalar*>(nullptr), &residual);
    else
      evaluate_forces<false>(model, ws, env, t1, x, v, static_cast<Scalar*>(nullptr), &residual);
    ++report.force_evaluations;
    r_max = residual.r_max;
    // NaN fails every comparison and max keeps one of its arguments: test the sum instead.
    if (!is_finite(residual.sum))
      ::kelp::detail::throw_numerical_error(
          "step_implicit: non-finite residual; the state is unchanged");
  };
  // Water and free surface: sampled by the first evaluation (at the predictor), then held.
  struct WaterGuard {
    TetherWorkspace<Scalar>& w;
    ~WaterGuard() { w.water_frozen = false; }
  } water_guard{ws};
  ws.water_frozen = false;
  // The Jacobian terms are needed where a matrix is formed: at the predictor unless one is kept.
  bool jacobian_here = matrix == nullptr;
  evaluate(ws.x1, ws.v1, res, jacobian_here);
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
  Scalar res_before(0);  // scaled residual before the last correction
  for (int it = 0;; ++it) {
    // At least one correction: the predictor alone never makes a step.
    if (it == 1) first_residual = res;
    if (it >= 1 && res <= tolerance) {
      converged = true;
      break;
    }
    if (it >= options.max_iterations) break;
    // Simplified Newton: keep the matrix while the iteration contracts fast enough to reach
    // the tolerance within the iterations left, θ = r_k / r_{k−1} < max_contraction and
    // θ^(k_max − k) r_k / (1 − θ) ≤ tol (Hairer & Wanner §IV.8, on the scaled residual), and
    // every segment is on the branch the matrix was formed with.
    bool form = form_always || matrix == nullptr || whole;
    const Scalar theta = it >= 1 ? res / res_before : Scalar(0);
    if (!form && it >= 1)
      form =
          !(theta < options.max_contraction) ||
          pow(theta, Scalar(options.max_iterations - it)) * res > (Scalar(1) - theta) * tolerance;
    if (!form) form = !branches_are(model, ws, *matrix_branch, options.slack_band);
    // Adaptive: when even a symmetric matrix formed at the last iterate contracted by less than
    // max_contraction, the terms it leaves out matter here (a node crossing the surface band, a
    // line whipped by the waves): the rest of the attempt uses the whole Jacobian, with which
    // Newton converges quadratically.
    if (may_switch && !whole && !whole_refused && fresh_symmetric &&
        !(theta < options.max_contraction)) {
      whole = true;
      form = true;
      ++report.whole_jacobian_attempts;
    }
    fresh_symmetric = form && !whole;
    if (form) {
      if (!jacobian_here) {
        // The same iterate again, with the Jacobian terms (rhs and res are unchanged).
        evaluate(ws.x1, ws.v1, res, true);
        jacobian_here = true;
      }
      if (whole) {
        try {
          report.factorisations +=
              whole_newton_direction(model, ws, env, ws.x1, ws.v1, ws.v1 - ws.v0, gh,
                                     options.slack_band, options.max_active_set_passes);
        } catch (const kelp::numerical_error&) {
          if (whole_from_start) throw;
          // Refused after the switch: the same iterate again (the active-set passes may have
          // left ws.rhs modified), then the symmetric matrix.
          whole = false;
          whole_refused = true;
          evaluate(ws.x1, ws.v1, res, true);
        }
      }
      if (whole) {
        // The direction is in ws.delta.
      } else if (simplified) {
        report.factorisations +=
            active_set_direction(model, ws, gh, options.slack_band, options.max_active_set_passes,
                                 ws.newton_factor.data());
        ws.newton_branch = ws.seg_branch;
        matrix = ws.newton_factor.data();
        matrix_branch = &ws.newton_branch;
      } else {
        report.factorisations +=
            active_set_direction(model, ws, gh, options.slack_band, options.max_active_set_passes);
      }
    } else {
      solve_factored_block_tridiagonal(model, matrix, ws.rhs, ws.delta);
      ++report.reused_factorisations;
      if (it == 0) first_reused = true;
      reused = true;
    }
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
      set_end_node_forces(model, ws, boundary);
      accept();
      return true;
    }
    const Eigen::Index nf = f1 - f0 + 1;
    // The trial iterate's free nodes, v = v1 + α δ and x = x̂ + γh v (one pass; the same bits as
    // the matrix expressions).
    Scalar alpha(1);
    const auto trial = [&]() {
      trial_all(3 * Eigen::Index(f0), 3 * Eigen::Index(f1 + 1), alpha, gh, ws.v1.data(),
                ws.delta.data(), ws.x0.data(), ws.vs.data(), ws.xs.data());
    };
    if (whole) {
      // Line search on the merit ψ(α) = Σ_i |R_i/a_i|² along δ: with the whole Jacobian δ is a
      // descent direction of ψ (ψ'(0) = −2ψ(0)) whether or not R is a gradient (the secant
      // search below assumes it is). Armijo test ψ(α) ≤ (1 − 2σα) ψ(0), σ = 1e-4; otherwise α
      // from the quadratic through ψ(0), ψ'(0), ψ(α), kept in [0.1α, 0.5α] (Dennis & Schnabel,
      // Numerical Methods for Unconstrained Optimization, §6.3.2). Damping is what stops a
      // node that crosses a kink of the forces (the edge of the surface band, a segment at its
      // rest length) from cycling between the two sides.
      const auto merit = [&]() {
        Scalar m(0);
        for (int i = f0; i <= f1; ++i)
          m += ws.rhs.col(i).squaredNorm() * (ws.mass_iso_inv(i) * ws.mass_iso_inv(i));
        return m;
      };
      const Scalar m0 = merit();
      Scalar trial_res(0);
      for (int ls = 0;; ++ls) {
        trial();
        evaluate(ws.xs, ws.vs, trial_res, true);
        if (ls >= options.max_backtracks) break;
        const Scalar m = merit();
        if (m <= (Scalar(1) - Scalar(2e-4) * alpha) * m0) break;
        const Scalar a_q = m0 * alpha * alpha / (m - m0 + Scalar(2) * m0 * alpha);
        alpha = std::min(std::max(a_q, Scalar(0.1) * alpha), Scalar(0.5) * alpha);
      }
      ws.x1.swap(ws.xs);
      ws.v1.swap(ws.vs);
      jacobian_here = true;
      res_before = res;
      res = trial_res;
      continue;
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
      return Scalar(-ws.rhs.middleCols(f0, nf).cwiseProduct(ws.delta.middleCols(f0, nf)).sum());
    };
    const Scalar g0 = slope();
    const Scalar a_lo(0), g_lo = g0;
    Scalar trial_res(0);
    for (int ls = 0;; ++ls) {
      trial();
      // Newton's method: the trial carries its Jacobian terms: when another Newton iteration
      // follows (half the steps of a line near the surface) they are needed at this point, and
      // filling them costs less than a second evaluation there (−6 % instructions per system
      // step). The simplified method goes on with the matrix it has.
      evaluate(ws.xs, ws.vs, trial_res, !simplified);
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
    jacobian_here = !simplified;
    res_before = res;
    res = trial_res;
  }
  if (!converged) {
    report.rejected_residual = std::max(report.rejected_residual, res);
    return false;
  }
  ws.end_forces = end_forces_from_workspace(model, ws, boundary);
  set_end_node_forces(model, ws, boundary);
  accept();
  return true;
}

/// implicit_attempt, with a non-finite iterate (numerical_error) counted as not converged: a
/// shorter step may well succeed. Nothing is committed when it returns false.
/// With the simplified method, an attempt that reused a kept matrix and failed is made again
/// with a fresh matrix at every iteration (Newton's method) before it counts as failed.
template <typename Scalar, typename Env>
bool try_implicit(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws, const Env& env,
                  TetherState<Scalar>& state, const TetherBoundary<Scalar>& boundary, double dt,
                  bool bdf2, const ImplicitOptions<Scalar>& options, StepReport<Scalar>& report) {
  const Scalar rejected = report.rejected_residual;
  // Attempts: 0 as the options say (reusing a kept matrix; JacobianKind::adaptive: turning to
  // the whole Jacobian where the symmetric matrix contracts slowly); 1 with fresh symmetric
  // matrices at every iteration (Newton's method as before the whole Jacobian) when attempt 0
  // reused a matrix or could switch; 2 with the whole Jacobian from the start
  // (JacobianKind::adaptive) when those did not converge.
  const bool always_whole = options.jacobian == JacobianKind::whole;
  const bool adaptive = options.jacobian == JacobianKind::adaptive;
  for (int attempt = 0; attempt < 3; ++attempt) {
    const bool whole = always_whole || attempt == 2;
    if (attempt == 2) ++report.whole_jacobian_attempts;
    bool reused = false;
    try {
      if (implicit_attempt(model, ws, env, state, boundary, dt, bdf2, options, report, attempt >= 1,
                           whole, adaptive && attempt == 0, reused)) {
        report.rejected_residual = rejected;  // the fallback made the step: nothing rejected
        return true;
      }
    } catch (const kelp::numerical_error&) {
      report.rejected_residual = std::numeric_limits<Scalar>::infinity();
    }
    if (whole || (attempt == 1 && options.jacobian != JacobianKind::adaptive)) break;
    if (attempt == 0 && !reused && !adaptive) attempt = 2;
  }
  return false;
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
/// in O(N) by block-Thomas elimination (no dense N×N). Left out of this J, so converging
/// linearly rather than quadratically when they dominate (rough seas, the surface band): the
/// tangent dependence of drag, forcing and added mass, the added-mass rate terms, the band's
/// scaling of the fluid forces, the direction dependence of the dashpot, bending (EI). The whole
/// Jacobian ∂R/∂v = M + γh ∂(M d)/∂x − γh ∂F/∂v − (γh)² ∂F/∂x (kelp/tether/jacobian.hpp, every
/// term; block-pentadiagonal, not symmetric, block LU in O(N), kelp/tether/whole_newton.hpp)
/// makes Newton converge quadratically at about twice the cost per iteration
/// (ImplicitOptions::jacobian: `whole` at every iteration; `adaptive`, the default, where a
/// symmetric matrix formed at the iterate contracts the residual by less than max_contraction,
/// and for a step the symmetric attempts cannot converge). Each Newton direction settles which
/// segments are taut, slack or clamped with a primal–dual active set
/// (detail::active_set_direction, detail::whole_newton_direction) and is shortened by a secant
/// line search on the slope R·δ when it overshoots (with the whole Jacobian, by an Armijo
/// backtracking on Σ|R_i/a_i|², R then not being a gradient).
///
/// The Newton matrix (ImplicitOptions::newton): NewtonMethod::exact evaluates the Jacobian and
/// factors J at every iteration. NewtonMethod::simplified (the default) is the simplified Newton
/// iteration of implicit Runge–Kutta codes, its matrix reused across steps (Hairer & Wanner,
/// Solving Ordinary Differential Equations II, 2nd ed. 1996, §IV.8 "Implementation of Implicit
/// Runge–Kutta Methods"): the factored matrix of the last step that formed one is kept in the state
/// (TetherState::newton) and each correction is one forward and back substitution with it
/// (detail::solve_factored_block_tridiagonal, about a fifth of a factorisation), the force
/// evaluations skipping the Jacobian terms. It is formed anew, from the Jacobian at the current
/// iterate, when none is kept, when γh differs from the one it was formed with (a new dt, or
/// BDF2's backward-Euler start), when a segment's taut/slack/clamped branch at the iterate is
/// not the one in the matrix (the kinks of the axial force change J by EA/l), when it has
/// served `max_matrix_age` steps, when the iteration's contraction θ_k = r_k/r_{k−1} of the
/// scaled residual reaches `max_contraction` or the residual is not expected to reach the
/// tolerance within the corrections left (θ^(k_max−k) r_k/(1 − θ) > tol), and at the next step
/// when a step's first correction left more than `refresh_residual` × the tolerance (the
/// residual a kept matrix leaves grows with its age; on the benchmark line it serves two or
/// three steps); after a step that the kept matrix could not make in one correction, the next
/// 1, 3, 7, … 31 steps form their own (a fast-moving line). A step that fails with a reused matrix
/// is attempted again with a fresh matrix at every iteration (Newton's method) before it is split.
/// Both methods stop on the same residual test, so their results agree to the tolerance. The
/// initial guess extrapolates the velocity when the previous step had the same dt: BDF2 from the
/// accelerations the last implicit step left (TetherState::acceleration), v_{n−1} + 2h a_n, or
/// linearly, 2v_n − v_{n−1}, whichever came closer to the last BDF2 step's solution
/// (TetherState::predict_from_acceleration); backward Euler linearly.
/// At least one and up to `options.max_iterations` corrections, until max_i |R_i|/a_i ≤
/// acceleration_tolerance · dt (the tolerance raised to the arithmetic's resolution where it is
/// below it, see ImplicitOptions::acceleration_tolerance). A step that does not converge is not
/// committed: it is retried as two half steps, each halved again if needed, at most
/// `options.max_step_halvings` times (BDF2 restarts with backward Euler after a change of step); if
/// even that fails, kelp::numerical_error is thrown with the state unchanged. End forces
/// (`ws.end_forces`) are those of the final iterate, at t + dt.
/// \returns the work done (sub-steps, Newton iterations, factorisations and reuses, worst
/// residual, retries).
/// \throws kelp::invalid_argument for bad input; kelp::numerical_error (state unchanged) when
/// the result is not finite or Newton's method does not converge.
namespace detail {
template <typename Scalar, typename Env>
StepReport<Scalar> step_implicit(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                                 const Env& env, TetherState<Scalar>& state,
                                 const TetherBoundary<Scalar>& boundary, double dt, bool bdf2,
                                 const ImplicitOptions<Scalar>& options) {
  detail::check_step_inputs(model, ws, state, boundary, dt);
  detail::load_parted(state, ws);
  detail::load_clamps(model, boundary, ws);
  detail::check_implicit_options(options);
  detail::check_resolvable(model, state, options);
  // A tolerance below what the arithmetic resolves asks Newton's method for noise (a stiff float
  // line: 0.1 m/s² against ~10 m/s² of rounding): raised to the resolution.
  ImplicitOptions<Scalar> resolved = options;
  using std::max;
  resolved.acceleration_tolerance =
      max(options.acceleration_tolerance, detail::force_resolution(model, state));
  ws.end_impulse = EndForces<Scalar>{};
  StepReport<Scalar> report;
  if (try_implicit(model, ws, env, state, boundary, dt, bdf2, resolved, report)) return report;
  // Not converged, nothing committed: retry in halves from a backup.
  ws.retry_backup.save(state);
  bool done = false;
  if (options.max_step_halvings > 0) {
    ++report.retries;
    done = implicit_halves(model, ws, env, state, boundary, 0.0, dt, bdf2, resolved,
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
}  // namespace detail

/// \brief One backward (implicit) Euler step of length `dt` [s] (Integrator::implicit_euler):
/// the Newton scheme above with γ = 1.
/// \param[in] model the tether. \param[in,out] ws buffers. \param[in] env the water.
/// \param[in,out] state advanced by dt (its clock too) on success, unchanged on failure.
/// \param[in] boundary the kinematic ends' motion. \param[in] dt step [s], > 0.
/// \param[in] options Newton settings.
/// \return the work done (sub-steps, Newton iterations, factorisations and reuses, worst
/// residual [m/s], retries).
/// \throws kelp::invalid_argument for bad input (state, boundary, dt, options, a workspace not
/// built for the model); kelp::numerical_error (state unchanged) when the result is not finite
/// or Newton's method does not converge even in sub-steps.
/// \tparam Scalar double or float (deduced from the model).
/// \tparam Env the environment type (kelp/tether/lumped_mass.hpp).
template <typename Scalar, typename Env>
StepReport<Scalar> step_implicit_euler(const TetherModel<Scalar>& model,
                                       TetherWorkspace<Scalar>& ws, const Env& env,
                                       TetherState<Scalar>& state,
                                       const TetherBoundary<Scalar>& boundary, double dt,
                                       const ImplicitOptions<Scalar>& options = {}) {
  return detail::step_implicit(model, ws, env, state, boundary, dt, false, options);
}

/// \brief One second-order BDF step of length `dt` [s] (Integrator::bdf2): the Newton scheme
/// above with γ = 2/3 (backward Euler on the first step or after a change of dt).
/// Parameters and throws as step_implicit_euler().
/// \tparam Scalar double or float (deduced from the model).
/// \tparam Env the environment type: kelp::environment::Environment or any type with its duck-typed
/// interface (kelp/tether/lumped_mass.hpp).
/// \param[in] model the tether.
/// \param[in,out] ws the workspace built for `model` (TetherWorkspace(model)); end_forces,
/// end_node_forces and end_impulse are set.
/// \param[in] env the water (density, gravity, kinematics, seabed), queried at the step's times.
/// \param[in,out] state advanced by dt (its clock too) on success, unchanged on failure.
/// \param[in] boundary the kinematic ends' motion over the step, NED, from the state's time.
/// \param[in] dt the step [s], > 0.
/// \param[in] options Newton settings.
/// \return the work done, as step_implicit_euler().
template <typename Scalar, typename Env>
StepReport<Scalar> step_bdf2(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                             const Env& env, TetherState<Scalar>& state,
                             const TetherBoundary<Scalar>& boundary, double dt,
                             const ImplicitOptions<Scalar>& options = {}) {
  return detail::step_implicit(model, ws, env, state, boundary, dt, true, options);
}

}  // namespace kelp::tether
