/// \file
/// \brief What the tether's time steps share: the schemes (`Integrator`), the implicit schemes'
/// Newton settings (`ImplicitOptions`), the report of a step (`StepReport`), and the checks,
/// commit and end-impulse bookkeeping every step goes through.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <type_traits>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/simd.hpp"
#include "kelp/core/types.hpp"
#include "kelp/tether/failure.hpp"
#include "kelp/tether/forces.hpp"
#include "kelp/tether/model.hpp"
#include "kelp/tether/state.hpp"

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
/// \param i the scheme.
/// \return its name, a string literal ("unknown" outside the enum).
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
/// \param i the value checked.
/// \return whether `i` is one of the five schemes.
inline bool is_valid(Integrator i) {
  return static_cast<int>(i) >= static_cast<int>(Integrator::symplectic_euler) &&
         static_cast<int>(i) <= static_cast<int>(Integrator::bdf2);
}

/// \brief True for the Newton-solved schemes.
/// \param i the scheme.
/// \return true for implicit_euler and bdf2.
inline bool is_implicit(Integrator i) {
  return i == Integrator::implicit_euler || i == Integrator::bdf2;
}

/// \brief Which Jacobian the implicit schemes' Newton iteration solves with.
enum class JacobianKind {
  /// The symmetric block-tridiagonal approximation M + γh D_v + (γh)² D_x (axial force,
  /// geometric stiffness, drag with the tangent held, seabed), solved by twisted block-Cholesky
  /// elimination (detail::active_set_direction): the cheapest per iteration, and the matrix the
  /// simplified Newton method keeps; Newton converges linearly where the terms it leaves out
  /// matter (rough seas, the surface band).
  symmetric,
  /// The whole Jacobian of the residual (kelp/tether/jacobian.hpp: the tangent's dependence of
  /// drag and added mass, the added-mass rate terms, surface band, seabed, dashpot direction,
  /// bending), block-pentadiagonal and not symmetric, solved by block LU
  /// (kelp/tether/whole_newton.hpp) and formed at every iteration: exact Newton, quadratic
  /// convergence, about twice the cost of a symmetric iteration.
  whole,
  /// The symmetric matrix (kept and reused by the simplified method), and the whole Jacobian
  /// for the rest of an attempt where a symmetric matrix formed at the iterate contracts the
  /// residual by less than ImplicitOptions::max_contraction, and for a step that did not
  /// converge with fresh symmetric matrices, before the step is split.
  adaptive
};

/// \brief Name of a Jacobian kind ("symmetric", "whole", "adaptive").
/// \param k the kind.
/// \return its name, a string literal (any value outside the enum reads "adaptive").
inline const char* jacobian_kind_name(JacobianKind k) {
  return k == JacobianKind::symmetric ? "symmetric"
                                      : (k == JacobianKind::whole ? "whole" : "adaptive");
}

/// \brief How the implicit schemes solve their nonlinear equations.
enum class NewtonMethod {
  /// Newton's method: the Jacobian is evaluated and the Newton matrix factored at every
  /// iteration.
  exact,
  /// Simplified Newton iteration with the matrix reused across steps (Hairer & Wanner, Solving
  /// Ordinary Differential Equations II, 2nd ed., Springer 1996, §IV.8): the factored Newton
  /// matrix is kept and reused across iterations and steps while the iteration contracts well,
  /// and formed again (from a fresh Jacobian) when the active set, γh or the contraction says it
  /// has gone stale.
  simplified
};

/// \brief Name of a Newton method ("exact", "simplified").
/// \param m the method.
/// \return its name, a string literal (any value outside the enum reads "simplified").
inline const char* newton_method_name(NewtonMethod m) {
  return m == NewtonMethod::exact ? "exact" : "simplified";
}

