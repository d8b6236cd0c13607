// The fast catenary path: the reference case, the statuses and the paper's equations.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <limits>
#include <new>

#include "kelp/tether/catenary.hpp"
#include "random_geometry.hpp"

using kelp::tether::CatenaryOptions;
using kelp::tether::CatenaryStatus;
using kelp::tether::solve_catenary;
using kelp_test::paper_residual_ld;

// Global operator new of this test executable, replaced to count calls: solve_catenary works on
// scalars and never touches an Eigen object, so EIGEN_RUNTIME_NO_MALLOC cannot see an allocation
// there (a std::vector or std::function would go unnoticed); this counter does.
namespace {
std::size_t g_operator_new_calls = 0;
}  // namespace

// Every non-array, non-aligned form is replaced, new and delete together, all on malloc/free: an
// allocator that replaces the library's (AddressSanitizer's, in the sanitizer build) must not
// see memory from one family freed by the other (Catch2 allocates with `new (std::nothrow)`).
// The array forms stay the library's, new[] and delete[] both.
void* operator new(std::size_t size) {
  ++g_operator_new_calls;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  ++g_operator_new_calls;
  return std::malloc(size == 0 ? 1 : size);
}
// GCC (12, -O1) inlines these into a test's `::operator delete(::operator new(16))` and then
// takes std::free of a pointer from operator new for a mismatch; here both are malloc/free.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

TEST_CASE("reference case of docs/equations.md to 6 digits", "[catenary]") {
  // docs/equations.md: D = 10, dz = +5, L = 20 -> a = 2.358583, c = 4.397588 (MoorPy, FAST-v7 and
  // an independent Newton solve agree).
  const auto r = solve_catenary(10.0, 5.0, 20.0);
  REQUIRE(r.status == CatenaryStatus::converged);
  CHECK(r.a == Approx(2.358583).epsilon(5e-7));
  CHECK(r.c == Approx(4.397588).epsilon(5e-7));
  CHECK(r.residual < 1e-14);
  CHECK(paper_residual_ld(r.a, r.c, 10, 5, 20) < 1e-14L);
  CHECK(r.iterations >= 1);
  CHECK(r.iterations <= 4);
}

TEMPLATE_TEST_CASE("reference case in float and double", "[catenary]", float, double) {
  const auto r = solve_catenary<TestType>(TestType(10), TestType(5), TestType(20));
  REQUIRE(r.status == CatenaryStatus::converged);
  CHECK(double(r.a) == Approx(2.358583).epsilon(2e-6));
  CHECK(double(r.c) == Approx(4.397588).epsilon(2e-6));
  // The residual is evaluated at the returned (possibly float-rounded) a, c.
  CHECK(double(r.residual) < (std::is_same<TestType, float>::value ? 1e-6 : 1e-14));
}

TEMPLATE_TEST_CASE("symmetric ends put the vertex midway", "[catenary]", float, double) {
  // dz = 0 -> atanh(0) = 0 -> c = D/2 exactly; and 2a sinh(D/2a) = L.
  for (double D : {1e-3, 0.5, 7.0, 19.99}) {
    const auto r = solve_catenary<TestType>(TestType(D), TestType(0), TestType(20));
    REQUIRE(r.status == CatenaryStatus::converged);
    CHECK(double(r.c) == Approx(D / 2).epsilon(1e-6));
    const double a = r.a;
    CHECK(2 * a * std::sinh(D / (2 * a)) ==
          Approx(20.0).epsilon(std::is_same<TestType, float>::value ? 1e-5 : 1e-12));
  }
}

TEST_CASE("near-taut line: L/chord - 1 = 1e-8", "[catenary]") {
  for (double t : {-0.8, 0.0, 0.3, 0.95}) {
    const double chord = 10.0;
    const double dz = t * chord, D = std::sqrt(chord * chord - dz * dz);
    const double L = chord * (1 + 1e-8);
    const auto r = solve_catenary(D, dz, L);
    REQUIRE(r.status == CatenaryStatus::converged);
    CHECK(r.residual <= 1e-10);
    CHECK(paper_residual_ld(r.a, r.c, D, dz, L) <= 1e-10L);
    // Small-sag limit (parabola): the extra length is L - chord ~ D^3 / (24 a^2) * (chord/D)^3 for
    // dz = 0; for any dz, 2a sinh(D/2a) = sqrt(L^2 - dz^2) -> a ~ D sqrt(D / (24 (sqrt(L^2-dz^2) -
    // D))).
    const double excess = std::sqrt(L * L - dz * dz) - D;
    const double a_parabola = D * std::sqrt(D / (24 * excess));
    CHECK(r.a == Approx(a_parabola).epsilon(1e-4));
  }
}

TEST_CASE("near-vertical line: D/L = 1e-6", "[catenary]") {
  for (double dz : {-15.0, 0.0, 12.0}) {
    const double L = 20.0, D = 1e-6 * L;
    const auto r = solve_catenary(D, dz, L);
    REQUIRE(r.status == CatenaryStatus::converged);
    CHECK(r.residual <= 1e-10);
    CHECK(paper_residual_ld(r.a, r.c, D, dz, L) <= 1e-10L);
    // a -> 0 and the vertex sits between the ends, at depth (L - dz)/2 below the start.
    CHECK(r.a < 1e-6);
    CHECK(r.c > 0);
    CHECK(r.c < D);
    const double z_vertex = r.a - r.a * std::cosh(r.c / r.a);
    CHECK(z_vertex == Approx(-(L - dz) / 2).epsilon(1e-6));
  }
}

