/// \file
/// \brief The Ceres solve of the paper's two catenary equations for (a, c) (target kelp::ceres).
///
/// Ceres' `TinySolver` (Levenberg–Marquardt on a fixed-size 2×2 problem, header-only, no heap) with
/// `TinySolverAutoDiffFunction` solves the paper's residuals exactly as written,
/// \f[ R_1 = a[\cosh((D-c)/a) - \cosh(c/a)] - \Delta z, \qquad
///     R_2 = a[\sinh((D-c)/a) + \sinh(c/a)] - L, \f]
/// warm-started from the fast analytic path (kelp/tether/catenary.hpp) by default or from a
/// caller's guess (e.g. the previous control step). Geometry statuses (taut, vertical, invalid
/// input) are decided exactly as on the fast path. This is the only kelp directory that includes
/// Ceres.
///
/// The namespace is `kelp::ceres_solver` (header path and CMake target stay `kelp/ceres/...` and
/// `kelp::ceres`): a namespace named `kelp::ceres` would hide the global namespace of Ceres from
/// any code inside `namespace kelp` (user code included), so that `ceres::Jet<double, N>` written
/// there would not find Ceres' type.
#pragma once

#include <cmath>
#include <limits>
#include <type_traits>

#include <ceres/jet.h>
#include <ceres/tiny_solver.h>
#include <ceres/tiny_solver_autodiff_function.h>

#include "kelp/core/scalar.hpp"
#include "kelp/tether/catenary.hpp"

namespace kelp {
/// \brief The Ceres-based solvers (target `kelp::ceres`, headers under `kelp/ceres/`).
namespace ceres_solver {

using tether::CatenaryOptions;
using tether::CatenaryResult;
using tether::CatenaryStatus;

/// \brief The paper's two catenary equations as a Ceres cost functor over x = (a, c).
///
/// Templated on the parameter type so that Ceres can differentiate it (autodiff). A non-positive
/// a (outside the model) gives infinite residuals, which makes the Levenberg–Marquardt step be
/// rejected.
struct CatenaryResidual {
  double D = 0.0;   ///< horizontal distance [m]
  double dz = 0.0;  ///< z_end − z_start, z up [m]
  double L = 0.0;   ///< tether length [m]

  /// \brief Number of residuals and parameters (for ceres::TinySolverAutoDiffFunction).
  enum { NUM_RESIDUALS = 2, NUM_PARAMETERS = 2 };

  /// \brief r = (R1, R2) [m] at x = (a, c) [m].
  /// \tparam T double or a ceres::Jet. \param x (a, c) [m]. \param r the residuals [m], written.
  /// \return true (Ceres' convention: the residuals were computed).
  template <typename T>
  bool operator()(const T* x, T* r) const {
    using std::cosh;
    using std::sinh;
    const T& a = x[0];
    const T& c = x[1];
    if (!(a > T(0.0))) {
      r[0] = r[1] = T(std::numeric_limits<double>::infinity());
      return true;
    }
    r[0] = a * (cosh((T(D) - c) / a) - cosh(c / a)) - T(dz);
    r[1] = a * (sinh((T(D) - c) / a) + sinh(c / a)) - T(L);
    return true;
  }
};

/// \brief A reusable Ceres catenary solver: keeps the TinySolver (its preallocated matrices and
/// factorisation) and the last solution, so a control loop can warm-start each call from the
/// previous one.
///
/// Not thread-safe (one instance per thread). No heap allocation per solve.
class CatenarySolver {
 public:
  /// \brief The residual with its automatic derivatives, as TinySolver wants it.
  using Function = ::ceres::TinySolverAutoDiffFunction<CatenaryResidual, 2, 2>;
  /// \brief Ceres' small dense Levenberg–Marquardt solver over Function.
  using Solver = ::ceres::TinySolver<Function>;
  /// \brief The unknowns (a, c) [m].
  using Parameters = Eigen::Vector2d;

  EIGEN_MAKE_ALIGNED_OPERATOR_NEW

  CatenarySolver() : function_(residual_) {}
  CatenarySolver(const CatenarySolver&) = delete;
  CatenarySolver& operator=(const CatenarySolver&) = delete;

  /// \brief Solves from the fast analytic path's solution (the default warm start).
  /// \tparam Scalar double, float or `ceres::Jet<double, N>` (derivatives by the implicit
  ///   function theorem on the paper's equations).
  /// \param[in] D horizontal distance [m], ≥ 0.
  /// \param[in] dz z_end − z_start, z up [m].
  /// \param[in] L tether length [m], > 0.
  /// \param[in] options the Ceres path uses max_iterations, residual_tolerance, target_residual
  ///   and vertical_tolerance (and tolerance for the fast-path start).
  /// \return the status (converged, taut, vertical, invalid_input or max_iterations: never throws)
  /// with a and c [m], the iterations, the relative residual and, taut, the tension [N].
  template <typename Scalar>
  CatenaryResult<Scalar> solve(Scalar D, Scalar dz, Scalar L,
                               const CatenaryOptions<Scalar>& options = {}) {
    CatenaryResult<Scalar> result;
    restarted_ = false;
    if (!classify(D, dz, L, options, result)) return result;
    const auto fast =
        tether::solve_catenary(value_of(D), value_of(dz), value_of(L), plain_options(options));
    return run(D, dz, L, Parameters(fast.a, fast.c), options);
  }

