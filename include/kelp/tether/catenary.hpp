/// \file
/// \brief The elastic-free catenary between two tether ends: a fast analytic solver for the paper's
/// two equations, physical statuses instead of exceptions, and a 3-D helper (shape, lowest point,
/// tensions) in world NED.
///
/// **The paper's plane.** x is horizontal from the start (ASV) end, z points up; D ≥ 0 is the
/// horizontal distance between the ends, Δz = z_end − z_start and L the tether length. The shape is
/// \f$ z(x) = a\cosh((x-c)/a) - a\cosh(c/a) \f$ with a, c from
/// \f[ a[\cosh((D-c)/a) - \cosh(c/a)] = \Delta z, \qquad a[\sinh((D-c)/a) + \sinh(c/a)] = L. \f]
/// Subtracting the squares gives \f$ \sqrt{L^2 - \Delta z^2} = 2a\sinh(D/(2a)) \f$ and dividing
/// them \f$ \Delta z / L = \tanh((D-2c)/(2a)) \f$, so with \f$ u = D/(2a) \f$ the problem is the
/// 1-D equation \f$ \sinh(u)/u = \sqrt{L^2-\Delta z^2}/D \f$ and
/// \f$ c = D/2 - a\,\mathrm{atanh}(\Delta z/L) \f$ (derivation in docs/equations.md).
///
/// **How it is solved.** The 1-D equation is solved in its logarithmic form
/// \f$ h(u) = \ln(\sinh(u)/u) = \lambda \f$, which never overflows and keeps full relative
/// precision near taut (u → 0, where h ≈ u²/6) and for very slack lines (h ≈ u − ln 2u). The target
/// λ comes from L² − Δz² − D² evaluated with error-free products, so lines within 1e-9 of taut keep
/// their digits. The initial guess (a fitted rational approximation, asymptotic form for large λ)
/// is within 1e-7 of the root, so one safeguarded Halley step (h is increasing and convex) reaches
/// full precision; c = D/2 − a·atanh(Δz/L) takes atanh from L ± Δz directly. The work is done in
/// double for every Scalar; for automatic-differentiation scalars (`ceres::Jet`) the derivative
/// parts of a and c are added by the implicit function theorem (du/dλ = 1/h'(u)), so no derivative
/// is taken through the iterations. Measured: ~0.1 µs per solve (benchmarks/results/catenary.md);
/// the paper's residuals stay below 1e-14·L over 2e5 random geometries (tests/catenary).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include <Eigen/Core>

#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"

namespace kelp {
namespace tether {

/// \brief Outcome of a catenary solve. Physically possible geometry never throws; it is reported
/// here.
enum class CatenaryStatus {
  converged,  ///< Slack line: a, c solve the paper's two equations.
  taut,       ///< L ≤ chord: the line is straight (stretched when L < chord); a = +∞, c = NaN.
  vertical,   ///< D ≤ vertical_tolerance·L: the ends are vertically aligned; a = 0, c = 0.
  invalid_input,   ///< NaN or ±Inf input, D < 0, L or a length outside the range of
                   ///< tether::limits (L in [1e-6, 1e9] m, D and |Δz| ≤ 1e9 m), unusable options
                   ///< (a tolerance not finite and ≥ 0, max_iterations < 1, a negative
                   ///< vertical_tolerance, EA not finite in [0, 1e15] N, a NaN seabed_depth);
                   ///< 3-D helper: also |w| not finite and ≤ 1e9 N/m, or an end below
                   ///< options.seabed_depth.
  max_iterations,  ///< The iteration limit was hit; a, c hold the last iterate (3-D helper: the
                   ///< shape, H = a·|w|, end forces and tensions all describe that iterate).
};

/// \brief A short lower-case name of a status ("converged", "taut", ...), for logs and messages.
/// \param status the status.
/// \return its name as spelled in the enum, a string literal ("unknown" outside the enum).
inline const char* to_string(CatenaryStatus status) {
  switch (status) {
    case CatenaryStatus::converged:
      return "converged";
    case CatenaryStatus::taut:
      return "taut";
    case CatenaryStatus::vertical:
      return "vertical";
    case CatenaryStatus::invalid_input:
      return "invalid_input";
    case CatenaryStatus::max_iterations:
      return "max_iterations";
  }
  return "unknown";
}

/// \brief Ranges of the catenary solvers' inputs (outside them: CatenaryStatus::invalid_input).
/// Far beyond any tether (kilometres, kilonewtons per metre), they keep every product of the
/// solve (L², a·w, EA·strain) finite.
namespace limits {
inline constexpr double min_catenary_length = 1e-6;  ///< L [m]
inline constexpr double max_catenary_length = 1e9;   ///< L, D, |Δz| [m]
inline constexpr double max_catenary_weight = 1e9;   ///< |w| [N/m]
inline constexpr double max_catenary_EA = 1e15;      ///< EA [N]
}  // namespace limits

/// \brief Controls of the catenary solvers (the fast path here and
/// `kelp::ceres_solver::solve_catenary`). \tparam Scalar double, float or `ceres::Jet` (EA may
/// carry derivative parts).
template <typename Scalar>
struct CatenaryOptions {
  /// Target relative accuracy of u = D/(2a) (dimensionless): the 1-D solve stops after a step δ
  /// with |δ/u|³ ≤ tolerance (Halley step) or (δ/u)² ≤ tolerance (Newton step), the orders of the
  /// error left after such a step.
  double tolerance = 1e-14;
  /// Iteration limit of the 1-D solve (the Ceres path uses it as its own iteration limit).
  int max_iterations = 30;
  /// Ends closer horizontally than `vertical_tolerance`·L are treated as vertically aligned
  /// (status `vertical`). Must be ≥ 0 (else invalid_input); the default keeps D/L = 1e-6 on the
  /// regular path. Values below √(smallest normal) of the scalar (1.5e-154 in double, 1.1e-19 in
  /// float) act as that floor, below which the solve's numbers overflow or underflow.
  double vertical_tolerance = 1e-12;
  /// Axial stiffness EA [N] used only for the tension of a taut (stretched) line:
  /// T = EA·(chord − L)/L. 0 (the default) means inextensible: a taut line then reports T = 0
  /// because statics alone cannot determine it.
  Scalar EA = Scalar(0);
  /// 3-D helper only (CatenaryShape): NED z [m] of a flat, frictionless seabed (positive depth);
  /// +∞ (the default) means no seabed. See CatenaryShape for the grounded shapes.
  double seabed_depth = std::numeric_limits<double>::infinity();
  /// Ceres path only (kelp/ceres/catenary_solver.hpp): the solution is accepted (status converged)
  /// when max(|R1|, |R2|)/L ≤ residual_tolerance, otherwise the status is max_iterations. The
  /// default leaves a margin under the required 1e-10 for the double evaluation of the residual
  /// itself (≈ 1e-12 near taut).
  double residual_tolerance = 1e-11;
  /// Ceres path only: Levenberg–Marquardt stops once max |R_i| is about target_residual·L
  /// (0.5‖R‖² < 0.5 (target_residual·L)²).
  double target_residual = 1e-14;
  /// Ceres path only: when the solve from a caller's guess does not reach residual_tolerance,
  /// repeat it from the fast path's solution (so that the Ceres path always answers).
  bool restart_from_fast_path = true;
};

/// \brief Result of a catenary solve in the paper's plane (x horizontal from the start, z up).
/// \tparam Scalar double, float or `ceres::Jet`.
template <typename Scalar>
struct CatenaryResult {
  /// Catenary parameter a = H/w [m]: the radius of curvature at the vertex. +∞ when taut, 0 when
  /// vertical, NaN when invalid.
  Scalar a = Scalar(std::numeric_limits<double>::quiet_NaN());
  /// Horizontal position of the vertex from the start end [m]; may lie outside [0, D] (then the
  /// vertex is on the virtual extension of the cable). NaN when taut or invalid, 0 when vertical.
  Scalar c = Scalar(std::numeric_limits<double>::quiet_NaN());
  /// What happened; see CatenaryStatus.
  CatenaryStatus status = CatenaryStatus::invalid_input;
  /// Iterations used by the solver (0 for taut, vertical and invalid input).
  int iterations = 0;
  /// max(|R1|, |R2|)/L with R1, R2 the paper's two equations written as residuals and evaluated in
  /// double at the returned a, c (dimensionless). 0 for taut and vertical, NaN for invalid input.
  Scalar residual = Scalar(std::numeric_limits<double>::quiet_NaN());
  /// Axial tension of a taut line, EA·(chord − L)/L [N] (0 when not taut or EA = 0).
  Scalar taut_tension = Scalar(0);

