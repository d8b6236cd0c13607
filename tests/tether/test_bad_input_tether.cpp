// Bad input at every public entry point of kelp/tether (lumped-mass model, integrators, statics,
// initial states): NaN, Inf, negative, zero, absurdly large, mismatched sizes, an empty or foreign
// workspace, out-of-range enums. Each must answer kelp::invalid_argument, and a state passed in
// must be unchanged bit for bit after the throw.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/integrators.hpp"
#include "kelp/tether/lumped_mass.hpp"
#include "kelp/tether/presets.hpp"
#include "tether_test_support.hpp"

namespace kt = kelp::tether;
using kelp::Matrix3X;
using kelp::Vector3;

namespace {

const double nan_ = std::numeric_limits<double>::quiet_NaN();
const double inf_ = std::numeric_limits<double>::infinity();

using kelp_test::same_bits;

bool same_state(const kt::TetherStated& a, const kt::TetherStated& b) {
  return same_bits(a.position, b.position) && same_bits(a.velocity, b.velocity) &&
         same_bits(a.previous_position, b.previous_position) &&
         same_bits(a.previous_velocity, b.previous_velocity) &&
         same_bits(a.acceleration, b.acceleration) && a.has_acceleration == b.has_acceleration &&
         std::memcmp(&a.time, &b.time, sizeof a.time) == 0 &&
         std::memcmp(&a.time_carry, &b.time_carry, sizeof a.time_carry) == 0 &&
         std::memcmp(&a.previous_dt, &b.previous_dt, sizeof a.previous_dt) == 0;
}

// A 10-segment line hanging between two fixed points, one step taken (so it has a history).
struct Line {
  kt::TetherParametersd params = kelp_test::benchmark_line<double>(10);
  kt::TetherModeld model{params};
  kt::TetherWorkspaced ws{model};
  kelp_test::TestWater<double> water;
  kt::TetherBoundaryd boundary =
      kt::TetherBoundaryd::fixed(Vector3<double>(0, 0, 1), Vector3<double>(15, 0, 6));
  kt::TetherStated state;
  Line() {
    state =
        kt::catenary_initial_state(model, water, boundary.start.position, boundary.end.position);
    (void)kt::step(model, ws, water, state, boundary, 0.01, {kt::Integrator::bdf2});
  }
};

// Requires `f` to throw kelp::invalid_argument and to leave `state` as it found it.
void require_refused(const std::string& what, kt::TetherStated& state,
                     const std::function<void()>& f) {
  INFO(what);
  const kt::TetherStated before = state;
  REQUIRE_THROWS_AS(f(), kelp::invalid_argument);
  REQUIRE(same_state(before, state));
}

}  // namespace

