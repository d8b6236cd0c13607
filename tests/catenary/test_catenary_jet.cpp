// Automatic differentiation: a and c as ceres::Jet, derivatives with respect to D, dz and L
// (implicit function theorem inside the solvers) against central finite differences.
#include <catch2/catch.hpp>
#include <cmath>
#include <type_traits>

#include "kelp/ceres/catenary_solver.hpp"
#include "kelp/tether/catenary.hpp"

using J3 = ceres::Jet<double, 3>;

// Every public class and solver instantiated for a Jet scalar.
template class kelp::tether::CatenaryShape<J3>;
template struct kelp::tether::CatenaryResult<J3>;
template struct kelp::tether::CatenaryOptions<J3>;
template kelp::tether::CatenaryResult<J3> kelp::tether::solve_catenary(
    J3, J3, J3, const kelp::tether::CatenaryOptions<J3>&);
template kelp::tether::CatenaryResult<J3> kelp::ceres_solver::solve_catenary(
    J3, J3, J3, double, double, const kelp::tether::CatenaryOptions<J3>&);

namespace kelp {
// Inside namespace kelp, `ceres::Jet` still names Ceres' Jet (re-exported by kelp::ceres).
static_assert(std::is_same<ceres::Jet<double, 3>, ::ceres::Jet<double, 3>>::value, "");
}  // namespace kelp
using kelp::tether::CatenaryStatus;
namespace kt = kelp::tether;

namespace {

struct Fd {
  double a[3], c[3];
};

// Central differences of the double fast path, step h relative to the scale of each input.
Fd finite_differences(double D, double dz, double L) {
  Fd out{};
  const double x[3] = {D, dz, L};
  for (int k = 0; k < 3; ++k) {
    const double h = 1e-6 * L;
    double p[3] = {x[0], x[1], x[2]}, m[3] = {x[0], x[1], x[2]};
    p[k] += h;
    m[k] -= h;
    const auto rp = kt::solve_catenary(p[0], p[1], p[2]);
    const auto rm = kt::solve_catenary(m[0], m[1], m[2]);
    out.a[k] = (rp.a - rm.a) / (2 * h);
    out.c[k] = (rp.c - rm.c) / (2 * h);
  }
  return out;
}

J3 seed(double v, int k) { return J3(v, k); }

}  // namespace

TEST_CASE("Jet: da, dc by implicit differentiation match finite differences", "[catenary][jet]") {
  const double cases[][3] = {{10, 5, 20},   {10, -5, 20},    {3, 0, 20},  {19, 1, 20},
                             {0.02, 8, 20}, {12, -9, 15.01}, {7, 3, 100}, {1, 0.5, 1.2}};
  for (const auto& g : cases) {
    const auto r = kt::solve_catenary(seed(g[0], 0), seed(g[1], 1), seed(g[2], 2));
    REQUIRE(r.status == CatenaryStatus::converged);
    const auto d = kt::solve_catenary(g[0], g[1], g[2]);
    CHECK(r.a.a == d.a);  // value parts identical to the double solve
    CHECK(r.c.a == d.c);
    const Fd fd = finite_differences(g[0], g[1], g[2]);
    for (int k = 0; k < 3; ++k) {
      INFO("geometry " << g[0] << ", " << g[1] << ", " << g[2] << ", input " << k);
      const double scale_a = std::abs(d.a) / g[2] + 1.0, scale_c = std::abs(d.c) / g[2] + 1.0;
      CHECK(r.a.v[k] == Approx(fd.a[k]).epsilon(1e-5).margin(1e-6 * scale_a));
      CHECK(r.c.v[k] == Approx(fd.c[k]).epsilon(1e-5).margin(1e-6 * scale_c));
    }
    // The Ceres path (IFT on the paper's equations) gives the same derivatives.
    const auto rc = kelp::ceres_solver::solve_catenary(seed(g[0], 0), seed(g[1], 1), seed(g[2], 2));
    REQUIRE(rc.status == CatenaryStatus::converged);
    for (int k = 0; k < 3; ++k) {
      CHECK(rc.a.v[k] == Approx(r.a.v[k]).epsilon(1e-8).margin(1e-12));
      CHECK(rc.c.v[k] == Approx(r.c.v[k]).epsilon(1e-8).margin(1e-12));
    }
  }
}