  /// \brief True when a, c describe the line (converged or vertical).
  /// \return false for taut (a straight line: no a, c), invalid_input and max_iterations.
  bool ok() const {
    return status == CatenaryStatus::converged || status == CatenaryStatus::vertical;
  }
};

namespace detail {

/// h(u) = ln(sinh(u)/u) and its first two derivatives, for u > 0.
struct LogSinhc {
  double h;   ///< ln(sinh(u)/u)
  double d1;  ///< h'(u) = coth(u) − 1/u (the Langevin function)
  double d2;  ///< h''(u) = 1/u² − 1/sinh²(u)
};

/// Taylor series of the Langevin function coth(u) − 1/u = u/3 − u³/45 + 2u⁵/945 − u⁷/4725 +
/// 2u⁹/93555 (next term −1382u¹¹/638512875: relative truncation error ~6e-12 at u = 0.25, ~6e-9
/// at u = 0.5). The one place both h' evaluations below take it from.
inline double langevin_series(double u) {
  const double v = u * u;
  return u * (1.0 / 3.0 +
              v * (-1.0 / 45.0 + v * (2.0 / 945.0 + v * (-1.0 / 4725.0 + v * (2.0 / 93555.0)))));
}

/// Evaluates h, h', h'' with full relative precision and without overflow at the cost of one
/// transcendental call below u = 0.5 (Taylor series of sinh(u)/u − 1, then log1p) and two above
/// (E = e^{−2u}: h = u + ln((1 − E)/(2u)), coth u = (1 + E)/(1 − E), sinh⁻² u = 4E/(1 − E)²).
inline LogSinhc eval_log_sinhc(double u) {
  LogSinhc out;
  if (u < 0.5) {
    const double v = u * u;
    // sinh(u)/u − 1 = Σ u^{2k}/(2k+1)!, truncated where the next term is < 1e-16 relative.
    const double sm1 =
        v * (1.0 / 6.0 + v * (1.0 / 120.0 +
                              v * (1.0 / 5040.0 + v * (1.0 / 362880.0 + v * (1.0 / 39916800.0 +
                                                                             v / 6227020800.0)))));
    out.h = std::log1p(sm1);
    out.d1 = langevin_series(u);  // ~6e-9 relative at u = 0.5: used for the step only
    out.d2 = 1.0 / 3.0 +
             v * (-1.0 / 15.0 + v * (2.0 / 189.0 + v * (-7.0 / 4725.0 + v * (18.0 / 93555.0))));
    return out;
  }
  const double E = std::exp(-2.0 * u);
  const double om = 1.0 - E;
  const double inv_u = 1.0 / u, inv_om = 1.0 / om;
  out.h = u + std::log(0.5 * om * inv_u);
  out.d1 = (1.0 + E) * inv_om - inv_u;
  out.d2 = inv_u * inv_u - 4.0 * E * inv_om * inv_om;
  return out;
}

/// h'(u) = coth(u) − 1/u to ~1e-11 relative or better (series below 0.25); used for the
/// implicit-function derivatives.
inline double log_sinhc_d1(double u) {
  if (u < 0.25) return langevin_series(u);
  return 1.0 / std::tanh(u) - 1.0 / u;
}

/// Initial guess of u for h(u) = λ, relative error < 1e-7 for every λ > 0, so that a single Halley
/// step reaches full precision.
///
/// λ ≤ 12 (√(L²−Δz²)/D up to 1.6e5): u² = 6λ·P(λ)/Q(λ), a [4/3] rational approximation of u²/(6λ)
/// fitted for kelp by iteratively reweighted (Sanathanan–Koerner) least squares to 4000 accurate
/// roots on [0, 12]; worst relative error of u 9.2e-8. It keeps the small-λ series
/// u² = 6λ(1 + λ/5 + ...) of h = u²/6 − u⁴/180 + ... (p1 − q1 = 1/5). λ > 12: h ≈ u − ln(2u)
/// (the neglected ln(1 − e^{−2u}) is < 1e-10), two Newton steps on it from v = λ + ln(2λ).
inline double log_sinhc_inverse_guess(double lambda) {
  if (lambda <= 12.0) {
    const double l = lambda;
    const double p =
        1.0 +
        l * (0.59460288262227212 +
             l * (0.17375041519214407 + l * (0.021532368471375008 + l * 0.00062716085099966557)));
    const double q =
        1.0 + l * (0.39459930367774465 + l * (0.09104145478205436 + l * 0.0036853656887719656));
    return std::sqrt(6.0 * l * p / q);
  }
  double u = lambda + std::log(2.0 * lambda);
  u -= (u - std::log(2.0 * u) - lambda) / (1.0 - 1.0 / u);
  u -= (u - std::log(2.0 * u) - lambda) / (1.0 - 1.0 / u);
  return u;
}

/// Result of the double-precision 1-D solve.
struct ReducedSolution {
  double u = 0.0;       ///< D/(2a)
  double lambda = 0.0;  ///< ln(√(L²−Δz²)/D)
  int iterations = 0;
  bool converged = false;
};

/// L² − Δz² − D² (= L² − chord², > 0 exactly when the line is slack) with error-free products
/// (fma) and two-sums, so that it keeps its relative precision when L is within 1e-9 of the chord:
/// a plain evaluation loses all digits there, and so does (L − chord)(L + chord) because the
/// rounded chord carries an error of eps·chord.
inline double slack_excess(double D, double dz, double L) {
  const double p1 = L * L, e1 = std::fma(L, L, -p1);
  const double p2 = dz * dz, e2 = std::fma(dz, dz, -p2);
  const double p3 = D * D, e3 = std::fma(D, D, -p3);
  // Knuth's two-sum: s + t == x + y exactly.
  const auto two_sum = [](double x, double y, double& t) {
    const double s = x + y;
    const double yy = s - x;
    t = (x - (s - yy)) + (y - yy);
    return s;
  };
  double t1 = 0.0, t2 = 0.0;
  const double s1 = two_sum(p1, -p2, t1);
  const double s2 = two_sum(s1, -p3, t2);
  return s2 + (((t1 + t2) + e1) - e2 - e3);
}

/// λ = ln(√(L²−Δz²)/D) = log1p(ρ) with ρ = E/(D(√(D²+E) + D)), E = L² − Δz² − D² (no cancellation
/// near taut).
inline double reduced_target(double D, double excess) {
  return std::log1p(excess / (D * (std::sqrt(D * D + excess) + D)));
}

/// Solves h(u) = λ by safeguarded Halley steps (h is increasing and convex on u > 0).
///
/// Stopping rule: after a step δ the remaining error is about (h''/2h')δ² for a Newton step and
/// [(h''/2h')² − h'''/6h']δ³ for a Halley step. In units of u these constants are ≤ 1/2 and ≈ 1/4
/// (h ≈ u²/6 − u⁴/180 near 0; h'' → 0 for large u; u·h''/2h' = 0.44 at u = 1). The loop therefore
/// stops after a Halley step with |δ/u|³ ≤ tolerance or a Newton step with (δ/u)² ≤ tolerance,
/// leaving a relative error of u below ~tolerance.
inline ReducedSolution solve_reduced(double lambda, double tolerance, int max_iterations) {
  ReducedSolution out;
  out.lambda = lambda;
  double u = log_sinhc_inverse_guess(lambda);
  for (int it = 1; it <= max_iterations; ++it) {
    const LogSinhc e = eval_log_sinhc(u);
    const double f = e.h - lambda;
    const double inv_d1 = 1.0 / e.d1;
    const double newton = f * inv_d1;
    const double denom = 1.0 - 0.5 * newton * e.d2 * inv_d1;
    // Halley's correction is only trusted while it is moderate; otherwise take the Newton step.
    const bool halley = denom > 0.5 && denom < 2.0;
    double next = halley ? u - newton / denom : u - newton;
    if (!(next > 0.0)) next = 0.5 * u;  // keep u > 0 (a > 0)
    const double rel = std::abs(next - u) / next;
    u = next;
    out.iterations = it;
    if ((halley ? rel * rel * rel : rel * rel) <= tolerance || f == 0.0) {
      out.converged = true;
      break;
    }
  }
  out.u = u;
  return out;
}

/// The paper's residuals a[cosh((D−c)/a) − cosh(c/a)] − Δz and a[sinh((D−c)/a) + sinh(c/a)] − L,
/// as written, in double; returns max(|R1|, |R2|)/L.
inline double paper_residual(double a, double c, double D, double dz, double L) {
  const double p = (D - c) / a;
  const double q = c / a;
  const double ep = std::exp(p), eq = std::exp(q);
  const double cosh_p = 0.5 * (ep + 1.0 / ep), sinh_p = 0.5 * (ep - 1.0 / ep);
  const double cosh_q = 0.5 * (eq + 1.0 / eq), sinh_q = 0.5 * (eq - 1.0 / eq);
  const double r1 = a * (cosh_p - cosh_q) - dz;
  const double r2 = a * (sinh_p + sinh_q) - L;
  return std::max(std::abs(r1), std::abs(r2)) / L;
}

/// atanh(dz/L) = ½ ln((L+dz)/(L−dz)) from dz and L themselves, written with log1p (ceres::Jet has
/// no atanh). Forming t = dz/L first would lose the digits of 1 − |t| for steep, nearly taut lines.
template <typename T>
T atanh_ratio(const T& dz, const T& L) {
  using std::log1p;
  if (dz < T(0.0)) return -atanh_ratio(T(-dz), L);
  return T(0.5) * log1p(T(2.0) * dz / (L - dz));
}

/// asinh(y) via log1p/sqrt (ceres::Jet has no asinh); odd-symmetric and exact near 0.
template <typename T>
T asinh_via_log(const T& y) {
  using std::log1p;
  using std::sqrt;
  if (y < T(0.0)) return -asinh_via_log(T(-y));
  return log1p(y + y * y / (T(1.0) + sqrt(T(1.0) + y * y)));
}

/// True when the options can be used (see CatenaryOptions): finite tolerances ≥ 0, at least one
/// iteration, EA finite in [0, limits::max_catenary_EA], a seabed depth that is not NaN.
template <typename Scalar>
bool catenary_options_valid(const CatenaryOptions<Scalar>& o) {
  const double ea = value_of(o.EA);
  return std::isfinite(o.tolerance) && o.tolerance >= 0.0 && o.max_iterations >= 1 &&
         std::isfinite(o.vertical_tolerance) && o.vertical_tolerance >= 0.0 && ea >= 0.0 &&
         ea <= limits::max_catenary_EA && !std::isnan(o.seabed_depth) &&
         std::isfinite(o.residual_tolerance) && o.residual_tolerance >= 0.0 &&
         std::isfinite(o.target_residual) && o.target_residual >= 0.0;
}

/// Classification shared by the fast and the Ceres paths, on the value parts.
/// Returns `converged` when the geometry needs a solve; `invalid_input` for non-finite or
/// out-of-range lengths (see limits) or unusable options.
/// `excess` receives L² − Δz² − D² (see slack_excess) for valid input.
template <typename Scalar>
CatenaryStatus classify_catenary(double D, double dz, double L,
                                 const CatenaryOptions<Scalar>& options, double& excess) {
  excess = 0.0;
  // NaN fails every comparison below.
  if (!(D >= 0.0 && D <= limits::max_catenary_length &&
        std::abs(dz) <= limits::max_catenary_length && L >= limits::min_catenary_length &&
        L <= limits::max_catenary_length) ||
      !catenary_options_valid(options))
    return CatenaryStatus::invalid_input;
  // Below √(smallest normal) of the scalar's value type, D/L is treated as vertical whatever
  // vertical_tolerance says: the reduced equation's ρ ~ (L/D)² would overflow (double: L/D
  // beyond ~1e154) or a = D/(2u) would underflow (float: D/L below ~1e-19).
  using Value = std::conditional_t<std::is_same_v<Scalar, float>, float, double>;
  const double floor_ratio = std::sqrt(double(std::numeric_limits<Value>::min()));
  const double vertical_tolerance = std::max(options.vertical_tolerance, floor_ratio);
  excess = slack_excess(D, dz, L);
  if (!(excess > 0.0)) return CatenaryStatus::taut;
  if (D <= vertical_tolerance * L) return CatenaryStatus::vertical;
  return CatenaryStatus::converged;
}

/// Fills the result for the statuses that need no solve (taut, vertical, invalid input).
template <typename Scalar>
void fill_unsolved(CatenaryStatus status, const Scalar& D, const Scalar& dz, const Scalar& L,
                   const CatenaryOptions<Scalar>& options, CatenaryResult<Scalar>& result) {
  using std::sqrt;
  result.status = status;
  result.iterations = 0;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (status == CatenaryStatus::taut) {
    result.a = Scalar(std::numeric_limits<double>::infinity());
    result.c = Scalar(nan);
    result.residual = Scalar(0.0);
    if (value_of(options.EA) > 0.0) {
      const Scalar chord = sqrt(D * D + dz * dz);
      result.taut_tension = options.EA * (chord - L) / L;
    }
  } else if (status == CatenaryStatus::vertical) {
    result.a = Scalar(0.0);
    result.c = Scalar(0.0);
    result.residual = Scalar(0.0);
  } else {
    result.a = Scalar(nan);
    result.c = Scalar(nan);
    result.residual = Scalar(nan);
  }
}

/// Turns the double solution u into a, c (and, for autodiff scalars, their derivative parts by the
/// implicit function theorem: δu = δλ / h'(u)).
template <typename Scalar>
void finish_from_u(const ReducedSolution& sol, const Scalar& D, const Scalar& dz, const Scalar& L,
                   CatenaryResult<Scalar>& result) {
  using std::log1p;
  const double Dd = value_of(D), dzd = value_of(dz), Ld = value_of(L);
  if constexpr (std::is_arithmetic_v<Scalar>) {
    const double a = Dd / (2.0 * sol.u);
    const double c = 0.5 * Dd - a * atanh_ratio(dzd, Ld);
    result.a = static_cast<Scalar>(a);
    result.c = static_cast<Scalar>(c);
  } else {
    // λ with its derivative parts, then one exact linearisation about the double root.
    using std::sqrt;
    const Scalar excess = L * L - dz * dz - D * D;  // only its derivative parts are used
    const Scalar lambda = log1p(excess / (D * (sqrt(D * D + excess) + D)));
    const Scalar u = Scalar(sol.u) + (lambda - Scalar(sol.lambda)) / log_sinhc_d1(sol.u);
    result.a = D / (Scalar(2.0) * u);
    result.c = Scalar(0.5) * D - result.a * atanh_ratio(dz, L);
    // The value parts are exactly those of the double solve (Jet division rounds differently).
    const double a = Dd / (2.0 * sol.u);
    result.a.a = a;
    result.c.a = 0.5 * Dd - a * atanh_ratio(dzd, Ld);
  }
  result.iterations = sol.iterations;
  result.residual = Scalar(paper_residual(value_of(result.a), value_of(result.c), Dd, dzd, Ld));
}

/// acosh(1 + y) = log1p(y + √(y(2 + y))), y ≥ 0, exact near 0 (ceres::Jet has no acosh).
template <typename T>
T acosh1p_via_log(const T& y) {
  using std::log1p;
  using std::sqrt;
  return log1p(y + sqrt(y * (T(2.0) + y)));
}

/// For a catenary whose vertex touches the seabed: the suspended arc length s = √(h² + 2ah) and
/// horizontal span x = a·acosh(1 + h/a) from the touchdown point to an end at height h above the
/// seabed; returns g = s − x ≥ 0 (the length the suspended part adds over its span) and dg/da.
/// Series in y = h/a below 1e-3, where s and x agree to ~y/3 relative:
/// g = a√(2y)·y·(1/3 − y/20 + 3y²/224 − 5y³/1152), dg/da = √(2y)·y·(−1/6 + 3y/40 − 15y²/448).
inline double grounded_excess(double a, double h, double& dg_da) {
  const double y = h / a;
  if (y < 1e-3) {
    const double ty = std::sqrt(2.0 * y) * y;
    dg_da = ty * (-1.0 / 6.0 + y * (3.0 / 40.0 - y * (15.0 / 448.0)));
    return a * ty * (1.0 / 3.0 + y * (-1.0 / 20.0 + y * (3.0 / 224.0 - y * (5.0 / 1152.0))));
  }
  const double r = std::sqrt(y * (y + 2.0));
  const double phi = r - acosh1p_via_log(y);
  dg_da = phi - y * y / r;
  return a * phi;
}

/// Result of the seabed-contact solve.
struct GroundedSolution {
  double a = 0.0;
  double residual = 0.0;  ///< |F(a)|/L
  int iterations = 0;
  bool converged = false;
};

/// Solves g(a, h1) + g(a, h2) = L − D for a > 0 (two suspended catenaries with their vertices on
/// the seabed and a straight grounded part between them; frictionless seabed, so H = a·w is the
/// same on both sides). F(a) = g1 + g2 − (L − D) decreases from h1 + h2 − (L − D) > 0 (a → 0) to
/// −(L − D) < 0 (a → ∞); Newton in ln a inside a maintained bracket, bisection as a fallback.
inline GroundedSolution solve_grounded(double D, double L, double h1, double h2, double a0,
                                       double tolerance, int max_iterations) {
  GroundedSolution out;
  const double target = L - D;
  const auto F = [&](double b, double& dF_db) {
    const double a = std::exp(b);
    double d1 = 0.0, d2 = 0.0;
    const double f = grounded_excess(a, h1, d1) + grounded_excess(a, h2, d2) - target;
    dF_db = a * (d1 + d2);
    return f;
  };
  double b = std::log(a0), dF = 0.0;
  double f = F(b, dF);
  // Bracket the root: F(lo) > 0 > F(hi).
  double lo = b, hi = b;
  double dummy = 0.0;
  if (f > 0.0) {
    while (F(hi, dummy) > 0.0 && hi < 700.0) hi += 2.302585092994046;  // ×10
  } else {
    while (F(lo, dummy) <= 0.0 && lo > -700.0) lo -= 2.302585092994046;
  }
  const double step_tolerance = std::sqrt(tolerance);
  for (int it = 1; it <= max_iterations + 60; ++it) {
    f = F(b, dF);
    out.iterations = it;
    if (f == 0.0) {
      out.converged = true;
      break;
    }
    if (f > 0.0)
      lo = b;
    else
      hi = b;
    double next = b - f / dF;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);  // Newton left the bracket: bisect
    const double step = next - b;
    b = next;
    if (std::abs(step) <= step_tolerance * 1e-1 || hi - lo <= 4e-16 * std::abs(b) + 1e-300) {
      out.converged = true;
      break;
    }
  }
  out.a = std::exp(b);
  double d = 0.0;
  out.residual =
      std::abs(grounded_excess(out.a, h1, d) + grounded_excess(out.a, h2, d) - target) / L;
  return out;
}

}  // namespace detail

/// \brief Solves the paper's catenary equations for a and c by the analytic reduction (fast path).
///
/// Solves \f$ a[\cosh((D-c)/a) - \cosh(c/a)] = \Delta z \f$ and
/// \f$ a[\sinh((D-c)/a) + \sinh(c/a)] = L \f$ through \f$ \sqrt{L^2-\Delta z^2} = 2a\sinh(D/(2a))
/// \f$ and \f$ c = D/2 - a\,\mathrm{atanh}(\Delta z/L) \f$ (paper; derivation in
/// docs/equations.md). Never throws and never allocates. \tparam Scalar double, float or
/// `ceres::Jet<double, N>` (derivatives of a, c with respect to
///   D, Δz and L by the implicit function theorem).
/// \param[in] D horizontal distance between the ends [m], ≥ 0.
/// \param[in] dz height of the end above the start, z_end − z_start with z up [m].
/// \param[in] L unstretched tether length [m], > 0.
/// \param[in] options tolerance, iteration limit, vertical threshold, EA for the taut tension.
/// \return a, c, status (converged / taut / vertical / invalid_input / max_iterations),
///   iterations and the paper's residual. Vertical (D ≤ vertical_tolerance·L): a = 0, c = 0 — the
///   slack L − |Δz| hangs as a doubled vertical loop below the lower end (for a weighted line),
///   see CatenaryShape.
template <typename Scalar>
CatenaryResult<Scalar> solve_catenary(Scalar D, Scalar dz, Scalar L,
                                      const CatenaryOptions<Scalar>& options = {}) {
  CatenaryResult<Scalar> result;
  const double Dd = value_of(D), dzd = value_of(dz), Ld = value_of(L);
  double excess = 0.0;
  const CatenaryStatus kind = detail::classify_catenary(Dd, dzd, Ld, options, excess);
  if (kind != CatenaryStatus::converged) {
    detail::fill_unsolved(kind, D, dz, L, options, result);
    return result;
  }
  const double lambda = detail::reduced_target(Dd, excess);
  const detail::ReducedSolution sol =
      detail::solve_reduced(lambda, options.tolerance, options.max_iterations);
  detail::finish_from_u(sol, D, dz, L, result);
  result.status = sol.converged ? CatenaryStatus::converged : CatenaryStatus::max_iterations;
  return result;
}

/// \brief The static catenary between two 3-D attachment points, in world NED.
///
/// Built by catenary_between(): the vertical plane through both ends, the paper's solve, then the
/// shape by arc length, the lowest point, the horizontal tension H = a·|w| and the 3-D forces
/// the cable exerts on its two attachment points. A buoyant line (w < 0) is the mirror image of a
/// hanging one (inverted catenary: it arches upwards).
///
/// Status-specific behaviour: `taut` — the straight segment from start to end; each end carries the
/// axial tension EA·(chord − L)/L (0 when EA = 0) plus half the weight w·L (the limit of a
/// vanishing sag). `vertical` — the ends are vertically aligned: the line runs from the start to
/// the vertex (lowest point for w ≥ 0, highest for w < 0) and back to the end along the vertical,
/// s_start = (L − Δz')/2 from the start (Δz' the height difference in the mirrored plane), H = 0,
/// each end carries the weight of its own branch. `max_iterations` — the shape, H = a·|w|, the end
/// forces and tension_at() are all those of the solver's last iterate (a, c in result()), so they
/// agree with one another (|force_on_start()| = tension_at(0)) but satisfy the paper's equations
/// only to result().residual; check status() before relying on them. `invalid_input` — every
/// query returns NaN. Whatever the status, point_at() and tension_at() refuse a NaN or infinite
/// arc length with kelp::invalid_argument.
///
/// **Seabed contact** (options.seabed_depth finite, w > 0, both ends at or above the seabed; an end
/// below it gives `invalid_input`). When the free catenary's lowest point would lie below the
/// seabed, the line is modelled as two catenaries whose vertices touch a flat frictionless seabed,
/// joined by a straight grounded part of length L_b (on_seabed(), grounded_length()). With h₁, h₂
/// the end heights above the seabed, each suspended part has arc length s = √(h² + 2ah) and span
/// x = a·acosh(1 + h/a), and a solves s₁ − x₁ + s₂ − x₂ = L − D (so that L_b = L − s₁ − s₂ =
/// D − x₁ − x₂). The seabed carries w·L_b; the ends carry H horizontally and w·s₁, w·s₂
/// vertically. If even H = 0 leaves slack (L ≥ h₁ + h₂ + D) the line drops vertically from both
/// ends and the grounded part, longer than D, is laid along the seabed between the touchdown points
/// with its length spread uniformly (statics does not fix a slack shape on the seabed). result().a
/// is then the grounded a, result().c the touchdown distance x₁ and result().residual |F(a)|/L.
/// \tparam Scalar double, float or `ceres::Jet<double, N>`.
template <typename Scalar>
class CatenaryShape {
 public:
  using Vector3S = Vector3<Scalar>;  ///< A 3-vector of the shape's scalar (NED points, forces).

