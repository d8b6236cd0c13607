// Line failure (TetherParameters::breaking_strength, kelp/tether/failure.hpp): under a slow load
// ramp the line parts at its most loaded segment when the quasi-static tension worked by hand
// reaches the breaking strength, in every integrator; the pieces then hang from their ends as
// free lines, nothing throws, and a strength of 0 or infinity never parts.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "kelp/tether/integrators.hpp"
#include "kelp/tether/lumped_mass.hpp"
#include "tether_test_support.hpp"

namespace kt = kelp::tether;
using kelp::Vector3;

namespace {

// A 10 m line of 10 segments, heavier than water, hanging between a fixed top (5 m down) and a
// bottom end that moves straight down at v = 1 cm/s: a slow load ramp (EA/L·v = 10 N/s).
struct Ramp {
  kelp_test::TestWater<double> water;
  kt::TetherModel<double> model;
  kt::TetherWorkspace<double> ws;
  kt::TetherState<double> state;
  Vector3<double> top{0, 0, 5}, bottom0;
  double v = 0.01, stretch0 = 0.03;

  static kt::TetherParameters<double> line(double strength) {
    kt::TetherParameters<double> p;
    p.segments = 10;
    p.length = 10.0;
    p.diameter = 0.01;
    p.mass_per_length = 0.2;  // 1.2 N/m in water
    p.axial_stiffness = 1e4;
    p.internal_damping = 100.0;
    p.breaking_strength = strength;
    return p;
  }
  explicit Ramp(double strength) : model(line(strength)), ws(model) {
    bottom0 = top + Vector3<double>(0, 0, 10.0 + stretch0);
    state = kt::straight_line_state(model, top, bottom0);
    kt::StaticOptions<double> o;
    o.force_tolerance = 1e-6;
    REQUIRE(kt::solve_static_equilibrium(model, ws, water, state, boundary(0.0), o).converged);
  }
  kt::TetherBoundary<double> boundary(double t) const {
    kt::TetherBoundary<double> b = kt::TetherBoundary<double>::fixed(top, bottom0);
    b.end.position.z() += v * t;
    b.end.velocity.z() = v;
    return b;
  }
  // Quasi-static tension of the top segment (worked by hand): the elastic tensions sum to
  // EA (D − L)/l, each segment carries the wet weight w l of every free node below it, and every
  // segment stretches at v/N (dashpot BA v/L): T_0 = EA (D − L)/L + w (L − l)/2 + BA v / L.
  // The time at which it reaches `strength`.
  double expected_time(double strength) const {
    const auto& p = model.parameters();
    const double w = model.submerged_weight_per_length(water.rho, water.g);
    const double l = model.segment_length();
    const double extension =
        (strength - w * (p.length - l) / 2.0 - p.internal_damping * v / p.length) * p.length /
        p.axial_stiffness;
    return (extension - stretch0) / v;
  }
};

}  // namespace

TEST_CASE("line failure: a load ramp parts the most loaded segment at the breaking strength",
          "[tether][failure]") {
  const double strength = 100.0;
  for (const auto& [name, integrator, max_dt] :
       {std::make_tuple("bdf2", kt::Integrator::bdf2, 0.01),
        std::make_tuple("implicit Euler", kt::Integrator::implicit_euler, 0.01),
        std::make_tuple("rk4", kt::Integrator::rk4, 0.0)}) {
    INFO(name);
    Ramp r(strength);
    // RK4 in sub-steps of its stable step (the dashpot is stiff: BA/l over the node mass).
    const double h =
        max_dt > 0 ? max_dt : 0.9 * kt::estimate_stable_dt(r.model, integrator, r.water.rho);
    const double t_expected = r.expected_time(strength);
    int partings = 0;
    kt::LineFailure<double> event;
    const double dt = 0.01;
    for (int k = 0; k < 4000; ++k) {
      const double t = r.state.time;
      kt::StepReport<double> rep;
      REQUIRE_NOTHROW(rep = kt::advance(r.model, r.ws, r.water, r.state, r.boundary(t), dt,
                                        kt::AdvanceOptions<double>(h, integrator)));
      if (rep.partings > 0 && partings == 0) event = rep.failure;
      partings += rep.partings;
    }
    INFO("parted at " << event.time << " s (expected " << t_expected << " s), segment "
                      << event.segment << ", " << event.tension << " N");
    // Once, at the top segment (the most loaded: it carries the whole wet weight), when the
    // ramp's tension reaches the strength: within 0.05 s = 0.5 N of the ramp.
    CHECK(partings == 1);
    CHECK(event.segment == 0);
    CHECK(event.tension > strength);
    CHECK(event.tension < strength + 1.0);
    CHECK(std::abs(event.time - t_expected) < 0.05);
    CHECK(event.position.z() == Approx(r.top.z() + 0.5).margin(0.01));  // the top segment's middle
    REQUIRE(r.state.parted_segments() == 1);
    CHECK(r.state.parted(0) == 1);
    // Afterwards (40 s − 6.5 s of fall and settling) the top segment carries nothing and the
    // rest of the line hangs from the bottom end as a free line: its free end (node 1) falls
    // from 9 m above that end to hanging below it (8.2 m at 40 s in every scheme: the light
    // piece still swings slowly under its 9 m length).
    CHECK(kt::segment_axial_force(r.model, r.state, 0) == 0.0);
    CHECK(r.state.position.allFinite());
    const double hang = r.state.position(2, 1) - r.state.position(2, 10);
    CHECK(hang > 7.5);
    CHECK(hang < 9.1);
  }
}

