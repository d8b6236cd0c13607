// Dynamics of the lumped-mass tether: pendulum period, energy conservation and dissipation,
// implicit (10 ms) against RK4 (0.1 ms) under a forced end, a buoyant line floating up.
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "kelp/environment/environment.hpp"
#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/integrators.hpp"
#include "kelp/tether/lumped_mass.hpp"
#include "tether_test_support.hpp"

namespace kt = kelp::tether;
using kelp::Vector3;

namespace {

// A stiff, nearly weightless 1 m line (1 g in total) carrying a 1 kg mass at its free end,
// hanging from a fixed point in vacuum: a simple pendulum of length l = 1 m (stretch
// m g / EA ≈ 1e-3 m).
kt::TetherParametersd pendulum_line() {
  kt::TetherParametersd p;
  p.segments = 10;
  p.length = 1.0;
  p.mass_per_length = 1e-3;
  p.axial_stiffness = 1e4;
  p.end_mode = kt::EndMode::free;
  p.end_point_mass = 1.0;
  return p;
}

struct PendulumRun {
  double period = 0;
  double max_length_error = 0;
  int crossings = 0;
};

PendulumRun run_pendulum(kt::Integrator integ, double dt, double duration) {
  const kelp_test::Vacuum<double> env;
  const kt::TetherModeld model(pendulum_line());
  kt::TetherWorkspaced ws(model);
  const double theta0 = 5.0 * kelp::pi / 180.0;
  const Vector3<double> top(0, 0, 0);
  const Vector3<double> bottom(std::sin(theta0), 0, std::cos(theta0));
  auto state = kt::straight_line_state(model, top, bottom * 1.001);  // pre-stretched by m g/EA
  const auto b = kt::TetherBoundaryd::fixed(top, top);
  PendulumRun run;
  double prev_x = state.position(0, 10), first = -1, last = -1;
  const int steps = static_cast<int>(std::lround(duration / dt));
  for (int k = 0; k < steps; ++k) {
    kt::step(model, ws, env, state, b, dt, {integ});
    const double x = state.position(0, 10);
    if (prev_x > 0 && x <= 0) {  // downward zero crossing, interpolated
      const double tc = state.time - dt * x / (x - prev_x);
      if (first < 0) first = tc;
      last = tc;
      ++run.crossings;
    }
    prev_x = x;
    const double len = (state.position.col(10) - state.position.col(0)).norm();
    run.max_length_error = std::max(run.max_length_error, std::abs(len - 1.0));
  }
  run.period = (last - first) / (run.crossings - 1);
  return run;
}

}  // namespace

TEST_CASE("pendulum: period 2 pi sqrt(l/g) within 2.5 %, length within 1 %",
          "[tether][dynamics][pendulum]") {
  // Small-amplitude period of a simple pendulum, l = 1 m, g = 9.80665: T = 2π sqrt(l/g).
  const double expected = 2 * kelp::pi * std::sqrt(1.0 / kelp::standard_gravity);
  const kt::TetherModeld model(pendulum_line());
  struct Case {
    kt::Integrator integ;
    double dt;
  };
  for (const Case c :
       {Case{kt::Integrator::symplectic_euler,
             kt::estimate_stable_dt(model, kt::Integrator::symplectic_euler, 0.0)},
        Case{kt::Integrator::rk4, kt::estimate_stable_dt(model, kt::Integrator::rk4, 0.0)},
        Case{kt::Integrator::implicit_euler, 1e-3}, Case{kt::Integrator::bdf2, 1e-2}}) {
    const PendulumRun run = run_pendulum(c.integ, c.dt, 4.5);
    INFO(kt::integrator_name(c.integ) << " dt " << c.dt << ": period " << run.period << " expected "
                                      << expected << ", length error " << run.max_length_error);
    REQUIRE(run.crossings >= 2);
    CHECK(run.period == Approx(expected).epsilon(0.025));
    CHECK(run.max_length_error < 0.01);
  }
}