TEST_CASE("Tether parameters: NaN, Inf, negative, zero and absurd values are refused",
          "[tether][bad_input]") {
  using P = kt::TetherParametersd;
  struct Field {
    const char* name;
    double P::*member;
    bool zero_ok;
  };
  const std::vector<Field> fields = {
      {"length", &P::length, false},
      {"diameter", &P::diameter, false},
      {"mass_per_length", &P::mass_per_length, false},
      {"axial_stiffness", &P::axial_stiffness, false},
      {"internal_damping", &P::internal_damping, true},
      {"internal_damping_ratio", &P::internal_damping_ratio, true},
      {"bending_stiffness", &P::bending_stiffness, true},
      {"normal_drag", &P::normal_drag, true},
      {"tangential_drag", &P::tangential_drag, true},
      {"normal_added_mass", &P::normal_added_mass, true},
      {"tangential_added_mass", &P::tangential_added_mass, true},
      {"seabed_stiffness", &P::seabed_stiffness, true},
      {"seabed_damping", &P::seabed_damping, true},
      {"seabed_damping_depth", &P::seabed_damping_depth, true},
      {"seabed_friction", &P::seabed_friction, true},
      {"friction_velocity", &P::friction_velocity, false},
      {"start_point_mass", &P::start_point_mass, true},
      {"end_point_mass", &P::end_point_mass, true},
  };
  for (const Field& f : fields) {
    std::vector<double> bad = {nan_, inf_, -inf_, -1.0, 1e300};
    if (!f.zero_ok) bad.push_back(0.0);
    for (const double value : bad) {
      P p;
      p.*(f.member) = value;
      INFO(f.name << " = " << value);
      REQUIRE_THROWS_AS(kt::TetherModeld(p), kelp::invalid_argument);
      // The message names the field.
      try {
        kt::TetherModeld m(p);
      } catch (const kelp::invalid_argument& e) {
        CHECK(std::string(e.what()).find(f.name) != std::string::npos);
      }
    }
    // A value inside the documented range is accepted (the bounds are not too tight).
    P p;
    p.*(f.member) = f.zero_ok ? 0.0 : 0.5 * (p.*(f.member));
    CHECK_NOTHROW(kt::TetherModeld(p));
  }
  // Tiny lengths whose derived constants overflow: EA/l = 1e5 N / 1e-310 m.
  for (const double length : {1e-300, 1e-310}) {
    P p;
    p.length = length;
    INFO("length = " << length);
    REQUIRE_THROWS_AS(kt::TetherModeld(p), kelp::invalid_argument);
  }
  for (const int segments : {0, -1, 2000000}) {
    P p;
    p.segments = segments;
    INFO("segments = " << segments);
    REQUIRE_THROWS_AS(kt::TetherModeld(p), kelp::invalid_argument);
  }
  P p;
  p.start_mode = static_cast<kt::EndMode>(7);
  REQUIRE_THROWS_AS(kt::TetherModeld(p), kelp::invalid_argument);
  p = P{};
  p.end_mode = static_cast<kt::EndMode>(-1);
  REQUIRE_THROWS_AS(kt::TetherModeld(p), kelp::invalid_argument);
  // Real tethers sit well inside the bounds: a 1 km steel mooring chain and a 2 m micro-tether.
  P chain;
  chain.segments = 200;
  chain.length = 1000;
  chain.diameter = 0.15;
  chain.mass_per_length = 450;
  chain.axial_stiffness = 2e9;
  CHECK_NOTHROW(kt::TetherModeld(chain));
  P micro;
  micro.segments = 40;
  micro.length = 2;
  micro.diameter = 0.001;
  micro.mass_per_length = 0.001;
  micro.axial_stiffness = 500;
  CHECK_NOTHROW(kt::TetherModeld(micro));
}

TEST_CASE("Tether low-level functions refuse an empty or foreign workspace and mismatched sizes",
          "[tether][bad_input]") {
  Line line;
  const kt::TetherModeld& model = line.model;
  kt::TetherWorkspaced empty;
  kt::TetherWorkspaced foreign{kt::TetherModeld(kelp_test::benchmark_line<double>(7))};
  const Matrix3X<double>& x = line.state.position;
  const Matrix3X<double>& v = line.state.velocity;
  const Vector3<double> zero = Vector3<double>::Zero();
  Matrix3X<double> short_x = x.leftCols(5), short_v = v.leftCols(5);
  for (kt::TetherWorkspaced* ws : {&empty, &foreign}) {
    REQUIRE_THROWS_AS(kt::compute_forces(model, *ws, line.water, 0.0, x, v),
                      kelp::invalid_argument);
    REQUIRE_THROWS_AS(kt::compute_forces<true>(model, *ws, line.water, 0.0, x, v),
                      kelp::invalid_argument);
    Matrix3X<double> acc(3, model.nodes());
    REQUIRE_THROWS_AS(kt::accelerations_from_forces(model, *ws, zero, zero, acc),
                      kelp::invalid_argument);
    REQUIRE_THROWS_AS(kt::end_forces_from_workspace(model, *ws, line.boundary),
                      kelp::invalid_argument);
    require_refused("step with a foreign workspace", line.state, [&] {
      (void)kt::step(model, *ws, line.water, line.state, line.boundary, 0.01,
                     {kt::Integrator::rk4});
    });
    require_refused("static solve with a foreign workspace", line.state, [&] {
      (void)kt::solve_static_equilibrium(model, *ws, line.water, line.state, line.boundary);
    });
  }
  // A workspace with one buffer resized by hand is foreign too.
  kt::TetherWorkspaced edited{model};
  edited.tension.resize(3);
  REQUIRE_THROWS_AS(kt::compute_forces(model, edited, line.water, 0.0, x, v),
                    kelp::invalid_argument);
  // Positions and velocities of the wrong size.
  kt::TetherWorkspaced& ws = line.ws;
  REQUIRE_THROWS_AS(kt::compute_forces(model, ws, line.water, 0.0, short_x, v),
                    kelp::invalid_argument);
  REQUIRE_THROWS_AS(kt::compute_forces(model, ws, line.water, 0.0, x, short_v),
                    kelp::invalid_argument);
  // Non-finite positions, velocities or time: refused, not NaN forces.
  Matrix3X<double> bad_x = x, bad_v = v;
  bad_x(1, 4) = nan_;
  bad_v(2, 3) = inf_;
  REQUIRE_THROWS_AS(kt::compute_forces(model, ws, line.water, 0.0, bad_x, v),
                    kelp::invalid_argument);
  REQUIRE_THROWS_AS(kt::compute_forces(model, ws, line.water, 0.0, x, bad_v),
                    kelp::invalid_argument);
  REQUIRE_THROWS_AS(kt::compute_forces(model, ws, line.water, nan_, x, v), kelp::invalid_argument);
  // After all that the workspace still works and gives the forces of the state.
  kt::compute_forces(model, ws, line.water, 0.0, x, v);
  REQUIRE(kelp::all_finite(ws.force));
  Matrix3X<double> acc(3, model.nodes()), wrong(3, 4);
  REQUIRE_THROWS_AS(kt::accelerations_from_forces(model, ws, zero, zero, wrong),
                    kelp::invalid_argument);
  REQUIRE_THROWS_AS(
      kt::accelerations_from_forces(model, ws, Vector3<double>(nan_, 0, 0), zero, acc),
      kelp::invalid_argument);
  kt::TetherBoundaryd nan_boundary = line.boundary;
  nan_boundary.end.acceleration.x() = nan_;
  REQUIRE_THROWS_AS(kt::end_forces_from_workspace(model, ws, nan_boundary), kelp::invalid_argument);
  // Energy of a state that does not fit, or is not finite.
  kt::TetherStated empty_state;
  REQUIRE_THROWS_AS(kt::tether_energy(model, line.water, empty_state), kelp::invalid_argument);
  kt::TetherStated nan_state = line.state;
  nan_state.velocity(0, 2) = nan_;
  REQUIRE_THROWS_AS(kt::tether_energy(model, line.water, nan_state), kelp::invalid_argument);
  CHECK(std::isfinite(kt::tether_energy(model, line.water, line.state)));
}