  /// \brief An invalid shape (status invalid_input); use catenary_between() to build one.
  CatenaryShape() = default;

  /// \brief Solves the catenary between `start_ned` and `end_ned`; see catenary_between().
  /// Never throws: bad inputs give status `invalid_input`.
  /// \param start_ned start attachment point, NED [m].
  /// \param end_ned end attachment point, NED [m].
  /// \param L unstretched length [m].
  /// \param w submerged weight per length [N/m] (< 0: buoyant).
  /// \param options solver options (EA for a taut line, seabed_depth for seabed contact).
  CatenaryShape(const Vector3S& start_ned, const Vector3S& end_ned, Scalar L, Scalar w,
                const CatenaryOptions<Scalar>& options = {})
      : start_(start_ned), end_(end_ned), L_(L), w_(w) {
    using std::abs;
    using std::sqrt;
    horizontal_dir_ = Vector3S(Scalar(1.0), Scalar(0.0), Scalar(0.0));
    const double seabed = options.seabed_depth;
    const bool has_seabed = std::isfinite(seabed);
    if (!(all_finite(start_ned) && all_finite(end_ned) && is_finite(w)) ||
        !(abs(value_of(w)) <= limits::max_catenary_weight) || std::isnan(seabed) ||
        (has_seabed && (value_of(start_ned.z()) > seabed || value_of(end_ned.z()) > seabed))) {
      detail::fill_unsolved(CatenaryStatus::invalid_input, Scalar(0.0), Scalar(0.0), L, options,
                            result_);
      return;
    }
    const Scalar dn = end_.x() - start_.x();
    const Scalar de = end_.y() - start_.y();
    D_ = sqrt(dn * dn + de * de);
    if (value_of(D_) > 0.0) horizontal_dir_ = Vector3S(dn / D_, de / D_, Scalar(0.0));
    buoyant_ = value_of(w_) < 0.0;
    // z up = −z_NED; the mirrored plane flips z for a buoyant line so that it always hangs.
    const Scalar dz_up = start_.z() - end_.z();
    dz_ = buoyant_ ? Scalar(-dz_up) : dz_up;
    weight_ = abs(w_);
    result_ = solve_catenary(D_, dz_, L_, options);
    // converged and max_iterations (the last iterate) alike: every query below describes the same
    // a, c, so that force_on_start/force_on_end and tension_at agree whatever the status.
    const bool has_iterate = result_.status == CatenaryStatus::converged ||
                             result_.status == CatenaryStatus::max_iterations;
    H_ = has_iterate ? Scalar(result_.a * weight_) : Scalar(0.0);
    const bool slack =
        result_.status == CatenaryStatus::converged || result_.status == CatenaryStatus::vertical;
    if (has_seabed && !buoyant_ && value_of(w_) > 0.0 && slack &&
        value_of(lowest_point().z()) > seabed) {
      ground(seabed, options);
    }
  }

