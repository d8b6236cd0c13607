// The Ceres path: the paper's residuals solved by ceres::TinySolver; same statuses as the fast
// path, agreement with it, warm starts from a caller's guess, no allocation.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <random>
#include <type_traits>
#include <vector>

#include "kelp/ceres/catenary_solver.hpp"
#include "random_geometry.hpp"

using kelp::tether::CatenaryOptions;
using kelp::tether::CatenaryStatus;
namespace kc = kelp::ceres_solver;
namespace kt = kelp::tether;

// Code written inside `namespace kelp` (as kelp's own headers and user extensions are) must see
// Ceres' namespace under its own name: a `kelp::ceres` namespace used to hide every Ceres name it
// did not re-export (here `ceres::isfinite`), and this did not compile.
namespace kelp::user_extension {
using JetInKelp = ceres::Jet<double, 2>;
inline bool jet_is_finite(const JetInKelp& x) { return ceres::isfinite(x); }
}  // namespace kelp::user_extension

TEST_CASE("Ceres path: ::ceres is not shadowed inside namespace kelp", "[catenary][ceres]") {
  STATIC_REQUIRE(std::is_same_v<kelp::user_extension::JetInKelp, ::ceres::Jet<double, 2>>);
  CHECK(kelp::user_extension::jet_is_finite(::ceres::Jet<double, 2>(1.0, 0)));
  CHECK_FALSE(kelp::user_extension::jet_is_finite(
      ::ceres::Jet<double, 2>(std::numeric_limits<double>::quiet_NaN(), 0)));
}

TEST_CASE("Ceres path: reference case D = 10 m, dz = 5 m, L = 20 m", "[catenary][ceres]") {
  const auto r = kc::solve_catenary(10.0, 5.0, 20.0);
  REQUIRE(r.status == CatenaryStatus::converged);
  CHECK(r.a == Approx(2.358583).epsilon(5e-7));
  CHECK(r.c == Approx(4.397588).epsilon(5e-7));
  CHECK(r.residual <= 1e-14);
  // From a naive start (a = L, c = D/2) Ceres still finds the same root.
  const auto n = kc::solve_catenary(10.0, 5.0, 20.0, 20.0, 5.0);
  REQUIRE(n.status == CatenaryStatus::converged);
  CHECK(n.a == Approx(2.358583199).epsilon(1e-9));
  CHECK(n.c == Approx(4.397587633).epsilon(1e-9));
  CHECK(n.iterations > 1);
}

TEMPLATE_TEST_CASE("Ceres path: float and double", "[catenary][ceres]", float, double) {
  using T = TestType;
  const auto r = kc::solve_catenary<T>(T(10), T(5), T(20));
  REQUIRE(r.status == CatenaryStatus::converged);
  CHECK(double(r.a) == Approx(2.358583).epsilon(2e-6));
}

TEST_CASE("Ceres path: statuses identical to the fast path", "[catenary][ceres]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CatenaryOptions<double> opt;
  opt.EA = 1e5;
  const double cases[][3] = {{3, 4, 5},  {3, 4, 4.9}, {0, 2, 5},     {nan, 1, 5},
                             {1, 0, -1}, {-1, 0, 5},  {1e-13, 2, 5}, {4, 1, 9}};
  for (const auto& g : cases) {
    const auto f = kt::solve_catenary(g[0], g[1], g[2], opt);
    const auto c = kc::solve_catenary(g[0], g[1], g[2], opt);
    CHECK(c.status == f.status);
    CHECK(c.taut_tension == f.taut_tension);
  }
}

TEST_CASE("Ceres and fast paths agree on 2e5 random geometries", "[catenary][ceres][random]") {
  // Warm-started from the fast path (the default), Ceres must accept the start or improve it:
  // agreement to 1e-9 and the paper's residual <= 1e-10 on every geometry.
  std::mt19937_64 rng(7);
  kc::CatenarySolver solver;
  int failures = 0;
  double worst_a = 0, worst_c = 0;
  long double worst_res = 0;
  for (int i = 0; i < 200000; ++i) {
    const auto g = (i & 1) ? kelp_test::random_by_slack(rng) : kelp_test::random_by_shape(rng);
    const auto f = kt::solve_catenary(g.D, g.dz, g.L);
    const auto c = solver.solve(g.D, g.dz, g.L);
    if (c.status != CatenaryStatus::converged) {
      ++failures;
      continue;
    }
    worst_a = std::max(worst_a, std::abs(c.a - f.a) / f.a);
    worst_c = std::max(worst_c, std::abs(c.c - f.c) / std::max(std::abs(f.c), g.D));
    worst_res = std::max(worst_res, kelp_test::paper_residual_ld(c.a, c.c, g.D, g.dz, g.L));
  }
  INFO("worst relative difference a " << worst_a << ", c " << worst_c << ", residual "
                                      << double(worst_res));
  CHECK(failures == 0);
  CHECK(worst_a <= 1e-9);
  CHECK(worst_c <= 1e-9);
  CHECK(worst_res <= 1e-10L);
}