TEST_CASE("Tether steps refuse bad input and leave the state unchanged", "[tether][bad_input]") {
  Line line;
  kt::TetherStated& state = line.state;
  REQUIRE(state.has_history());
  const auto step = [&](double dt, kt::Integrator integrator,
                        const kt::ImplicitOptionsd& options = {},
                        const kt::TetherBoundaryd* b = nullptr) {
    (void)kt::step(line.model, line.ws, line.water, state, b ? *b : line.boundary, dt,
                   {integrator, options});
  };
  const kt::Integrator all[] = {kt::Integrator::symplectic_euler, kt::Integrator::rk2,
                                kt::Integrator::rk4, kt::Integrator::implicit_euler,
                                kt::Integrator::bdf2};
  for (const kt::Integrator integrator : all) {
    INFO(kt::integrator_name(integrator));
    for (const double dt : {0.0, -0.01, nan_, inf_, -inf_})
      require_refused("dt", state, [&] { step(dt, integrator); });
    for (int k = 0; k < 6; ++k) {
      kt::TetherBoundaryd b = line.boundary;
      kt::EndMotion<double>& e = k < 3 ? b.start : b.end;
      Vector3<double>& field = k % 3 == 0 ? e.position : (k % 3 == 1 ? e.velocity : e.acceleration);
      field.y() = nan_;
      require_refused("boundary", state, [&] { step(0.01, integrator, {}, &b); });
    }
  }
  require_refused("integrator out of range", state,
                  [&] { step(0.01, static_cast<kt::Integrator>(42)); });
  // Invalid implicit options.
  const std::vector<std::function<void(kt::ImplicitOptionsd&)>> bad_options = {
      [](kt::ImplicitOptionsd& o) { o.max_iterations = 0; },
      [](kt::ImplicitOptionsd& o) { o.acceleration_tolerance = 0; },
      [](kt::ImplicitOptionsd& o) { o.acceleration_tolerance = nan_; },
      [](kt::ImplicitOptionsd& o) { o.acceleration_tolerance = inf_; },
      [](kt::ImplicitOptionsd& o) { o.slack_band = -0.1; },
      [](kt::ImplicitOptionsd& o) { o.slack_band = nan_; },
      [](kt::ImplicitOptionsd& o) { o.max_active_set_passes = 0; },
      [](kt::ImplicitOptionsd& o) { o.max_backtracks = -1; },
      [](kt::ImplicitOptionsd& o) { o.max_step_halvings = 31; },
  };
  for (std::size_t k = 0; k < bad_options.size(); ++k) {
    kt::ImplicitOptionsd o;
    bad_options[k](o);
    INFO("option case " << k);
    require_refused("implicit options", state, [&] { step(0.01, kt::Integrator::bdf2, o); });
    require_refused("advance with implicit options", state, [&] {
      (void)kt::advance(line.model, line.ws, line.water, state, line.boundary, 0.05,
                        {0.01, kt::Integrator::implicit_euler, o});
    });
  }
  // States that do not fit or are not finite are refused as they are.
  kt::TetherStated wrong = state;
  wrong.position.conservativeResize(3, 4);
  require_refused("state of the wrong size", wrong, [&] {
    (void)kt::step(line.model, line.ws, line.water, wrong, line.boundary, 0.01,
                   {kt::Integrator::rk4});
  });
  REQUIRE(state.has_acceleration);  // the accelerations of the step Line took
  for (int k = 0; k < 6; ++k) {
    kt::TetherStated s = state;
    if (k == 0) s.position(0, 3) = nan_;
    if (k == 1) s.velocity(2, 5) = -inf_;
    if (k == 2) s.time = nan_;
    if (k == 3) s.previous_position(1, 1) = nan_;
    if (k == 4) s.previous_dt = -1;
    if (k == 5) s.acceleration(2, 4) = nan_;
    for (const kt::Integrator integrator : all)
      require_refused("non-finite state", s, [&] {
        (void)kt::step(line.model, line.ws, line.water, s, line.boundary, 0.01, {integrator});
      });
  }
  // Driver arguments.
  for (const double d : {0.0, -1.0, nan_, inf_})
    require_refused("advance duration", state, [&] {
      (void)kt::advance(line.model, line.ws, line.water, state, line.boundary, d,
                        {0.01, kt::Integrator::rk4});
    });
  for (const double h : {0.0, -1.0, nan_, 1e-300})
    require_refused("advance max_dt", state, [&] {
      (void)kt::advance(line.model, line.ws, line.water, state, line.boundary, 1.0,
                        {h, kt::Integrator::rk4});
    });
  // The line still steps after all of this.
  const double t0 = state.time;
  step(0.01, kt::Integrator::bdf2);
  CHECK(state.time == Approx(t0 + 0.01));
}