TEMPLATE_TEST_CASE("taut, vertical and invalid statuses", "[catenary]", float, double) {
  using T = TestType;
  const T nan = std::numeric_limits<T>::quiet_NaN();
  const T inf = std::numeric_limits<T>::infinity();
  // L = chord exactly (3-4-5) and L < chord: taut, straight line.
  auto r = solve_catenary<T>(T(3), T(4), T(5));
  CHECK(r.status == CatenaryStatus::taut);
  CHECK(std::isinf(double(r.a)));
  CHECK(double(r.taut_tension) == 0.0);
  CatenaryOptions<T> opt;
  opt.EA = T(1e5);
  r = solve_catenary<T>(T(3), T(4), T(4.9), opt);
  CHECK(r.status == CatenaryStatus::taut);
  // Elastic tension EA (chord - L)/L = 1e5 * 0.1 / 4.9.
  CHECK(double(r.taut_tension) == Approx(1e5 * 0.1 / 4.9).epsilon(1e-5));
  CHECK(solve_catenary<T>(T(0), T(-4), T(4)).status == CatenaryStatus::taut);
  // Vertical: D = 0 with slack, and D below the threshold.
  r = solve_catenary<T>(T(0), T(2), T(5));
  CHECK(r.status == CatenaryStatus::vertical);
  CHECK(double(r.a) == 0.0);
  CHECK(double(r.c) == 0.0);
  opt.vertical_tolerance = 1e-3;
  CHECK(solve_catenary<T>(T(1e-3), T(2), T(5), opt).status == CatenaryStatus::vertical);
  CHECK(solve_catenary<T>(T(1e-2), T(2), T(5), opt).status == CatenaryStatus::converged);
  // Invalid: NaN, Inf, L <= 0, D < 0 -- statuses, never exceptions.
  CHECK(solve_catenary<T>(nan, T(1), T(5)).status == CatenaryStatus::invalid_input);
  CHECK(solve_catenary<T>(T(1), inf, T(5)).status == CatenaryStatus::invalid_input);
  CHECK(solve_catenary<T>(T(1), T(1), inf).status == CatenaryStatus::invalid_input);
  CHECK(solve_catenary<T>(T(1), T(0), T(0)).status == CatenaryStatus::invalid_input);
  CHECK(solve_catenary<T>(T(1), T(0), T(-3)).status == CatenaryStatus::invalid_input);
  CHECK(solve_catenary<T>(T(-1), T(0), T(3)).status == CatenaryStatus::invalid_input);
  CHECK(std::isnan(double(solve_catenary<T>(nan, T(1), T(5)).a)));
}

TEST_CASE("iteration limit is reported as max_iterations", "[catenary]") {
  CatenaryOptions<double> opt;
  opt.max_iterations = 1;
  opt.tolerance = 0.0;  // never satisfied unless the residual is exactly zero
  const auto r = solve_catenary(10.0, 5.0, 20.0, opt);
  CHECK(r.status == CatenaryStatus::max_iterations);
  CHECK(r.iterations == 1);
  CHECK(std::isfinite(r.a));
}

TEST_CASE("the fast path and the 3-D helper do not allocate", "[catenary]") {
  // The instrument is live: a call to the global operator new is counted.
  const std::size_t probe = g_operator_new_calls;
  ::operator delete(::operator new(16));
  REQUIRE(g_operator_new_calls == probe + 1);
  // solve_catenary on every status (scalars only: the operator new counter is the check), then
  // the 3-D helper and its queries (Eigen vectors: EIGEN_RUNTIME_NO_MALLOC checks them too).
  CatenaryOptions<double> opt;
  opt.EA = 1e4;
  const std::size_t before = g_operator_new_calls;
  Eigen::internal::set_is_malloc_allowed(false);
  const auto r = solve_catenary(10.0, 5.0, 20.0);
  const auto rf = solve_catenary(10.0f, 5.0f, 20.0f);
  const auto taut = solve_catenary(3.0, 4.0, 4.9, opt);
  const auto vertical = solve_catenary(0.0, 2.0, 5.0);
  const auto invalid = solve_catenary(-1.0, 0.0, 3.0);
  const kelp::Vector3<double> start(0, 0, 0), end(10, 0, -5);
  const auto shape = kelp::tether::catenary_between(start, end, 20.0, 0.2);
  const kelp::Vector3<double> f = shape.force_on_start() + shape.force_on_end() +
                                  shape.point_at(7.0) + shape.vertex() + shape.lowest_point();
  const double t = shape.tension_at(3.0);
  Eigen::internal::set_is_malloc_allowed(true);
  const std::size_t after = g_operator_new_calls;
  CHECK(after == before);
  CHECK(r.status == CatenaryStatus::converged);
  CHECK(rf.status == CatenaryStatus::converged);
  CHECK(taut.status == CatenaryStatus::taut);
  CHECK(vertical.status == CatenaryStatus::vertical);
  CHECK(invalid.status == CatenaryStatus::invalid_input);
  CHECK(std::isfinite(f.sum() + t));
}