namespace {

// A 20 m line between fixed ends 10 m apart horizontally and 5 m vertically, released from its
// catenary rotated 60 degrees about the chord: it swings like a skipping rope.
kt::TetherStated swinging_state(const kt::TetherModeld& model, const Vector3<double>& a,
                                const Vector3<double>& b) {
  kelp::environment::Environmentd water;  // catenary shape of the line in water
  auto s = kt::catenary_initial_state(model, water, a, b);
  const Vector3<double> axis = (b - a).normalized();
  const Eigen::AngleAxisd rot(kelp::pi / 3, axis);
  for (int i = 0; i < model.nodes(); ++i) s.position.col(i) = a + rot * (s.position.col(i) - a);
  return s;
}

double kinetic_energy(const kt::TetherModeld& model, const kt::TetherStated& s) {
  double e = 0;
  for (int i = 0; i < model.nodes(); ++i)
    e += 0.5 * model.node_mass(i) * s.velocity.col(i).squaredNorm();
  return e;
}

}  // namespace

TEST_CASE("energy: conserved within 1 % without drag and damping, never increasing with them",
          "[tether][dynamics][energy]") {
  const Vector3<double> a(0, 0, 0), b(10, 0, 5);
  SECTION("conservative: symplectic Euler and RK4 at a stable dt over 10 s") {
    const kelp_test::Vacuum<double> env;  // no drag, buoyancy or added mass
    auto p = kelp_test::benchmark_line<double>(10);
    const kt::TetherModeld model(p);
    for (auto integ : {kt::Integrator::symplectic_euler, kt::Integrator::rk4}) {
      kt::TetherWorkspaced ws(model);
      auto s = swinging_state(model, a, b);
      const auto bnd = kt::TetherBoundaryd::fixed(a, b);
      // Symplectic Euler conserves a shadow energy that differs from the true one by O((hω)²)
      // in the stiff axial modes: near its stability limit (hω → 2) the true energy swings by
      // tens of percent, so it runs at a quarter of the limit (RK4 at the default 0.8).
      const double safety = integ == kt::Integrator::symplectic_euler ? 0.25 : 0.8;
      const double dt = kt::estimate_stable_dt(model, integ, 0.0, safety);
      const double e0 = kt::tether_energy(model, env, s);
      double max_drift = 0, max_ke = 0;
      while (s.time < 10.0) {
        kt::step(model, ws, env, s, bnd, dt, {integ});
        max_drift = std::max(max_drift, std::abs(kt::tether_energy(model, env, s) - e0));
        max_ke = std::max(max_ke, kinetic_energy(model, s));
      }
      // Drift relative to the energy that moves: the peak kinetic energy of the swing.
      INFO(kt::integrator_name(integ)
           << " dt " << dt << ": drift " << max_drift << " J, peak KE " << max_ke << " J");
      CHECK(max_ke > 1.0);
      CHECK(max_drift <= 0.01 * max_ke);
    }
  }
  SECTION("dissipative: drag and internal damping, RK4 and implicit Euler") {
    kelp_test::TestWater<double> env;
    auto p = kelp_test::benchmark_line<double>(10);
    p.internal_damping = 50.0;  // default drag and added-mass coefficients
    const kt::TetherModeld model(p);
    for (auto integ : {kt::Integrator::rk4, kt::Integrator::implicit_euler}) {
      kt::TetherWorkspaced ws(model);
      auto s = swinging_state(model, a, b);
      const auto bnd = kt::TetherBoundaryd::fixed(a, b);
      const double dt = integ == kt::Integrator::rk4 ? 2e-4 : 1e-2;
      kt::ImplicitOptions<double> tight;  // energy is only monotone for a converged solve
      tight.acceleration_tolerance = 1e-8;
      tight.max_iterations = 20;
      double e_prev = kt::tether_energy(model, env, s);
      const double e0 = e_prev;
      int increases = 0;
      while (s.time < 5.0) {
        kt::step(model, ws, env, s, bnd, dt, {integ, tight});
        const double e = kt::tether_energy(model, env, s);
        if (e > e_prev + 1e-9 * std::abs(e0)) ++increases;
        e_prev = e;
      }
      INFO(kt::integrator_name(integ) << ": E0 " << e0 << " E(5 s) " << e_prev);
      CHECK(increases == 0);
      CHECK(e_prev < e0);
    }
  }
}