/// \brief Newton settings of the implicit schemes.
/// \tparam Scalar double or float (the tolerances' type).
template <typename Scalar>
struct ImplicitOptions {
  /// Maximum Newton corrections per step (each: one solve with the Newton matrix, factored anew
  /// for NewtonMethod::exact).
  int max_iterations = 8;
  /// The Newton matrix (JacobianKind): the symmetric approximation, reused by the simplified
  /// method, with the whole Jacobian for the steps it cannot converge (adaptive, the default);
  /// always symmetric; or always the whole Jacobian (exact Newton, no reuse).
  JacobianKind jacobian = JacobianKind::adaptive;
  /// Newton's method (refactor at every iteration) or the simplified Newton method that keeps the
  /// factored Newton matrix J = M + γh D_v + (γh)² D_x in the state (TetherState::newton) and
  /// reuses it across iterations and steps. The simplified method forms it again when there is
  /// none, when γh changed (a new dt, or BDF2's first step), when a segment's taut/slack/clamped
  /// branch differs from the one it was formed with, when it is older than `max_matrix_age` steps,
  /// or when the iteration contracts by less than `max_contraction` per correction (θ_k = r_k /
  /// r_{k−1} of the scaled residuals) or is not expected to reach the tolerance within the
  /// iterations left (θ^(k_max − k)/(1 − θ) r_k above it, Hairer & Wanner §IV.8). Force evaluations
  /// skip the Jacobian terms while the kept matrix serves. A step that does not converge with a
  /// reused matrix is attempted again with a fresh one at every iteration (Newton's method) before
  /// it is split in halves. Both methods stop on the same residual test, so they agree to the
  /// tolerance. Ignored (exact) when `check_convergence` is false.
  NewtonMethod newton = NewtonMethod::simplified;
  /// NewtonMethod::simplified: a kept Newton matrix serves at most this many steps.
  int max_matrix_age = 64;
  /// NewtonMethod::simplified: largest accepted contraction θ of the residual per correction
  /// with a kept matrix (0 < θ < 1); a slower iteration forms the matrix again.
  Scalar max_contraction = Scalar(0.5);
  /// NewtonMethod::simplified: a kept matrix whose first correction of a step leaves a scaled
  /// residual above this fraction of the tolerance is formed anew at the next step (the residual
  /// it leaves grows with its age, and a second correction costs more than a new matrix). Above
  /// max(1, refresh_residual) × the tolerance (the kept matrix missed it), the following 1, 3, 7,
  /// … 31 steps form their own matrix before a kept one is tried again (TetherState::newton's
  /// pause: a line moving too fast for a matrix to serve the next step).
  Scalar refresh_residual = Scalar(0.5);
  /// Newton converges when max_i |R_i| / a_i ≤ acceleration_tolerance · dt, R_i the momentum
  /// residual of node i and a_i its isotropic mass: an error ΔF in the node force shows up as
  /// γ dt ΔF / a_i, so this bounds the node forces' error per unit mass [m/s²] whatever the step,
  /// and a smaller dt is never less accurate (a fixed velocity tolerance would let the error
  /// grow as dt shrinks). At least one Newton correction is always made, so the velocity
  /// predictor alone never makes a step. Default 1.5e-4 m/s² in double (1.5e-6 m/s at 10 ms, node
  /// forces to ~3e-6 N on the benchmark line); 0.1 m/s² in single precision, whose rounding of
  /// ~10 m coordinates already costs EA/l · 6e-7 m of tension (use a softer line or double for
  /// stiff tethers). The arithmetic resolves node forces only to the rounding of the positions
  /// (EA/l·ε|x| per segment, ε of Scalar): a tolerance below that resolution over the lightest
  /// node's mass is raised to it for the step (in float, a 1 m line of 2 segments at 10 m depth
  /// resolves ~16 m/s²), and one more than 1000 times below it is refused up front.
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
/// \tparam Scalar double or float.
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
  /// Newton matrices factored (block eliminations, one per active-set pass; failed attempts
  /// included; 0 for explicit schemes).
  int factorisations = 0;
  /// Newton corrections that reused a kept factorisation (NewtonMethod::simplified).
  int reused_factorisations = 0;
  /// Step attempts that turned to the whole Jacobian (JacobianKind::adaptive): within the
  /// attempt, when a symmetric matrix formed at the iterate contracted the residual by less than
  /// `max_contraction`, or after the symmetric attempts did not converge.
  int whole_jacobian_attempts = 0;
  /// Times the line parted (TetherParameters::breaking_strength; kelp/tether/failure.hpp).
  int partings = 0;
  /// The first parting of these steps (valid when partings > 0).
  LineFailure<Scalar> failure;