TEST_CASE("Jet: symmetric case has dc/dD = 1/2 and dc/dL = 0", "[catenary][jet]") {
  // c = D/2 - a atanh(dz/L): at dz = 0, dc/dD = 1/2, dc/dL = 0, dc/ddz = -a/L.
  const auto r = kt::solve_catenary(seed(6.0, 0), seed(0.0, 1), seed(10.0, 2));
  REQUIRE(r.status == CatenaryStatus::converged);
  CHECK(r.c.v[0] == Approx(0.5).epsilon(1e-14));
  CHECK(r.c.v[2] == Approx(0.0).margin(1e-14));
  CHECK(r.c.v[1] == Approx(-r.a.a / 10.0).epsilon(1e-13));
}

TEST_CASE("Jet: 3-D end force derivatives match finite differences", "[catenary][jet]") {
  // d(force on the end)/d(end position): the tether's stiffness matrix seen by the vehicle.
  const double w = 0.18;
  const Eigen::Vector3d start(0, 0, 2), end(8, 3, 1);
  kelp::Vector3<J3> s = start.cast<J3>(), e;
  for (int k = 0; k < 3; ++k) e[k] = J3(end[k], k);
  const auto shape = kt::catenary_between(s, e, J3(20.0), J3(w));
  REQUIRE(shape.status() == CatenaryStatus::converged);
  const auto f = shape.force_on_end();
  for (int k = 0; k < 3; ++k) {
    const double h = 1e-6;
    Eigen::Vector3d ep = end, em = end;
    ep[k] += h;
    em[k] -= h;
    const Eigen::Vector3d fp = kt::catenary_between(start, ep, 20.0, w).force_on_end();
    const Eigen::Vector3d fm = kt::catenary_between(start, em, 20.0, w).force_on_end();
    const Eigen::Vector3d dfd = (fp - fm) / (2 * h);
    for (int i = 0; i < 3; ++i) CHECK(f[i].v[k] == Approx(dfd[i]).epsilon(1e-5).margin(1e-7));
  }
}

TEST_CASE("Jet: grounded line's end force derivatives match finite differences",
          "[catenary][jet]") {
  // Seabed at 12 m, ends at 0.5 m and 3 m depth, 9 m apart, 25 m of tether (grounded, H > 0).
  kelp::tether::CatenaryOptions<double> od;
  od.seabed_depth = 12.0;
  kelp::tether::CatenaryOptions<J3> oj;
  oj.seabed_depth = 12.0;
  const double w = 0.3, L = 25.0;
  const Eigen::Vector3d start(1, -2, 0.5), end(8.2, 3.4, 3.0);
  kelp::Vector3<J3> s = start.cast<J3>(), e;
  for (int k = 0; k < 3; ++k) e[k] = J3(end[k], k);
  const auto shape = kt::catenary_between(s, e, J3(L), J3(w), oj);
  REQUIRE(shape.on_seabed());
  REQUIRE(shape.horizontal_tension().a > 0);
  const auto f = shape.force_on_end();
  for (int k = 0; k < 3; ++k) {
    const double h = 1e-6;
    Eigen::Vector3d ep = end, em = end;
    ep[k] += h;
    em[k] -= h;
    const Eigen::Vector3d fp = kt::catenary_between(start, ep, L, w, od).force_on_end();
    const Eigen::Vector3d fm = kt::catenary_between(start, em, L, w, od).force_on_end();
    const Eigen::Vector3d dfd = (fp - fm) / (2 * h);
    for (int i = 0; i < 3; ++i) CHECK(f[i].v[k] == Approx(dfd[i]).epsilon(1e-5).margin(1e-7));
  }
}