  /// \brief Solves from a caller's guess (a0, c0) [m], e.g. the previous control step's solution.
  ///
  /// An unusable guess (a0 ≤ 0 or non-finite) starts from the fast path instead. When Ceres does
  /// not reach options.residual_tolerance from the guess — it happens within ~1e-3 of taut, where
  /// the (a, c) problem is badly conditioned — and options.restart_from_fast_path is set (default),
  /// the solve is repeated from the fast path's solution; restarted() tells, and `iterations`
  /// counts both runs.
  /// \tparam Scalar as solve(D, dz, L, options).
  /// \param[in] D horizontal distance [m], ≥ 0. \param[in] dz z_end − z_start, z up [m].
  /// \param[in] L tether length [m], > 0. \param[in] a0 guess of a [m]. \param[in] c0 guess of c
  /// [m]. \param[in] options as solve(D, dz, L, options).
  /// \return the status (converged, taut, vertical, invalid_input or max_iterations: never throws)
  /// with a and c [m], the iterations, the relative residual and, taut, the tension [N].
  template <typename Scalar>
  CatenaryResult<Scalar> solve(Scalar D, Scalar dz, Scalar L, double a0, double c0,
                               const CatenaryOptions<Scalar>& options = {}) {
    CatenaryResult<Scalar> result;
    restarted_ = false;
    if (!classify(D, dz, L, options, result)) return result;
    if (!(std::isfinite(a0) && std::isfinite(c0) && a0 > 0.0)) return solve(D, dz, L, options);
    result = run(D, dz, L, Parameters(a0, c0), options);
    if (result.status == CatenaryStatus::converged || !options.restart_from_fast_path)
      return result;
    const int first_run = result.iterations;
    result = solve(D, dz, L, options);
    result.iterations += first_run;
    restarted_ = true;
    return result;
  }

  /// \brief True when the last solve from a caller's guess had to restart from the fast path.
  /// \return whether it restarted.
  bool restarted() const { return restarted_; }

  /// \brief Solves warm-started from this solver's previous converged solution (the fast path on
  /// the first call or after a failure).
  /// \tparam Scalar as solve(D, dz, L, options).
  /// \param[in] D horizontal distance [m], ≥ 0. \param[in] dz z_end − z_start, z up [m].
  /// \param[in] L tether length [m], > 0. \param[in] options as solve(D, dz, L, options).
  /// \return the status (converged, taut, vertical, invalid_input or max_iterations: never throws)
  /// with a and c [m], the iterations, the relative residual and, taut, the tension [N].
  template <typename Scalar>
  CatenaryResult<Scalar> solve_from_previous(Scalar D, Scalar dz, Scalar L,
                                             const CatenaryOptions<Scalar>& options = {}) {
    if (has_previous_) return solve(D, dz, L, previous_.x(), previous_.y(), options);
    return solve(D, dz, L, options);
  }

  /// \brief Ceres' summary of the last solve (iterations, costs, termination reason).
  /// \return a reference valid until the next solve.
  const Solver::Summary& summary() const { return solver_.summary; }

 private:
  template <typename Scalar>
  static CatenaryOptions<double> plain_options(const CatenaryOptions<Scalar>& o) {
    CatenaryOptions<double> p;
    p.tolerance = o.tolerance;
    p.max_iterations = o.max_iterations;
    p.vertical_tolerance = o.vertical_tolerance;
    return p;
  }

  /// Taut / vertical / invalid geometry exactly as on the fast path; true when a solve is needed.
  template <typename Scalar>
  bool classify(const Scalar& D, const Scalar& dz, const Scalar& L,
                const CatenaryOptions<Scalar>& options, CatenaryResult<Scalar>& result) {
    double excess = 0.0;
    const CatenaryStatus kind =
        tether::detail::classify_catenary(value_of(D), value_of(dz), value_of(L), options, excess);
    if (kind == CatenaryStatus::converged) return true;
    tether::detail::fill_unsolved(kind, D, dz, L, options, result);
    has_previous_ = false;
    return false;
  }