  /// \brief Adds another step's report: counts add up, the residual is the worst, the first
  /// parting is kept.
  /// \param o the report added.
  /// \return `*this`.
  StepReport& operator+=(const StepReport& o) {
    substeps += o.substeps;
    force_evaluations += o.force_evaluations;
    newton_iterations += o.newton_iterations;
    residual = std::max(residual, o.residual);
    retries += o.retries;
    rejected_residual = std::max(rejected_residual, o.rejected_residual);
    factorisations += o.factorisations;
    reused_factorisations += o.reused_factorisations;
    whole_jacobian_attempts += o.whole_jacobian_attempts;
    if (partings == 0 && o.partings > 0) failure = o.failure;
    partings += o.partings;
    return *this;
  }
};

namespace detail {

/// The arrays and constants of the implicit step's predictor (step_pass_body.hpp's
/// predict_pass: the mode and the formulas), the flat 3 × (N+1) arrays of `len` scalars.
template <typename Scalar>
struct PredictArrays {
  Eigen::Index len;
  int mode;
  Scalar four_thirds, third, gh, two_h;
  const Scalar *xn, *vn, *xp, *vp, *an;  ///< x_n, v_n, x_{n−1}, v_{n−1}, a_n
  Scalar *x0, *v0, *x1, *v1;             ///< out: x̂, v̂, the predicted x and v
};

/// The arrays and constants of the accelerations after an implicit step (step_pass_body.hpp's
/// acceleration_pass), the flat 3 × (N+1) arrays of `len` scalars, the free nodes' entries in
/// [free0, free1).
template <typename Scalar>
struct AccelerationArrays {
  Eigen::Index len, free0, free1;
  bool compare;  ///< compare the two predictors with the solution v
  Scalar inv_gh, two_h;
  const Scalar *vn, *vp, *an, *v0, *v;  ///< v_n, v_{n−1}, a_n, v̂, the solution
  Scalar* a_new;                        ///< out: the new accelerations
  Scalar lin{}, leap{};                 ///< out (compare): the squared distances
};

/// The segments of branches_are's packed check (step_pass_body.hpp's branch_pass): segments
/// [begin, end) of rest length `l`, none parted; their stretched lengths, clamped axial forces
/// and the branch codes to compare with (0 slack, 1 at rest, 2 taut).
template <typename Scalar>
struct BranchArrays {
  Eigen::Index begin, end;
  Scalar l, taut_from;  ///< the rest length; taut at and above `taut_from` when `banded`
  bool banded, clamp;   ///< a slack band; no axial force in compression
  const Scalar *stretched, *tension, *branch;
};

// The implicit steps' array passes (kelp/tether/step_pass_body.hpp): once for the build's own
// packets, and where kelp dispatches at run time once more for AVX2, chosen as the force passes
// are (force_passes_take_avx2). Doxygen does not read them (their namespaces are details).
#if !defined(KELP_DOXYGEN)
namespace step_baseline {
namespace vec = ::kelp::simd;
#define KELP_STEP_PASS_BODY 1
#include "kelp/tether/step_pass_body.hpp"  // IWYU pragma: keep
#undef KELP_STEP_PASS_BODY
}  // namespace step_baseline

#if defined(KELP_X86_DISPATCH)
KELP_AVX2_BEGIN
namespace step_avx2 {
namespace vec = ::kelp::simd::detail::avx2;
#define KELP_STEP_PASS_BODY 1
#include "kelp/tether/step_pass_body.hpp"  // IWYU pragma: keep
#undef KELP_STEP_PASS_BODY
}  // namespace step_avx2
KELP_AVX2_END
#endif
#endif  // KELP_DOXYGEN

/// The sum of the `len` scalars of each of the K arrays `p` (step_pass_body.hpp's flat_sum, on
/// AVX2 where the force passes take it): only its finiteness is meaningful, its bits depend on
/// the path.
template <int K, typename Scalar>
Scalar flat_sum(const Scalar* const (&p)[K], Eigen::Index len) {
#if defined(KELP_X86_DISPATCH)
  if constexpr (std::is_same_v<Scalar, double>)
    if (force_passes_take_avx2()) return step_avx2::flat_sum(p, len);
#endif
  return step_baseline::flat_sum(p, len);
}

/// step_pass_body.hpp's predict_all on AVX2 where the force passes take it (the same bits).
template <typename Scalar>
void predict_all(const PredictArrays<Scalar>& a) {
#if defined(KELP_X86_DISPATCH)
  if constexpr (std::is_same_v<Scalar, double>)
    if (force_passes_take_avx2()) return step_avx2::predict_all(a);
#endif
  step_baseline::predict_all(a);
}

/// step_pass_body.hpp's trial_all on AVX2 where the force passes take it (the same bits).
template <typename Scalar>
void trial_all(Eigen::Index begin, Eigen::Index end, Scalar alpha, Scalar gh, const Scalar* v1,
               const Scalar* delta, const Scalar* x0, Scalar* vs, Scalar* xs) {
#if defined(KELP_X86_DISPATCH)
  if constexpr (std::is_same_v<Scalar, double>)
    if (force_passes_take_avx2())
      return step_avx2::trial_all(begin, end, alpha, gh, v1, delta, x0, vs, xs);
#endif
  step_baseline::trial_all(begin, end, alpha, gh, v1, delta, x0, vs, xs);
}

/// step_pass_body.hpp's branches_all on AVX2 where the force passes take it (the same answer).
template <typename Scalar>
bool branches_all(const BranchArrays<Scalar>& a) {
#if defined(KELP_X86_DISPATCH)
  if constexpr (std::is_same_v<Scalar, double>)
    if (force_passes_take_avx2()) return step_avx2::branches_all(a);
#endif
  return step_baseline::branches_all(a);
}

/// step_pass_body.hpp's accelerations_all: on AVX2 where the force passes take it unless it
/// compares the predictors (its sums, on packets of another width, would round otherwise and
/// could choose otherwise on another CPU; the comparison runs in a few steps in a hundred).
template <typename Scalar>
void accelerations_all(AccelerationArrays<Scalar>& a) {
#if defined(KELP_X86_DISPATCH)
  if constexpr (std::is_same_v<Scalar, double>)
    if (!a.compare && force_passes_take_avx2()) return step_avx2::accelerations_all(a);
#endif
  step_baseline::accelerations_all(a);
}

/// True when the sum of every coordinate of x and v is finite: every one is, and their sum does
/// not overflow (the state's one-pass check; the named checks say which).
template <typename Scalar>
bool all_finite_fast(const Matrix3X<Scalar>& x, const Matrix3X<Scalar>& v) {
  using std::isfinite;
  if (x.size() != v.size())
    return isfinite(value_of(flat_sum({x.data()}, x.size()) + flat_sum({v.data()}, v.size())));
  return isfinite(value_of(flat_sum({x.data(), v.data()}, x.size())));
}

/// Commits (x, v) as the state at t + dt if finite; the state before the step becomes the
/// state's history (BDF2, velocity predictor). The kept Newton matrix is dropped (an implicit
/// step hands its own to the state after this).
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
  state.newton.clear();
  state.has_acceleration = false;  // an implicit step sets its own after this
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
  KELP_CHECK(o.jacobian == JacobianKind::symmetric || o.jacobian == JacobianKind::whole ||
                 o.jacobian == JacobianKind::adaptive,
             "ImplicitOptions::jacobian must be JacobianKind::symmetric, whole or adaptive");
  check_positive(o.acceleration_tolerance, "ImplicitOptions::acceleration_tolerance");
  check_non_negative(o.slack_band, "ImplicitOptions::slack_band");
  KELP_CHECK(o.max_active_set_passes >= 1, "ImplicitOptions::max_active_set_passes must be >= 1");
  KELP_CHECK(o.max_backtracks >= 0, "ImplicitOptions::max_backtracks must be >= 0");
  KELP_CHECK(o.max_step_halvings >= 0 && o.max_step_halvings <= 30,
             "ImplicitOptions::max_step_halvings must be in [0, 30]");
  KELP_CHECK(o.newton == NewtonMethod::exact || o.newton == NewtonMethod::simplified,
             "ImplicitOptions::newton must be NewtonMethod::exact or NewtonMethod::simplified");
  KELP_CHECK(o.max_matrix_age >= 1, "ImplicitOptions::max_matrix_age must be >= 1");
  KELP_CHECK(o.max_contraction > Scalar(0) && o.max_contraction < Scalar(1),
             "ImplicitOptions::max_contraction must be in (0, 1)");
  check_non_negative(o.refresh_residual, "ImplicitOptions::refresh_residual");
}