TEST_CASE("Static solve and initial states refuse bad options before touching the state",
          "[tether][bad_input]") {
  Line line;
  kt::TetherStated& state = line.state;
  const std::vector<std::function<void(kt::StaticOptionsd&)>> bad = {
      [](kt::StaticOptionsd& o) { o.force_tolerance = nan_; },
      [](kt::StaticOptionsd& o) { o.force_tolerance = inf_; },
      [](kt::StaticOptionsd& o) { o.max_iterations = 0; },
      [](kt::StaticOptionsd& o) { o.initial_pseudo_dt = 0; },
      [](kt::StaticOptionsd& o) { o.initial_pseudo_dt = -0.05; },
      [](kt::StaticOptionsd& o) { o.initial_pseudo_dt = nan_; },
      [](kt::StaticOptionsd& o) { o.initial_pseudo_dt = inf_; },
  };
  for (std::size_t k = 0; k < bad.size(); ++k) {
    kt::StaticOptionsd o;
    bad[k](o);
    INFO("static option case " << k);
    require_refused("static options", state, [&] {
      (void)kt::solve_static_equilibrium(line.model, line.ws, line.water, state, line.boundary, o);
    });
    require_refused("static initial state options", state, [&] {
      (void)kt::static_initial_state(line.model, line.ws, line.water, line.boundary.start.position,
                                     line.boundary.end.position, state, o);
    });
  }
  require_refused("static initial state with a NaN end", state, [&] {
    (void)kt::static_initial_state(line.model, line.ws, line.water, Vector3<double>(0, nan_, 0),
                                   line.boundary.end.position, state);
  });
  kt::TetherBoundaryd b = line.boundary;
  b.start.position.z() = inf_;
  require_refused("static solve with an infinite end", state, [&] {
    (void)kt::solve_static_equilibrium(line.model, line.ws, line.water, state, b);
  });
  REQUIRE_THROWS_AS(kt::catenary_initial_state(line.model, line.water, Vector3<double>(nan_, 0, 0),
                                               line.boundary.end.position),
                    kelp::invalid_argument);
  REQUIRE_THROWS_AS(
      kt::straight_line_state(line.model, Vector3<double>(0, 0, 0), Vector3<double>(0, inf_, 0)),
      kelp::invalid_argument);
  // A good static solve still converges from the state.
  const kt::StaticResultd r =
      kt::solve_static_equilibrium(line.model, line.ws, line.water, state, line.boundary);
  CHECK(r.converged);
}