TEST_CASE("line failure: a line parted in the middle falls as two free lines",
          "[tether][failure]") {
  // A slack heavy line between two fixed ends 6 m apart at 5 m depth, parted at segment 4 of 10
  // by hand: each piece swings down and hangs below its own end (the implicit and the explicit
  // schemes alike), its free end's tangent along its own last segment.
  for (const auto& [name, integrator, max_dt] :
       {std::make_tuple("bdf2", kt::Integrator::bdf2, 0.01),
        std::make_tuple("rk4", kt::Integrator::rk4, 0.0)}) {
    INFO(name);
    kelp_test::TestWater<double> water;
    kt::TetherParameters<double> p = Ramp::line(0.0);
    p.bending_stiffness = 0.01;
    const kt::TetherModel<double> model(p);
    const double h =
        max_dt > 0 ? max_dt : 0.9 * kt::estimate_stable_dt(model, integrator, water.rho);
    kt::TetherWorkspace<double> ws(model);
    const Vector3<double> a(0, 0, 5), b(6, 0, 5);
    kt::TetherState<double> s = kt::straight_line_state(model, a, b);
    // Start from the hanging catenary (the straight state is shorter than the line: slack).
    REQUIRE(
        kt::solve_static_equilibrium(model, ws, water, s, kt::TetherBoundary<double>::fixed(a, b))
            .converged);
    s.parted(4) = 1;
    for (int k = 0; k < 3000; ++k)
      REQUIRE_NOTHROW(kt::advance(model, ws, water, s, kt::TetherBoundary<double>::fixed(a, b),
                                  0.01, kt::AdvanceOptions<double>(h, integrator)));
    REQUIRE(s.position.allFinite());
    // Piece A: nodes 0–4, 4 m below a; piece B: nodes 5–10, 5 m below b (within 5 cm).
    CHECK(s.position(2, 4) - a.z() == Approx(4.0).margin(0.05));
    CHECK(std::abs(s.position(0, 4) - a.x()) < 0.05);
    CHECK(s.position(2, 5) - b.z() == Approx(5.0).margin(0.05));
    CHECK(std::abs(s.position(0, 5) - b.x()) < 0.05);
    // The free ends' tangents are their own segments' (vertical), not the gap between them.
    kt::compute_forces(model, ws, water, s.time, s.position, s.velocity);
    CHECK(std::abs(ws.tangent(2, 4)) > 0.999);
    CHECK(std::abs(ws.tangent(2, 5)) > 0.999);
    CHECK(ws.tension(4) == 0.0);
  }
}

TEST_CASE("line failure: a strength of 0 or infinity never parts; negative or NaN is refused",
          "[tether][failure]") {
  for (double strength : {0.0, std::numeric_limits<double>::infinity()}) {
    Ramp r(strength);
    for (int k = 0; k < 1500; ++k)
      CHECK(kt::advance(r.model, r.ws, r.water, r.state, r.boundary(r.state.time), 0.01).partings ==
            0);
    CHECK(r.state.parted_segments() == 0);
  }
  kt::TetherParameters<double> p;
  p.breaking_strength = -1.0;
  CHECK_THROWS_AS(kt::validate(p), kelp::invalid_argument);
  p.breaking_strength = std::nan("");
  CHECK_THROWS_AS(kt::validate(p), kelp::invalid_argument);
}