/// Checks a step's inputs, then gives a state whose history buffers do not fit the model (a
/// state assembled by hand) fitting ones and no history: nothing is changed unless all checks
/// pass.
template <typename Scalar>
void check_step_inputs(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                       TetherState<Scalar>& state, const TetherBoundary<Scalar>& b, double dt) {
  check_positive(dt, "dt");
  check_workspace(model, ws);
  // Segment 0's rest length at a winch (kelp/tether/winch.hpp): 0, or at least 1 % of l.
  if (!(state.winch_length == Scalar(0) ||
        (is_finite(state.winch_length) &&
         state.winch_length >= Scalar(0.01) * model.segment_length() &&
         state.winch_length <= limits::max_length)))
    ::kelp::detail::throw_invalid_argument(
        "state.winch_length must be 0 (no winch) or in [0.01 l, limits::max_length]");
  // The winch's payout rate, which advance_winch() reads after this step in system::step and a
  // fleet's: finite (as check_state requires), so that a coupled step refuses a bad one before
  // it changes anything.
  check_finite(state.payout_rate, "state.payout_rate");
  ws.winch_length = state.winch_length;
  KELP_CHECK(state.position.cols() == model.nodes() && state.velocity.cols() == model.nodes(),
             "state.position and state.velocity must have segments + 1 columns");
  check_boundary(b);
  const bool history_fits = state.previous_position.cols() == model.nodes() &&
                            state.previous_velocity.cols() == model.nodes();
  const bool acceleration_fits = state.acceleration.cols() == model.nodes();
  // The accelerations count where a step can use them: with the history they extrapolate.
  const bool acceleration_used =
      acceleration_fits && state.has_acceleration && history_fits && state.has_history();
  // One pass over the state; the named checks run only to build the message.
  if (!(all_finite_fast(state.position, state.velocity) && std::isfinite(state.time) &&
        state.previous_dt >= 0.0 &&
        (!history_fits || !state.has_history() ||
         all_finite_fast(state.previous_position, state.previous_velocity)) &&
        (!acceleration_used || std::isfinite(value_of(flat_sum({state.acceleration.data()},
                                                               state.acceleration.size())))))) {
    check_all_finite(state.position, "state.position");
    check_all_finite(state.velocity, "state.velocity");
    check_finite(state.time, "state.time");
    check_non_negative(state.previous_dt, "state.previous_dt");
    if (history_fits) {
      check_all_finite(state.previous_position, "state.previous_position");
      check_all_finite(state.previous_velocity, "state.previous_velocity");
    }
    if (acceleration_used) check_all_finite(state.acceleration, "state.acceleration");
    ::kelp::detail::throw_invalid_argument("state: the sum of its coordinates overflows");
  }
  if (!history_fits) {
    state.previous_position.setZero(3, model.nodes());
    state.previous_velocity.setZero(3, model.nodes());
    state.previous_dt = 0.0;
  }
  if (!acceleration_fits) {
    state.acceleration.setZero(3, model.nodes());
    state.has_acceleration = false;
  }
  KELP_CHECK(state.parted.size() == 0 || state.parted.size() == model.segments(),
             "state.parted must be empty or have one flag per segment");
  if (state.newton.factor.size() != newton_factor_size(model.nodes()) ||
      state.newton.branch.size() != model.segments())
    state.newton.resize(model.nodes());
}