TEST_CASE("Stable time step estimate refuses non-physical water and safety factors",
          "[tether][bad_input]") {
  const kt::TetherModeld model(kelp_test::benchmark_line<double>(20));
  for (const double rho : {nan_, inf_, -1.0, 1e300})
    for (const kt::Integrator integrator : {kt::Integrator::rk4, kt::Integrator::bdf2}) {
      INFO("rho = " << rho);
      REQUIRE_THROWS_AS(kt::estimate_stable_dt(model, integrator, rho), kelp::invalid_argument);
    }
  for (const double safety : {nan_, inf_, 0.0, -0.5})
    REQUIRE_THROWS_AS(kt::estimate_stable_dt(model, kt::Integrator::rk4, 1025.0, safety),
                      kelp::invalid_argument);
  REQUIRE_THROWS_AS(kt::estimate_stable_dt(model, static_cast<kt::Integrator>(9)),
                    kelp::invalid_argument);
  REQUIRE_THROWS_AS(kt::estimate_stable_dt(model, static_cast<kt::Integrator>(-1)),
                    kelp::invalid_argument);
  for (const kt::Integrator i :
       {kt::Integrator::symplectic_euler, kt::Integrator::rk2, kt::Integrator::rk4,
        kt::Integrator::implicit_euler, kt::Integrator::bdf2})
    CHECK(kt::is_valid(i));
  CHECK_FALSE(kt::is_valid(static_cast<kt::Integrator>(5)));
  for (const double rho : {nan_, -1.0})
    REQUIRE_THROWS_AS(kt::highest_axial_frequency(model, rho), kelp::invalid_argument);
  // Vacuum (ρ = 0) is allowed and gives a finite step; tangential added mass does not lengthen
  // it (a node in air has none).
  kt::TetherParametersd p = kelp_test::benchmark_line<double>(20);
  p.tangential_added_mass = 0.5;
  const kt::TetherModeld with_cat(p);
  const double in_water = kt::estimate_stable_dt(with_cat, kt::Integrator::rk4, 1025.0);
  const double in_vacuum = kt::estimate_stable_dt(with_cat, kt::Integrator::rk4, 0.0);
  CHECK(std::isfinite(in_water));
  CHECK(std::isfinite(in_vacuum));
  CHECK(in_water == kt::estimate_stable_dt(model, kt::Integrator::rk4, 1025.0));
  // A speed bound that is negative, NaN or absurd is refused; so is RK2 on an undamped line.
  kt::StableDtOptionsd options;
  for (const double speed : {nan_, inf_, -1.0, 1e300}) {
    options.max_relative_speed = speed;
    REQUIRE_THROWS_AS(kt::estimate_stable_dt(model, kt::Integrator::rk4, options),
                      kelp::invalid_argument);
  }
  REQUIRE_THROWS_AS(kt::estimate_stable_dt(model, kt::Integrator::rk2), kelp::invalid_argument);
  CHECK(std::isinf(kt::estimate_stable_dt(model, kt::Integrator::bdf2, 1025.0)));
}