TEST_CASE("implicit at dt = 10 ms matches RK4 at 0.1 ms under a forced heave of the far end",
          "[tether][dynamics][implicit]") {
  // Benchmark line (20 segments), ASV end fixed at the surface, AUV end heaving 0.5 m at 0.2 Hz
  // around (10, 0, 5). Compare the end tension |F_end| over 10 s (two periods).
  kelp::environment::Environmentd env;
  auto p = kelp_test::benchmark_line<double>(20);
  p.internal_damping = 100.0;  // von Benzon et al. 2022's ROV tether value
  const kt::TetherModeld model(p);
  const Vector3<double> a(0, 0, 0), b(10, 0, 5);
  const double amp = 0.5, w = 2 * kelp::pi * 0.2;
  // z = z0 + A (1 − cos ωt): 0.5 m heave amplitude at 0.2 Hz starting from rest (a jump in the
  // end velocity at t = 0 would start an axial shock that both schemes resolve differently).
  const auto boundary_at = [&](double t) {
    kt::TetherBoundaryd bnd = kt::TetherBoundaryd::fixed(a, b);
    bnd.end.position.z() += amp * (1 - std::cos(w * t));
    bnd.end.velocity.z() = amp * w * std::sin(w * t);
    bnd.end.acceleration.z() = amp * w * w * std::cos(w * t);
    return bnd;
  };
  kt::TetherWorkspaced ws(model);
  kt::TetherStated s0;
  REQUIRE(kt::static_initial_state(model, ws, env, a, b, s0).converged);

  const double dt_imp = 0.01, duration = 10.0;
  const int n_imp = static_cast<int>(duration / dt_imp), sub = 100;
  std::vector<double> t_ref(n_imp), t_imp(n_imp), t_bdf(n_imp);
  {
    auto s = s0;
    kt::TetherWorkspaced w_ref(model);
    for (int k = 0; k < n_imp; ++k) {
      for (int j = 0; j < sub; ++j)
        kt::step_rk4(model, w_ref, env, s, boundary_at(s.time), dt_imp / sub);
      // End force at the end of the step, as the implicit schemes report it.
      kt::compute_forces(model, w_ref, env, s.time, s.position, s.velocity);
      t_ref[k] = kt::end_forces_from_workspace(model, w_ref, boundary_at(s.time)).on_end.norm();
    }
  }
  int retried = 0, max_newton = 0;
  for (auto integ : {kt::Integrator::implicit_euler, kt::Integrator::bdf2}) {
    auto s = s0;
    kt::TetherWorkspaced w_imp(model);
    auto& out = integ == kt::Integrator::bdf2 ? t_bdf : t_imp;
    for (int k = 0; k < n_imp; ++k) {
      const auto r = kt::step(model, w_imp, env, s, boundary_at(s.time), dt_imp, {integ});
      retried += r.retries;
      max_newton = std::max(max_newton, r.newton_iterations);
      out[k] = w_imp.end_forces.on_end.norm();
    }
  }
  double se = 0, se_bdf = 0, sr = 0;
  for (int k = 0; k < n_imp; ++k) {
    se += (t_imp[k] - t_ref[k]) * (t_imp[k] - t_ref[k]);
    se_bdf += (t_bdf[k] - t_ref[k]) * (t_bdf[k] - t_ref[k]);
    sr += t_ref[k] * t_ref[k];
  }
  const double rel = std::sqrt(se / sr), rel_bdf = std::sqrt(se_bdf / sr);
  INFO("relative RMS tension error: implicit Euler "
       << rel << ", BDF2 " << rel_bdf << "; Newton max " << max_newton << ", retried steps "
       << retried);
  CHECK(rel <= 0.05);
  CHECK(rel_bdf <= 0.05);
  CHECK(retried == 0);
  // The forcing matters: the tension varies by more than 10 % over the run.
  const auto [mn, mx] = std::minmax_element(t_ref.begin(), t_ref.end());
  CHECK(*mx - *mn > 0.1 * *mx);
}