  /// \brief The solver's status (see CatenaryStatus).
  /// \return converged, taut, vertical, max_iterations or invalid_input.
  CatenaryStatus status() const { return result_.status; }
  /// \brief The full solve result in the (mirrored, for w < 0) paper plane: a, c, iterations,
  /// residual, taut tension (for a grounded line see the class description).
  /// \return the result (a [m], c [m], taut_tension [N]).
  const CatenaryResult<Scalar>& result() const { return result_; }
  /// \brief Horizontal tension H = a·|w| [N], the same all along the line (0 when vertical, taut or
  /// invalid; for max_iterations that of the last iterate, like the shape and the end forces).
  /// \return H [N], ≥ 0.
  Scalar horizontal_tension() const { return H_; }
  /// \brief Horizontal distance between the ends D [m].
  /// \return D [m] (0 for an invalid input).
  Scalar horizontal_distance() const { return D_; }
  /// \brief Unstretched length L [m].
  /// \return L [m], as given.
  Scalar length() const { return L_; }
  /// \brief Submerged weight per length w [N/m] (< 0: buoyant).
  /// \return w [N/m], as given.
  Scalar weight_per_length() const { return w_; }
  /// \brief True when part of the line rests on the seabed (options.seabed_depth).
  /// \return whether the grounded shape applies.
  bool on_seabed() const { return grounded_; }
  /// \brief Length resting on the seabed L_b [m] (0 when not on the seabed); the seabed carries
  /// its weight w·L_b.
  /// \return L_b [m], ≥ 0.
  Scalar grounded_length() const { return grounded_ ? Lb_ : Scalar(0.0); }