// The probe: a one-segment line between two kinematic ends got +infinity from RK2 and RK4
// (and "no stable step found" from symplectic Euler). Such a line has no free node: nothing is
// integrated, so no step is limited by stability, and the estimate refuses the question instead
// of answering with a number a step would then refuse.
TEST_CASE("Stable time step of a one-segment line: refused without a free node, finite with one",
          "[tether][bad_input]") {
  const kt::Integrator all[] = {kt::Integrator::symplectic_euler, kt::Integrator::rk2,
                                kt::Integrator::rk4, kt::Integrator::implicit_euler,
                                kt::Integrator::bdf2};
  kt::TetherParametersd p = kelp_test::benchmark_line<double>(1);
  p.internal_damping = 10.0;  // RK2 needs internal damping (checked separately above)
  const kt::TetherModeld fixed(p);
  REQUIRE(fixed.first_free_node() > fixed.last_free_node());
  for (const kt::Integrator integ : all) {
    INFO(kt::integrator_name(integ));
    REQUIRE_THROWS_AS(kt::estimate_stable_dt(fixed, integ), kelp::invalid_argument);
    REQUIRE_THROWS_WITH(kt::estimate_stable_dt(fixed, integ), Catch::Contains("no free node"));
  }
  // One or both ends free: the free nodes (μ l/2 each) on the segment's spring k = EA/l oscillate
  // at ω = √(k/m) (one free end) or √(2k/m) (both: the two nodes against each other). The RK4
  // step is finite, inside RK4's limit h ω ≤ 2√2 for that mode, and steps the line for 10 s
  // without blowing up.
  const double m = p.mass_per_length * p.length / 2, k = p.axial_stiffness / p.length;
  for (const int free_ends : {1, 2}) {
    INFO("free ends " << free_ends);
    kt::TetherParametersd q = p;
    q.end_mode = kt::EndMode::free;
    if (free_ends == 2) q.start_mode = kt::EndMode::free;
    const kt::TetherModeld model(q);
    const double omega = std::sqrt(free_ends * k / m);
    const double dt = kt::estimate_stable_dt(model, kt::Integrator::rk4);
    REQUIRE(std::isfinite(dt));
    REQUIRE(dt > 0.0);
    CHECK(dt * omega <= 2.0 * std::sqrt(2.0));
    for (const kt::Integrator integ : all)
      CHECK(kt::estimate_stable_dt(model, integ) > 0.0);  // an answer for every scheme
    kt::TetherWorkspaced ws(model);
    kelp_test::TestWater<double> water;
    const Vector3<double> a(0, 0, 0), b(p.length, 0, 0);
    kt::TetherStated s = kt::straight_line_state(model, a, b);
    s.velocity.col(1) = Vector3<double>(0.5, 0.0, 0.2);  // a stretch and a swing
    const kt::TetherBoundaryd bnd = kt::TetherBoundaryd::fixed(a, b);
    REQUIRE_NOTHROW(kt::advance(model, ws, water, s, bnd, 10.0, {dt, kt::Integrator::rk4}));
    CHECK(kelp::all_finite(s.position));
    CHECK(s.velocity.norm() < 10.0);
  }
}