TEST_CASE("a buoyant tether with a free end floats up to the surface",
          "[tether][dynamics][buoyant]") {
  kelp::environment::Environmentd env;
  auto p = kelp_test::benchmark_line<double>(20);
  p.mass_per_length = 0.03;  // ρA = 0.0515 kg/m: buoyant
  p.end_mode = kt::EndMode::free;
  const kt::TetherModeld model(p);
  kt::TetherWorkspaced ws(model);
  // Anchored at 6 m depth, laid out horizontally, released. The net buoyancy is
  // (ρA − μ) g = 0.21 N/m against normal drag ½ρ d Cdn v² = 4.9 v² N/m: it rises at ~0.2 m/s.
  const Vector3<double> a(0, 0, 6);
  auto s = kt::straight_line_state(model, a, Vector3<double>(20, 0, 6));
  const auto bnd = kt::TetherBoundaryd::fixed(a, a);
  for (int k = 0; k < 6000; ++k) kt::step(model, ws, env, s, bnd, 0.01, {kt::Integrator::bdf2});
  // The line rises monotonically from the anchor and its free part floats at the surface
  // (nodes above it lose their buoyancy, so they bob at z ≈ 0).
  for (int i = 1; i <= 20; ++i) CHECK(s.position(2, i) < s.position(2, i - 1) + 0.05);
  CHECK(std::abs(s.position(2, 20)) < 0.2);
  CHECK(std::abs(s.position(2, 15)) < 0.2);
  CHECK(ws.end_forces.on_start.z() < 0);  // pulls the anchor up
}

TEST_CASE("a slack line falls onto the seabed without compression and comes to rest on it",
          "[tether][dynamics][seabed]") {
  kelp_test::TestWater<double> env;
  env.bed = 12.0;
  auto p = kelp_test::benchmark_line<double>(20);
  p.seabed_friction = 0.3;
  const kt::TetherModeld model(p);
  kt::TetherWorkspaced ws(model);
  // Ends on the bed 8 m apart; the 20 m line starts 2 m above it in a wide S (slack everywhere).
  const Vector3<double> a(0, 0, 12), b(8, 0, 12);
  kt::TetherStated s(model);
  for (int i = 0; i <= 20; ++i)
    s.position.col(i) = Vector3<double>(0.4 * i, 2.5 * std::sin(kelp::pi * i / 10.0),
                                        i == 0 || i == 20 ? 12.0 : 10.0);
  const auto bnd = kt::TetherBoundaryd::fixed(a, b);
  double min_tension = 0;
  for (int k = 0; k < 2000; ++k) {
    kt::step(model, ws, env, s, bnd, 0.01, {kt::Integrator::bdf2});
    // BA = 0: the axial force is purely elastic and must never be compressive.
    min_tension = std::min(min_tension, ws.tension.minCoeff());
  }
  CHECK(min_tension >= 0.0);
  // At rest on the bed: each interior node's contact force carries its submerged weight
  // (kb d l (z − h) = w l) and the line barely moves.
  const double w = model.submerged_weight_per_length(env.rho, env.g);
  for (int i = 2; i <= 18; ++i) {
    INFO("node " << i);
    CHECK(ws.seabed_force(i) == Approx(w * model.node_length(i)).epsilon(0.02));
    CHECK(s.position(2, i) > 12.0);
  }
  CHECK(s.velocity.cwiseAbs().maxCoeff() < 1e-3);
}