  /// \brief The NED point [m] at unstretched arc length s ∈ [0, L] from the start end.
  ///
  /// Slack line (paper plane, mirrored when buoyant): with σ₀ = −a sinh(c/a) the arc length of the
  /// start from the vertex, x(s) = c + a·asinh((σ₀ + s)/a) and
  /// z(x) = a cosh((x−c)/a) − a cosh(c/a) = 2a sinh(x/(2a)) sinh((x−2c)/(2a)).
  /// Taut: linear interpolation. Grounded: see the class description.
  /// \param[in] s arc length [m] from the start, finite (meant in [0, L]).
  /// \return the point, NED [m] (NaN for status invalid_input).
  /// \throws kelp::invalid_argument when s is NaN or ±Inf (a shape of status `invalid_input`
  /// answers a finite s with NaN, its documented status value).
  Vector3S point_at(Scalar s) const {
    using std::sinh;
    check_arc_length(s);
    const Scalar nan = Scalar(std::numeric_limits<double>::quiet_NaN());
    if (grounded_) return grounded_point(s);
    switch (result_.status) {
      case CatenaryStatus::taut:
        return start_ + (s / L_) * (end_ - start_);
      case CatenaryStatus::vertical: {
        const Scalar s1 = start_branch_length();
        const Scalar z_plane = s <= s1 ? Scalar(-s) : Scalar(s - Scalar(2.0) * s1);
        return from_plane(D_ * s / L_, z_plane);
      }
      case CatenaryStatus::converged:
      case CatenaryStatus::max_iterations: {
        const Scalar a = result_.a, c = result_.c;
        const Scalar sigma0 = -a * sinh(c / a);
        const Scalar x = c + a * detail::asinh_via_log((sigma0 + s) / a);
        return from_plane(x, plane_height(x));
      }
      case CatenaryStatus::invalid_input:
        break;
    }
    return Vector3S(nan, nan, nan);
  }