TEST_CASE("Catenary solvers answer bad input with invalid_input and valid input with finite values",
          "[tether][catenary][bad_input]") {
  const double values[] = {0, -1, 1e-300, 1e300, nan_, inf_, -inf_,
                           1, 10, 5e-324, 1e-10, 1e15, 1e-7, 2e9};
  int checked = 0;
  for (const double D : values)
    for (const double dz : values)
      for (const double L : values) {
        const kt::CatenaryResultd r = kt::solve_catenary(D, dz, L);
        INFO("D = " << D << ", dz = " << dz << ", L = " << L);
        const bool in_range = D >= 0 && D <= 1e9 && std::abs(dz) <= 1e9 && L >= 1e-6 && L <= 1e9;
        REQUIRE((r.status == kt::CatenaryStatus::invalid_input) == !in_range);
        if (r.status == kt::CatenaryStatus::taut)
          REQUIRE(std::isfinite(r.taut_tension));
        else if (r.status != kt::CatenaryStatus::invalid_input)
          REQUIRE((std::isfinite(r.a) && std::isfinite(r.c)));
        ++checked;
      }
  for (const double x : values)
    for (const double L : values)
      for (const double w : values)
        for (const double ea : {0.0, 1e5, nan_, -1.0, 1e300}) {
          kt::CatenaryOptionsd o;
          o.EA = ea;
          const kt::CatenaryShaped s =
              kt::catenary_between(Vector3<double>(0, 0, 0), Vector3<double>(x, 0, 5), L, w, o);
          INFO("x = " << x << ", L = " << L << ", w = " << w << ", EA = " << ea);
          if (!(ea >= 0 && ea <= 1e15 && std::abs(w) <= 1e9))
            REQUIRE(s.status() == kt::CatenaryStatus::invalid_input);
          if (s.status() == kt::CatenaryStatus::invalid_input) continue;
          REQUIRE(kelp::all_finite(s.force_on_start()));
          REQUIRE(kelp::all_finite(s.force_on_end()));
          REQUIRE(kelp::all_finite(s.point_at(L / 2)));
          ++checked;
        }
  CHECK(checked > 1000);
  // Unusable options.
  const std::vector<std::function<void(kt::CatenaryOptionsd&)>> bad = {
      [](kt::CatenaryOptionsd& o) { o.tolerance = -1e-14; },
      [](kt::CatenaryOptionsd& o) { o.tolerance = nan_; },
      [](kt::CatenaryOptionsd& o) { o.max_iterations = 0; },
      [](kt::CatenaryOptionsd& o) { o.vertical_tolerance = -1e-12; },
      [](kt::CatenaryOptionsd& o) { o.vertical_tolerance = inf_; },
      [](kt::CatenaryOptionsd& o) { o.seabed_depth = nan_; },
      [](kt::CatenaryOptionsd& o) { o.residual_tolerance = nan_; },
      [](kt::CatenaryOptionsd& o) { o.target_residual = -1; },
  };
  for (std::size_t k = 0; k < bad.size(); ++k) {
    kt::CatenaryOptionsd o;
    bad[k](o);
    INFO("option case " << k);
    CHECK(kt::solve_catenary(8.0, 3.0, 10.0, o).status == kt::CatenaryStatus::invalid_input);
  }
  CHECK(kt::solve_catenary(8.0, 3.0, 10.0).status == kt::CatenaryStatus::converged);
  // Found by fuzz_catenary: D/L so small that the solve over- or underflows is vertical, even
  // with vertical_tolerance = 0 (before: max_iterations with a = c = NaN in double, a = 0 and a
  // NaN residual in float).
  kt::CatenaryOptionsd zero;
  zero.vertical_tolerance = 0;
  const kt::CatenaryResultd d = kt::solve_catenary(1e-310, 0.0, 3.0, zero);
  CHECK(d.status == kt::CatenaryStatus::vertical);
  CHECK((std::isfinite(d.a) && std::isfinite(d.c)));
  kt::CatenaryOptionsf zero_f;
  zero_f.vertical_tolerance = 0;
  const kt::CatenaryResultf f = kt::solve_catenary(1e-43f, 0.0f, 40.0f, zero_f);
  CHECK(f.status == kt::CatenaryStatus::vertical);
  // Just above the floor the solve still converges with a > 0.
  const kt::CatenaryResultd above = kt::solve_catenary(1e-150, 0.0, 3.0, zero);
  CHECK(above.status == kt::CatenaryStatus::converged);
  CHECK(above.a > 0);
  CHECK(std::isfinite(above.residual));
  const kt::CatenaryResultf above_f = kt::solve_catenary(1e-17f, 0.0f, 40.0f, zero_f);
  CHECK(above_f.status == kt::CatenaryStatus::converged);
  CHECK(above_f.a > 0);
}

TEST_CASE("Tether presets refuse lengths they cannot cut into segments", "[tether][bad_input]") {
  for (const double length : {0.0, -1.0, nan_, inf_, 1e300, 2e5})
    REQUIRE_THROWS_AS(kt::presets::rov_tether(length), kelp::invalid_argument);
  for (const double length : {0.0, -1.0, nan_, inf_, 1e300, 2e5})
    REQUIRE_THROWS_AS(kt::presets::bead_chain(length), kelp::invalid_argument);
  for (const double seg : {0.0, -0.5, nan_, inf_, 1e-300})
    REQUIRE_THROWS_AS(kt::presets::rov_tether(10.0, seg), kelp::invalid_argument);
  // 100 m at 1 mm is 100000 segments: the most a model takes.
  CHECK(kt::presets::rov_tether(100.0, 1e-3).segments == 100000);
  CHECK_THROWS_AS(kt::presets::rov_tether(100.0, 0.9e-3), kelp::invalid_argument);
  CHECK(kt::presets::bead_chain(30.0).segments == 60);
}

TEST_CASE("The ROV tether preset refuses segments shorter than a tether model takes",
          "[tether][bad_input]") {
  // 0.1 mm cut into 10 nm segments (10000 of them: a count the model takes), and 0.1 µm in one
  // segment: each shorter than limits::min_segment_length (1 µm), which TetherModel refuses.
  for (const auto& [length, segment] : {std::pair{1e-4, 1e-8}, std::pair{1e-7, 0.25}}) {
    INFO(length << " m in segments of at most " << segment << " m");
    REQUIRE_THROWS_AS(kt::presets::rov_tether(length, segment), kelp::invalid_argument);
    REQUIRE_THROWS_WITH(kt::presets::rov_tether(length, segment),
                        Catch::Contains("segment length"));
  }
  REQUIRE_THROWS_AS(kt::presets::rov_tether(1e-4f, 1e-8f), kelp::invalid_argument);
  // What the preset gives, the model takes: 5 cm in 2 µm segments.
  const kt::TetherParametersd fine = kt::presets::rov_tether(0.05, 2e-6);
  CHECK(fine.segments == 25000);
  CHECK_NOTHROW(kt::validate(fine));
}