TEST_CASE("the sub-stepping driver equals the same steps taken by hand", "[tether][advance]") {
  kelp::environment::Environmentd env;
  const kt::TetherModeld model(kelp_test::benchmark_line<double>(10));
  kt::TetherWorkspaced w1(model), w2(model);
  kt::TetherStated s0;
  REQUIRE(kt::static_initial_state(model, w1, env, Vector3<double>(0, 0, 0),
                                   Vector3<double>(10, 0, 5), s0)
              .converged);
  auto b = kt::TetherBoundaryd::fixed(Vector3<double>(0, 0, 0), Vector3<double>(10, 0, 5));
  b.end.velocity = Vector3<double>(0.2, 0, -0.1);
  // 5 ms with max_dt 1.2 ms → 5 RK4 sub-steps of 1 ms (stable: 1.9 ms); the end moves with its
  // velocity.
  auto s1 = s0, s2 = s0;
  CHECK(kt::advance(model, w1, env, s1, b, 0.005, {0.0012, kt::Integrator::rk4}).substeps == 5);
  for (int k = 0; k < 5; ++k) {
    auto bk = b;
    bk.end.position = b.end.position_at(0.001 * k);
    kt::step_rk4(model, w2, env, s2, bk, 0.001);
  }
  CHECK((s1.position - s2.position).cwiseAbs().maxCoeff() < 1e-12);
  CHECK(s1.time == Approx(0.005));
  CHECK((s1.position.col(10) - (b.end.position + 0.005 * b.end.velocity)).norm() < 1e-12);
  // (advance() moves an explicit scheme's sub-step boundaries on one sub-step at a time, p + h v
  // each time, which rounds differently from p + k h v: EA/l = 1e5 N/m turns the last bit of a
  // position into 1e-11 N.)
  CHECK((w1.end_forces.on_end - w2.end_forces.on_end).norm() <=
        1e-10 * w2.end_forces.on_end.norm());
  CHECK_THROWS_AS(kt::advance(model, w1, env, s1, b, 0.0, {0.01, kt::Integrator::rk4}),
                  kelp::invalid_argument);
}

TEST_CASE("a state reset between implicit steps ignores the workspace's history",
          "[tether][dynamics][regression]") {
  // BDF2 history and the velocity predictor belong to the state that was stepped: after the
  // state is reset (or a workspace is reused for another state) the step must equal one taken
  // with a fresh workspace.
  kelp::environment::Environmentd env;
  const kt::TetherModeld model(kelp_test::benchmark_line<double>(10));
  const Vector3<double> a(0, 0, 0), b(10, 0, 5);
  const auto s0 = swinging_state(model, a, b);
  const auto bnd = kt::TetherBoundaryd::fixed(a, b);
  const double dt = 0.01;
  for (auto integ : {kt::Integrator::implicit_euler, kt::Integrator::bdf2}) {
    INFO(kt::integrator_name(integ));
    kt::TetherWorkspaced used(model), fresh(model);
    auto s = s0;
    for (int k = 0; k < 3; ++k) kt::step(model, used, env, s, bnd, dt, {integ});
    s = s0;  // reset
    const auto r1 = kt::step(model, used, env, s, bnd, dt, {integ});
    auto f = s0;
    const auto r2 = kt::step(model, fresh, env, f, bnd, dt, {integ});
    CHECK(r1.force_evaluations == r2.force_evaluations);
    CHECK((s.position - f.position).cwiseAbs().maxCoeff() == 0.0);
    CHECK((s.velocity - f.velocity).cwiseAbs().maxCoeff() == 0.0);
    // The next step continues with the history of the reset run, as the fresh one does.
    kt::step(model, used, env, s, bnd, dt, {integ});
    kt::step(model, fresh, env, f, bnd, dt, {integ});
    CHECK((s.position - f.position).cwiseAbs().maxCoeff() == 0.0);
  }
}