  /// \brief The vertex of the catenary in NED [m]: the lowest point of the curve for w ≥ 0, the
  /// highest for w < 0. It may lie beyond the ends (then it is not on the cable). Grounded: the
  /// first touchdown point. NaN when taut or invalid.
  /// \return the vertex, NED [m].
  Vector3S vertex() const {
    const Scalar nan = Scalar(std::numeric_limits<double>::quiet_NaN());
    if (grounded_) return grounded_point(s1_);
    if (result_.status == CatenaryStatus::vertical) return point_at(start_branch_length());
    if (result_.status == CatenaryStatus::converged ||
        result_.status == CatenaryStatus::max_iterations)
      return from_plane(result_.c, plane_height(result_.c));
    return Vector3S(nan, nan, nan);
  }

  /// \brief The deepest point of the cable itself, NED [m]: the vertex when it lies between the
  /// ends of a hanging line, otherwise the deeper end (always an end for a buoyant or taut line);
  /// the first touchdown point when grounded.
  /// \return the point with the largest NED z on the cable [m] (NaN when invalid).
  Vector3S lowest_point() const {
    const Vector3S deeper_end = end_.z() > start_.z() ? end_ : start_;
    if (grounded_) return vertex();
    switch (result_.status) {
      case CatenaryStatus::converged:
      case CatenaryStatus::max_iterations:
        if (!buoyant_ && result_.c >= Scalar(0.0) && result_.c <= D_) return vertex();
        return deeper_end;
      case CatenaryStatus::vertical:
        return buoyant_ ? deeper_end : vertex();
      case CatenaryStatus::taut:
        return deeper_end;
      case CatenaryStatus::invalid_input:
        break;
    }
    return vertex();
  }

