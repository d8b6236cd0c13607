// Bending stiffness (TetherParameters::bending_stiffness) against a cantilever worked by hand:
// a line clamped at one end (EndMotion::direction) and loaded by a point force P at its free tip
// deflects by P L³/(3 EI) (Euler–Bernoulli, small deflection; e.g. Timoshenko & Gere, Mechanics of
// Materials, the cantilever with an end load). Neutrally buoyant line under water, so that the tip
// load is exactly the weight in water of the point mass at the free end, M g.
#include <catch2/catch.hpp>
#include <cmath>

#include "kelp/core/constants.hpp"
#include "kelp/tether/integrators.hpp"
#include "kelp/tether/lumped_mass.hpp"
#include "tether_test_support.hpp"

namespace kt = kelp::tether;
using kelp::Vector3;

namespace {

struct Cantilever {
  double length = 1.0, ei = 100.0, tip_mass = 0.0306;  // P = 0.300 N: δ = 1 mm = L/1000
  int segments = 20;
  bool clamped = true;
};

struct Result {
  double tip_deflection = 0, expected = 0;
  bool converged = false;
};

// Static shape of a horizontal line clamped at x = 0 (depth 10 m) along +x, its far end free.
Result solve(const Cantilever& c) {
  kelp_test::TestWater<double> water;
  kt::TetherParameters<double> p;
  p.segments = c.segments;
  p.length = c.length;
  p.diameter = 0.01;
  p.mass_per_length = water.rho * kelp::pi * p.diameter * p.diameter / 4.0;  // neutral
  // Inextensible at these loads (strain < 1e-6), yet resolvable: the static solve's tolerance
  // below must stay above the rounding of the axial force, EA/l·ε|x| (a stiffer line, 1e7 N,
  // stalls the pseudo-transient solve at 1e-9 N: it reports not converged).
  p.axial_stiffness = 1e6;
  p.bending_stiffness = c.ei;
  p.end_mode = kt::EndMode::free;
  p.end_point_mass = c.tip_mass;
  const kt::TetherModel<double> model(p);
  kt::TetherWorkspace<double> ws(model);
  const Vector3<double> a(0, 0, 10), b(c.length, 0, 10);
  kt::TetherState<double> s = kt::straight_line_state(model, a, b);
  kt::TetherBoundary<double> bd = kt::TetherBoundary<double>::fixed(a, b);
  if (c.clamped) bd.start.direction = Vector3<double>(1, 0, 0);
  kt::StaticOptions<double> o;
  o.force_tolerance = 1e-6;  // against P = 0.3 N
  o.max_iterations = 400;
  const kt::StaticResult<double> r = kt::solve_static_equilibrium(model, ws, water, s, bd, o);
  Result out;
  out.converged = r.converged;
  out.tip_deflection = s.position(2, c.segments) - 10.0;  // NED z down: positive = downwards
  const double P = c.tip_mass * water.g;
  out.expected = P * std::pow(c.length, 3) / (3.0 * c.ei);
  return out;
}

}  // namespace

TEST_CASE("bending: a clamped cantilever's tip deflects by P L^3 / (3 EI) within 2 %",
          "[tether][bending]") {
  for (int n : {10, 20, 40}) {
    Cantilever c;
    c.segments = n;
    const Result r = solve(c);
    INFO("N = " << n << ": tip " << r.tip_deflection << " m, P L^3/(3EI) " << r.expected << " m");
    REQUIRE(r.converged);
    const double error = r.tip_deflection / r.expected - 1.0;
    CHECK(std::abs(error) < 0.02);
    // Second order in l: the rotational springs sum P(L − x)²/EI over the nodes as the
    // trapezoidal rule (half weight at the clamp, hence its stiffness 2EI/l), whose error is
    // (L/12) l² · 2P/EI, i.e. 1/(2N²) of P L³/(3EI): 0.5 %, 0.125 %, 0.031 % (measured the same).
    // With the clamp's stiffness EI/l the error would be 1.5/N (7.5 % at N = 20).
    CHECK(error == Approx(0.5 / (n * n)).epsilon(0.2));
  }
  // Twice the stiffness, half the deflection; twice the length, eight times (still small).
  Cantilever stiff;
  stiff.ei = 200.0;
  const Result rs = solve(stiff);
  REQUIRE(rs.converged);
  CHECK(std::abs(rs.tip_deflection / rs.expected - 1.0) < 0.02);
}

TEST_CASE("bending: BDF2 settles the clamped cantilever at the same deflection",
          "[tether][bending]") {
  // The implicit scheme with bending and a clamp (its Newton matrix: the adaptive Jacobian):
  // released straight, the line swings down and its drag settles it within 20 s.
  Cantilever c;
  kelp_test::TestWater<double> water;
  kt::TetherParameters<double> p;
  p.segments = c.segments;
  p.length = c.length;
  p.diameter = 0.01;
  p.mass_per_length = water.rho * kelp::pi * p.diameter * p.diameter / 4.0;
  p.axial_stiffness = 1e7;
  p.bending_stiffness = c.ei;
  p.end_mode = kt::EndMode::free;
  p.end_point_mass = c.tip_mass;
  const kt::TetherModel<double> model(p);
  kt::TetherWorkspace<double> ws(model);
  const Vector3<double> a(0, 0, 10), b(c.length, 0, 10);
  kt::TetherState<double> s = kt::straight_line_state(model, a, b);
  kt::TetherBoundary<double> bd = kt::TetherBoundary<double>::fixed(a, b);
  bd.start.direction = Vector3<double>(1, 0, 0);
  for (int k = 0; k < 2000; ++k) (void)kt::step_bdf2(model, ws, water, s, bd, 0.01);
  const double expected = c.tip_mass * water.g * std::pow(c.length, 3) / (3.0 * c.ei);
  const double tip = s.position(2, c.segments) - 10.0;
  INFO("tip " << tip << " m, P L^3/(3EI) " << expected << " m");
  CHECK(std::abs(tip / expected - 1.0) < 0.02);
}

TEST_CASE("bending: without the clamp the line is pinned and hangs from its end",
          "[tether][bending]") {
  // The check can fail: a pinned end carries no moment, so the same line (no bending resistance
  // at its root) swings down far beyond the cantilever's deflection.
  Cantilever c;
  c.clamped = false;
  const Result r = solve(c);
  INFO("tip " << r.tip_deflection << " m against " << r.expected << " m clamped");
  CHECK(r.tip_deflection > 10.0 * r.expected);
}