TEST_CASE("A tether state's winch length and payout rate must be finite", "[tether][bad_input]") {
  Line line;
  kt::check_state(line.model, line.state);
  for (const double bad : {nan_, inf_, -inf_}) {
    INFO("value " << bad);
    kt::TetherStated s = line.state;
    s.winch_length = bad;
    REQUIRE_THROWS_WITH(kt::check_state(line.model, s), Catch::Contains("state.winch_length"));
    REQUIRE_THROWS_AS(kt::tether_energy(line.model, line.water, s), kelp::invalid_argument);
    require_refused("static solve, winch_length", s, [&] {
      (void)kt::solve_static_equilibrium(line.model, line.ws, line.water, s, line.boundary);
    });
    s = line.state;
    s.payout_rate = bad;
    REQUIRE_THROWS_WITH(kt::check_state(line.model, s), Catch::Contains("state.payout_rate"));
    REQUIRE_THROWS_AS(kt::tether_energy(line.model, line.water, s), kelp::invalid_argument);
    require_refused("static solve, payout_rate", s, [&] {
      (void)kt::solve_static_equilibrium(line.model, line.ws, line.water, s, line.boundary);
    });
  }
}

TEST_CASE("Workspace resize refuses node counts no tether has, naming the count",
          "[tether][bad_input]") {
  // resize(0) and resize(-5) used to reach Eigen with a negative segment count and throw
  // std::bad_alloc. A tether has segments + 1 nodes, segments in [1, limits::max_segments].
  const auto refused_naming = [](auto&& buffers, int nodes) {
    try {
      buffers.resize(nodes);
    } catch (const kelp::invalid_argument& e) {
      const std::string what = e.what();
      CHECK(what.find("nodes") != std::string::npos);
      CHECK(what.find("got " + std::to_string(nodes)) != std::string::npos);
      return true;
    } catch (...) {
      return false;
    }
    return false;
  };
  const kt::TetherModeld model(kt::TetherParametersd{});
  for (const int nodes :
       {0, -5, 1, kt::limits::max_segments + 2, std::numeric_limits<int>::min()}) {
    INFO("nodes = " << nodes);
    kt::TetherWorkspaced ws(model);
    CHECK(refused_naming(ws, nodes));
    CHECK(ws.fits(model.nodes()));  // left as it was
    kt::TetherWorkspacef wf;
    CHECK(refused_naming(wf, nodes));
    kt::StateBackup<double> backup;
    CHECK(refused_naming(backup, nodes));
  }
  // The smallest tether (one segment) still fits.
  kt::TetherWorkspaced two;
  two.resize(2);
  CHECK(two.fits(2));
}

TEST_CASE("A tether state's accelerations are refused, by name, where the steps use them",
          "[tether][bad_input]") {
  Line line;
  REQUIRE(line.state.has_acceleration);
  kt::TetherStated s = line.state;
  s.acceleration(1, 3) = nan_;
  REQUIRE_THROWS_WITH(kt::check_state(line.model, s), Catch::Contains("state.acceleration"));
  for (const kt::Integrator integrator : {kt::Integrator::bdf2, kt::Integrator::rk4}) {
    kt::TetherStated t = s;
    INFO("integrator " << int(integrator));
    REQUIRE_THROWS_WITH(
        kt::step(line.model, line.ws, line.water, t, line.boundary, 0.01, {integrator}),
        Catch::Contains("state.acceleration"));
    REQUIRE(same_state(s, t));
  }
  // Not kept: not read, and the step leaves its own.
  s.has_acceleration = false;
  kt::check_state(line.model, s);
  (void)kt::step(line.model, line.ws, line.water, s, line.boundary, 0.01, {kt::Integrator::bdf2});
  CHECK(s.has_acceleration);
  CHECK(s.acceleration.allFinite());
  // An explicit step drops them; clear_history() too.
  (void)kt::step(line.model, line.ws, line.water, s, line.boundary, 0.001, {kt::Integrator::rk4});
  CHECK_FALSE(s.has_acceleration);
  s = line.state;
  s.clear_history();
  CHECK_FALSE(s.has_acceleration);
}