  /// \brief Force the cable exerts on the start attachment point, NED [N].
  ///
  /// Slack line: H toward the end horizontally and H·sinh(c/a) = |w|·(arc length from the start to
  /// the vertex) downwards (upwards for a buoyant line), i.e. the cable tension T = H cosh(c/a)
  /// along the tangent. Taut, vertical and grounded: see the class description.
  /// \return the force, NED [N] (NaN when invalid).
  Vector3S force_on_start() const { return end_force(true); }

  /// \brief Force the cable exerts on the end attachment point, NED [N] (see force_on_start()).
  /// \return the force, NED [N] (NaN when invalid).
  Vector3S force_on_end() const { return end_force(false); }

  /// \brief Tension magnitude [N] at arc length s: H cosh((x(s) − c)/a) = |w|√(a² + σ²) for a
  /// slack line (σ the arc length from the vertex); H on the grounded part.
  /// \param[in] s arc length [m] from the start, finite (meant in [0, L]).
  /// \return the tension [N] (taut: result().taut_tension; NaN for status invalid_input).
  /// \throws kelp::invalid_argument when s is NaN or ±Inf (a shape of status `invalid_input`
  /// answers a finite s with NaN, its documented status value).
  Scalar tension_at(Scalar s) const {
    using std::sinh;
    using std::sqrt;
    check_arc_length(s);
    if (grounded_) {
      const Scalar a = result_.a;
      if (s <= s1_) return weight_ * sqrt(a * a + (s1_ - s) * (s1_ - s));
      if (s >= s1_ + Lb_) return weight_ * sqrt(a * a + (s - s1_ - Lb_) * (s - s1_ - Lb_));
      return H_;
    }
    switch (result_.status) {
      case CatenaryStatus::converged:
      case CatenaryStatus::max_iterations: {
        const Scalar a = result_.a, c = result_.c;
        const Scalar sigma = s - a * sinh(c / a);  // arc length from the vertex
        return weight_ * sqrt(a * a + sigma * sigma);
      }
      case CatenaryStatus::vertical: {
        const Scalar s1 = start_branch_length();
        return weight_ * (s <= s1 ? Scalar(s1 - s) : Scalar(s - s1));
      }
      case CatenaryStatus::taut:
        return result_.taut_tension;
      case CatenaryStatus::invalid_input:
        break;
    }
    return Scalar(std::numeric_limits<double>::quiet_NaN());
  }

 private:
  /// The queries' check of their arc length: a NaN s has no point on the line, and would give
  /// NaN for every status (it used to answer silently with NaN).
  static void check_arc_length(const Scalar& s) {
    if (!is_finite(s))
      ::kelp::detail::throw_invalid_argument("CatenaryShape: arc length s must be finite");
  }

  /// Switches to the seabed-contact shape (see the class description).
  void ground(double seabed, const CatenaryOptions<Scalar>& options) {
    using std::sqrt;
    seabed_ = Scalar(seabed);
    const Scalar h1 = seabed_ - start_.z(), h2 = seabed_ - end_.z();
    const double D = value_of(D_), L = value_of(L_), h1d = value_of(h1), h2d = value_of(h2);
    CatenaryResult<Scalar> r;
    r.taut_tension = Scalar(0.0);
    if (L >= h1d + h2d + D) {  // slack even with H = 0: vertical drops, slack on the seabed
      r.a = Scalar(0.0);
      r.status = result_.status == CatenaryStatus::vertical ? CatenaryStatus::vertical
                                                            : CatenaryStatus::converged;
      r.iterations = 0;
      r.residual = Scalar(0.0);
      s1_ = h1;
      x1_ = Scalar(0.0);
      x2_ = Scalar(0.0);
      Lb_ = L_ - h1 - h2;
      slack_on_seabed_ = true;
    } else {
      const double a0 = result_.status == CatenaryStatus::converged ? value_of(result_.a)
                                                                    : 0.5 * (h1d + h2d + 1e-3 * L);
      const detail::GroundedSolution g = detail::solve_grounded(
          D, L, h1d, h2d, a0 > 0.0 ? a0 : 1e-3 * L, options.tolerance, options.max_iterations);
      r.status = g.converged ? CatenaryStatus::converged : CatenaryStatus::max_iterations;
      r.iterations = g.iterations;
      r.residual = Scalar(g.residual);
      if constexpr (std::is_arithmetic_v<Scalar>) {
        r.a = static_cast<Scalar>(g.a);
      } else {
        // Implicit function theorem on F(a; D, L, h1, h2) = g1 + g2 − (L − D) = 0.
        double d1 = 0.0, d2 = 0.0;
        detail::grounded_excess(g.a, h1d, d1);
        detail::grounded_excess(g.a, h2d, d2);
        const Scalar as(g.a);
        const Scalar F = suspended_excess(as, h1) + suspended_excess(as, h2) - (L_ - D_);
        r.a = as - F / (d1 + d2);
        r.a.a = g.a;
      }
      const Scalar a = r.a;
      s1_ = sqrt(h1 * h1 + Scalar(2.0) * a * h1);
      x1_ = a * detail::acosh1p_via_log(Scalar(h1 / a));
      x2_ = a * detail::acosh1p_via_log(Scalar(h2 / a));
      const Scalar s2 = sqrt(h2 * h2 + Scalar(2.0) * a * h2);
      Lb_ = L_ - s1_ - s2;
      slack_on_seabed_ = false;
      // A (theoretically impossible) negative grounded length keeps the free solution.
      if (r.status == CatenaryStatus::converged && !(value_of(Lb_) >= 0.0)) return;
    }
    r.c = x1_;
    result_ = r;
    H_ = r.a * weight_;
    grounded_ = true;
  }

  /// s − x of a suspended part in Scalar arithmetic (for the implicit derivatives).
  static Scalar suspended_excess(const Scalar& a, const Scalar& h) {
    using std::sqrt;
    return sqrt(h * h + Scalar(2.0) * a * h) - a * detail::acosh1p_via_log(Scalar(h / a));
  }