/// `x` in %g format, for error messages.
inline std::string format_g(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", x);
  return buf;
}

/// Rounding [N] of a segment's axial force in the arithmetic of Scalar: positions of magnitude
/// |x| are rounded to ε|x| (ε of Scalar: 1.2e-7 in float, 2.2e-16 in double), which rounds each
/// segment's axial force EA/l·Δl by about EA/l·ε|x|. |x| is bounded by the end nodes' distance
/// from the origin plus the line's length. O(1).
template <typename Scalar>
double axial_force_rounding(const TetherModel<Scalar>& model, const TetherState<Scalar>& state,
                            double& reach) {
  const int n = model.segments();
  reach = std::max(double(value_of(state.position.col(0).norm())),
                   double(value_of(state.position.col(n).norm()))) +
          double(value_of(model.parameters().length));
  return double(value_of(model.axial_spring())) *
         double(value_of(std::numeric_limits<Scalar>::epsilon())) * reach;
}

/// The acceleration [m/s²] to which Newton's method can resolve the node forces: the axial
/// force rounding (axial_force_rounding) over the lightest node's mass. A residual below it is
/// noise, which no iteration reduces.
template <typename Scalar>
Scalar force_resolution(const TetherModel<Scalar>& model, const TetherState<Scalar>& state) {
  double reach;
  const double rounding = axial_force_rounding(model, state, reach);
  return Scalar(rounding / double(value_of(model.min_node_mass())));
}