  template <typename Scalar>
  CatenaryResult<Scalar> run(const Scalar& D, const Scalar& dz, const Scalar& L, Parameters x,
                             const CatenaryOptions<Scalar>& options) {
    const double Dd = value_of(D), dzd = value_of(dz), Ld = value_of(L);
    residual_.D = Dd;
    residual_.dz = dzd;
    residual_.L = Ld;
    auto& so = solver_.options;
    so.max_num_iterations = options.max_iterations + 1;  // TinySolver counts from 1
    so.gradient_tolerance = 0.0;
    so.function_tolerance = 0.0;
    so.parameter_tolerance = 1e-15;
    const double target = options.target_residual * Ld;
    so.cost_threshold = 0.5 * target * target;
    solver_.Solve(function_, &x);

    CatenaryResult<Scalar> result;
    result.iterations = solver_.summary.iterations;
    const double res = tether::detail::paper_residual(x.x(), x.y(), Dd, dzd, Ld);
    result.status = res <= options.residual_tolerance ? CatenaryStatus::converged
                                                      : CatenaryStatus::max_iterations;
    if constexpr (std::is_arithmetic_v<Scalar>) {
      result.a = static_cast<Scalar>(x.x());
      result.c = static_cast<Scalar>(x.y());
    } else {
      implicit_derivatives(x, D, dz, L, result);
    }
    result.residual =
        Scalar(tether::detail::paper_residual(value_of(result.a), value_of(result.c), Dd, dzd, Ld));
    has_previous_ = result.status == CatenaryStatus::converged;
    if (has_previous_) previous_ = x;
    return result;
  }

  /// (a, c) with derivative parts from the implicit function theorem on R(a, c; D, dz, L) = 0:
  /// d(a, c) = −J⁻¹ ∂R/∂(D, dz, L) d(D, dz, L), J = ∂R/∂(a, c) evaluated analytically in double.
  template <typename Scalar>
  static void implicit_derivatives(const Parameters& x, const Scalar& D, const Scalar& dz,
                                   const Scalar& L, CatenaryResult<Scalar>& result) {
    using std::cosh;
    using std::sinh;
    const double a = x.x(), c = x.y();
    const double p = (value_of(D) - c) / a, q = c / a;
    const double ch_p = std::cosh(p), sh_p = std::sinh(p), ch_q = std::cosh(q), sh_q = std::sinh(q);
    const double j11 = ch_p - ch_q - p * sh_p + q * sh_q;  // ∂R1/∂a
    const double j12 = -sh_p - sh_q;                       // ∂R1/∂c
    const double j21 = sh_p + sh_q - p * ch_p - q * ch_q;  // ∂R2/∂a
    const double j22 = -ch_p + ch_q;                       // ∂R2/∂c
    const double det = j11 * j22 - j12 * j21;
    // The residuals at the fixed (a, c) carry ∂R/∂(D, dz, L)·d(D, dz, L) in their derivative
    // parts; their value parts are the (tiny) residuals themselves.
    const Scalar as(a), cs(c);
    const Scalar r1 = as * (cosh((D - cs) / as) - cosh(cs / as)) - dz;
    const Scalar r2 = as * (sinh((D - cs) / as) + sinh(cs / as)) - L;
    // Newton step with the double Jacobian: value part ~ 0, derivative part = −J⁻¹ dR.
    result.a = as - (j22 * r1 - j12 * r2) / det;
    result.c = cs - (-j21 * r1 + j11 * r2) / det;
    // Keep the value parts exactly those of the Ceres solution.
    result.a.a = a;
    result.c.a = c;
  }

  CatenaryResidual residual_{};
  Function function_;
  Solver solver_{};
  Parameters previous_ = Parameters::Zero();
  bool has_previous_ = false;
  bool restarted_ = false;
};

/// \brief Solves the paper's catenary equations for a and c with Ceres, warm-started from the fast
/// analytic path.
///
/// Same statuses and result as tether::solve_catenary(): taut, vertical and invalid input are
/// classified identically; converged means max(|R1|, |R2|)/L ≤ options.residual_tolerance.
/// \tparam Scalar double, float or `ceres::Jet<double, N>`.
/// \param[in] D horizontal distance between the ends [m], ≥ 0.
/// \param[in] dz z_end − z_start with z up [m].
/// \param[in] L tether length [m], > 0.
/// \param[in] options tolerances and limits; the Ceres path uses max_iterations, residual_tolerance
/// and target_residual.
/// \return the status (converged, taut, vertical, invalid_input or max_iterations: never throws)
/// with a and c [m], the iterations, the relative residual and, taut, the tension [N].
template <typename Scalar>
CatenaryResult<Scalar> solve_catenary(Scalar D, Scalar dz, Scalar L,
                                      const CatenaryOptions<Scalar>& options = {}) {
  CatenarySolver solver;
  return solver.solve(D, dz, L, options);
}

/// \brief As above, from a caller's guess (a0, c0) [m] (e.g. the previous control step).
/// \tparam Scalar double, float or `ceres::Jet<double, N>`.
/// \param[in] D horizontal distance [m], ≥ 0. \param[in] dz z_end − z_start, z up [m].
/// \param[in] L tether length [m], > 0. \param[in] a0 guess of a [m]. \param[in] c0 guess of c [m].
/// \param[in] options as solve_catenary(D, dz, L, options).
/// \return the status (converged, taut, vertical, invalid_input or max_iterations: never throws)
/// with a and c [m], the iterations, the relative residual and, taut, the tension [N].
template <typename Scalar>
CatenaryResult<Scalar> solve_catenary(Scalar D, Scalar dz, Scalar L, double a0, double c0,
                                      const CatenaryOptions<Scalar>& options = {}) {
  CatenarySolver solver;
  return solver.solve(D, dz, L, a0, c0, options);
}

}  // namespace ceres_solver
}  // namespace kelp