  /// Grounded shape by arc length (x from the start, η above the seabed).
  Vector3S grounded_point(const Scalar& s) const {
    using std::sqrt;
    const Scalar a = result_.a;
    Scalar x, eta;
    const Scalar s_down = s1_ + Lb_;  // arc length where the end-side part leaves the seabed
    if (s <= s1_ || s >= s_down) {
      const bool first = s <= s1_;
      const Scalar sigma = first ? Scalar(s1_ - s) : Scalar(s - s_down);
      Scalar dx(0.0);
      if (value_of(a) > 0.0) {
        dx = a * detail::asinh_via_log(Scalar(sigma / a));
        eta = sigma * sigma / (sqrt(a * a + sigma * sigma) + a);
      } else {
        eta = sigma;
      }
      x = first ? Scalar(x1_ - dx) : Scalar(D_ - x2_ + dx);
    } else {
      const Scalar along = s - s1_;
      const Scalar span = D_ - x1_ - x2_;
      x = x1_ + (slack_on_seabed_ ? Scalar(along * span / Lb_) : along);
      eta = Scalar(0.0);
    }
    Vector3S p = start_ + x * horizontal_dir_;
    p.z() = seabed_ - eta;
    return p;
  }

  /// Arc length from the start to the vertex of a vertical line, (L − Δz')/2.
  Scalar start_branch_length() const { return Scalar(0.5) * (L_ - dz_); }

  /// z of the (mirrored) paper plane at horizontal position x: 2a sinh(x/2a) sinh((x−2c)/2a).
  Scalar plane_height(const Scalar& x) const {
    using std::sinh;
    const Scalar a = result_.a, c = result_.c;
    return Scalar(2.0) * a * sinh(x / (Scalar(2.0) * a)) *
           sinh((x - Scalar(2.0) * c) / (Scalar(2.0) * a));
  }

  /// NED point of the (mirrored) plane coordinates (x, z).
  Vector3S from_plane(const Scalar& x, const Scalar& z_plane) const {
    const Scalar z_up = buoyant_ ? Scalar(-z_plane) : z_plane;
    Vector3S p = start_ + x * horizontal_dir_;
    p.z() = start_.z() - z_up;
    return p;
  }

  /// NED vector of a (mirrored) plane vector (horizontal, vertical-up).
  Vector3S plane_vector(const Scalar& fx, const Scalar& fz_plane) const {
    const Scalar fz_up = buoyant_ ? Scalar(-fz_plane) : fz_plane;
    Vector3S f = fx * horizontal_dir_;
    f.z() = -fz_up;
    return f;
  }

  Vector3S end_force(bool at_start) const {
    using std::sinh;
    using std::sqrt;
    const Scalar nan = Scalar(std::numeric_limits<double>::quiet_NaN());
    if (grounded_) {
      const Scalar branch = at_start ? s1_ : Scalar(L_ - s1_ - Lb_);
      return plane_vector(at_start ? H_ : Scalar(-H_), -weight_ * branch);
    }
    switch (result_.status) {
      case CatenaryStatus::converged:
      case CatenaryStatus::max_iterations: {
        const Scalar a = result_.a, c = result_.c;
        // Vertical components from the arc lengths to the vertex: w·a·sinh(·).
        if (at_start) return plane_vector(H_, -weight_ * a * sinh(c / a));
        return plane_vector(Scalar(-H_), -weight_ * a * sinh((D_ - c) / a));
      }
      case CatenaryStatus::vertical: {
        const Scalar s1 = start_branch_length();
        const Scalar branch = at_start ? s1 : Scalar(L_ - s1);
        return plane_vector(Scalar(0.0), -weight_ * branch);
      }
      case CatenaryStatus::taut: {
        const Vector3S chord = end_ - start_;
        const Scalar n = sqrt(chord.squaredNorm());
        Vector3S f = (at_start ? result_.taut_tension : Scalar(-result_.taut_tension)) / n * chord;
        f.z() += Scalar(0.5) * w_ * L_;
        return f;
      }
      case CatenaryStatus::invalid_input:
        break;
    }
    return Vector3S(nan, nan, nan);
  }

  Vector3S start_ = Vector3S::Zero();
  Vector3S end_ = Vector3S::Zero();
  Vector3S horizontal_dir_ = Vector3S(Scalar(1.0), Scalar(0.0), Scalar(0.0));
  Scalar L_ = Scalar(0.0);
  Scalar w_ = Scalar(0.0);
  Scalar weight_ = Scalar(0.0);  // |w|
  Scalar D_ = Scalar(0.0);
  Scalar dz_ = Scalar(0.0);  // height difference in the (mirrored) plane, z up
  Scalar H_ = Scalar(0.0);
  bool buoyant_ = false;
  // Seabed contact (valid when grounded_).
  bool grounded_ = false;
  bool slack_on_seabed_ = false;
  Scalar seabed_ = Scalar(0.0);  // NED z of the seabed
  Scalar s1_ = Scalar(0.0);      // arc length from the start to the first touchdown
  Scalar x1_ = Scalar(0.0);      // horizontal span of the start-side suspended part
  Scalar x2_ = Scalar(0.0);      // horizontal span of the end-side suspended part
  Scalar Lb_ = Scalar(0.0);      // grounded length
  CatenaryResult<Scalar> result_{};
};

/// \brief The static catenary between two attachment points given in world NED (z down, sea
/// surface at z = 0).
///
/// Builds the vertical plane through both points (x along the horizontal projection of
/// end − start, z up), solves the paper's equations with solve_catenary() and returns the shape
/// with its tensions. Never throws; non-finite inputs give status `invalid_input`.
/// \tparam Scalar double, float or `ceres::Jet<double, N>`.
/// \param[in] start_ned start attachment point (the ASV end in the paper), NED [m].
/// \param[in] end_ned end attachment point, NED [m].
/// \param[in] L unstretched tether length [m].
/// \param[in] w submerged weight per length [N/m]: weight minus buoyancy, w = (m' − ρ A) g
///   (w > 0 hangs, w < 0 is buoyant and arches upwards, w = 0 gives the shape with zero tension).
/// \param[in] options solver options (EA sets the tension of a taut line).
/// \return the shape; check its status() before using it.
template <typename Scalar>
CatenaryShape<Scalar> catenary_between(const Vector3<Scalar>& start_ned,
                                       const Vector3<Scalar>& end_ned, Scalar L, Scalar w,
                                       const CatenaryOptions<Scalar>& options = {}) {
  return CatenaryShape<Scalar>(start_ned, end_ned, L, w, options);
}

using CatenaryOptionsd = CatenaryOptions<double>;  ///< CatenaryOptions<double>
using CatenaryOptionsf = CatenaryOptions<float>;   ///< CatenaryOptions<float>
using CatenaryResultd = CatenaryResult<double>;    ///< CatenaryResult<double>
using CatenaryResultf = CatenaryResult<float>;     ///< CatenaryResult<float>
using CatenaryShaped = CatenaryShape<double>;      ///< CatenaryShape<double>
using CatenaryShapef = CatenaryShape<float>;       ///< CatenaryShape<float>

}  // namespace tether
}  // namespace kelp