TEST_CASE("Ceres from a perturbed start converges to the fast path's root", "[catenary][ceres]") {
  // An independent check of both solvers: 1e4 geometries away from the ill-conditioned corners
  // (L/chord - 1 >= 1e-4, D/L >= 1e-3; nearer to taut a ~ (L - chord)^(-1/2) changes by ~5e8 times
  // the relative change of L, so (a, c) are not fixed to 1e-9 by double inputs and residuals),
  // Ceres alone (no restart) started 1 % away in a and c must land on the fast path's (a, c).
  std::mt19937_64 rng(11);
  kc::CatenarySolver solver;
  CatenaryOptions<double> no_restart;
  no_restart.restart_from_fast_path = false;
  int tried = 0, failures = 0;
  double worst = 0;
  while (tried < 10000) {
    const auto g = kelp_test::random_by_shape(rng);
    if (g.L / std::hypot(g.D, g.dz) - 1 < 1e-4 || g.D / g.L < 1e-3) continue;
    ++tried;
    const auto f = kt::solve_catenary(g.D, g.dz, g.L);
    const auto c =
        solver.solve(g.D, g.dz, g.L, f.a * 1.01, f.c + 0.01 * (std::abs(f.c) + g.D), no_restart);
    if (c.status != CatenaryStatus::converged) {
      ++failures;
      continue;
    }
    worst = std::max(worst, std::abs(c.a - f.a) / f.a);
    worst = std::max(worst, std::abs(c.c - f.c) / std::max(std::abs(f.c), g.D));
  }
  INFO("worst relative difference " << worst);
  CHECK(failures == 0);
  CHECK(worst <= 1e-9);
}

TEST_CASE("Ceres from a perturbed start always answers (restart)", "[catenary][ceres]") {
  // Over the whole random range, including the near-taut corner where Levenberg-Marquardt from a
  // 1 % error does not reach 1e-10, the default restart from the fast path gives a converged
  // answer with the paper's residual <= 1e-10 every time; count how often it was needed.
  std::mt19937_64 rng(13);
  kc::CatenarySolver solver;
  int failures = 0, restarts = 0;
  long double worst = 0;
  for (int i = 0; i < 20000; ++i) {
    const auto g = (i & 1) ? kelp_test::random_by_slack(rng) : kelp_test::random_by_shape(rng);
    const auto f = kt::solve_catenary(g.D, g.dz, g.L);
    const auto c = solver.solve(g.D, g.dz, g.L, f.a * 1.01, f.c + 0.01 * (std::abs(f.c) + g.D));
    failures += c.status != CatenaryStatus::converged;
    restarts += solver.restarted();
    worst = std::max(worst, kelp_test::paper_residual_ld(c.a, c.c, g.D, g.dz, g.L));
  }
  INFO("restarts " << restarts << " of 20000, worst residual " << double(worst));
  CHECK(failures == 0);
  CHECK(worst <= 1e-10L);
  CHECK(restarts > 0);          // the corner is really exercised
  CHECK(restarts < 20000 / 5);  // and it is a corner
}

TEST_CASE("warm start from the previous control step", "[catenary][ceres]") {
  // An AUV drifting away from the ASV: each step starts from the previous solution.
  kc::CatenarySolver solver;
  int max_iterations = 0;
  for (int k = 0; k < 200; ++k) {
    const double D = 5.0 + 0.02 * k, dz = -8.0 + 0.01 * k;
    const auto r = solver.solve_from_previous(D, dz, 20.0);
    REQUIRE(r.status == CatenaryStatus::converged);
    const auto f = kt::solve_catenary(D, dz, 20.0);
    CHECK(r.a == Approx(f.a).epsilon(1e-10));
    CHECK(r.c == Approx(f.c).epsilon(1e-10));
    if (k > 0) max_iterations = std::max(max_iterations, r.iterations);
  }
  CHECK(max_iterations <= 6);
  // A bad guess (a <= 0) falls back to the fast-path start.
  CHECK(solver.solve(10.0, 5.0, 20.0, -1.0, 0.0).status == CatenaryStatus::converged);
}

TEST_CASE("Ceres path does not allocate", "[catenary][ceres]") {
  kc::CatenarySolver solver;
  Eigen::internal::set_is_malloc_allowed(false);
  const auto r = solver.solve(10.0, 5.0, 20.0, 15.0, 4.0);
  Eigen::internal::set_is_malloc_allowed(true);
  CHECK(r.status == CatenaryStatus::converged);
}

TEST_CASE(
    "Ceres path: out-of-range input and unusable options are invalid_input, as on the fast "
    "path",
    "[catenary][ceres][bad_input]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    double D, dz, L;
    CatenaryOptions<double> o;
  };
  std::vector<Case> cases = {{nan, 0, 10, {}},  {8, 3, 1e-7, {}},  {8, 3, 2e9, {}},
                             {2e9, 3, 3e9, {}}, {8, 1e10, 10, {}}, {-1, 3, 10, {}}};
  CatenaryOptions<double> o;
  o.EA = -1;
  cases.push_back({8, 3, 10, o});
  o = {};
  o.EA = 1e300;
  cases.push_back({8, 3, 10, o});
  o = {};
  o.max_iterations = 0;
  cases.push_back({8, 3, 10, o});
  o = {};
  o.residual_tolerance = nan;
  cases.push_back({8, 3, 10, o});
  for (const Case& c : cases) {
    INFO("D = " << c.D << ", dz = " << c.dz << ", L = " << c.L);
    CHECK(kc::solve_catenary(c.D, c.dz, c.L, c.o).status == CatenaryStatus::invalid_input);
    CHECK(kt::solve_catenary(c.D, c.dz, c.L, c.o).status == CatenaryStatus::invalid_input);
  }
  CHECK(kc::solve_catenary(8.0, 3.0, 10.0).status == CatenaryStatus::converged);
}