/// Refuses a Newton tolerance that the arithmetic cannot resolve: when the axial force rounding
/// (axial_force_rounding) is above a thousand times the tolerance a_min·acceleration_tolerance on
/// the lightest node, no step can converge (e.g. a 1 cm line cut into 200 segments: EA/l = 2e9 N/m
/// at 5 m depth rounds the force to 2e-6 N against a tolerance of 3e-10 N in double; a 1 m float
/// line cut into 200 segments rounds it to ~30 N against 2e-5 N). Below that, the implicit steps
/// raises the tolerance to the resolution (force_resolution). O(1).
/// \throws kelp::invalid_argument saying what to change.
template <typename Scalar>
void check_resolvable(const TetherModel<Scalar>& model, const TetherState<Scalar>& state,
                      const ImplicitOptions<Scalar>& options) {
  double reach;
  const double rounding = axial_force_rounding(model, state, reach);
  const double tolerance =
      double(value_of(model.min_node_mass())) * double(value_of(options.acceleration_tolerance));
  if (rounding > 1000.0 * tolerance)
    ::kelp::detail::throw_invalid_argument(
        std::string("step_implicit: this tether cannot be resolved to the Newton tolerance in ") +
        (std::is_same_v<Scalar, float> ? "single" : "double") + " precision: segments of " +
        format_g(double(value_of(model.segment_length()))) + " m (EA/l = " +
        format_g(double(value_of(model.axial_spring()))) + " N/m) at coordinates up to " +
        format_g(reach) + " m round the axial force to ~" + format_g(rounding) +
        " N, over 1000 times the tolerance of the lightest node (" + format_g(tolerance) +
        " N); use fewer, longer segments, coordinates nearer the origin, a larger "
        "ImplicitOptions::acceleration_tolerance" +
        (std::is_same_v<Scalar, float> ? ", or double precision" : ""));
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
  load_parted(state, ws);
  load_clamps(model, boundary, ws);
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

using StepReportd = StepReport<double>;            ///< StepReport<double>
using StepReportf = StepReport<float>;             ///< StepReport<float>
using ImplicitOptionsd = ImplicitOptions<double>;  ///< ImplicitOptions<double>
using ImplicitOptionsf = ImplicitOptions<float>;   ///< ImplicitOptions<float>

}  // namespace kelp::tether
