// Integrator contracts of the lumped-mass tether: a passive line with the default added mass, a
// cable that never pushes, accuracy that does not fall as dt shrinks, steps that are never
// committed unconverged, round-off that is not taken for a physical failure, the integrator
// history in the state, and a clock that does not drift.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "kelp/environment/environment.hpp"
#include "kelp/environment/sea_state.hpp"
#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/integrators.hpp"
#include "kelp/tether/lumped_mass.hpp"
#include "kelp/tether/presets.hpp"
#include "tether_test_support.hpp"

namespace kt = kelp::tether;
using kelp::Vector3;

namespace {

// The benchmark line (N segments) hanging between (0, 0, 0) and (10, 0, 5) in still seawater,
// rotated 60° about its chord so that it swings.
kt::TetherStated swinging(const kt::TetherModeld& model) {
  const kelp::environment::Environmentd water;
  const Vector3<double> a(0, 0, 0), b(10, 0, 5);
  auto s = kt::catenary_initial_state(model, water, a, b);
  const Eigen::AngleAxisd rot(kelp::pi / 3, (b - a).normalized());
  for (int i = 0; i < model.nodes(); ++i) s.position.col(i) = a + rot * (s.position.col(i) - a);
  return s;
}

bool bitwise_equal(const kt::TetherStated& a, const kt::TetherStated& b) {
  return kelp_test::same_bits(a.position, b.position) &&
         kelp_test::same_bits(a.velocity, b.velocity) &&
         std::memcmp(&a.time, &b.time, sizeof(double)) == 0;
}

}  // namespace

TEST_CASE(
    "added mass keeps the line passive: energy drift with Can = 1 within 2x that with Can = 0",
    "[tether][energy][added_mass]") {
  // 10 segments in deep still water, no drag, no internal damping, swinging from 60°; RK4 at
  // 0.5× and 0.1× its stable step for 20 s. The node mass aI + b q qᵀ turns with the tangent:
  // without the terms of its rate of change the line gained 0.22–0.27 J here (peak kinetic
  // energy ≈ 4 J) with Can = 1, against ≤ 0.054 J with Can = 0.
  const kelp::environment::Environmentd env;
  const Vector3<double> a(0, 0, 0), b(10, 0, 5);
  const auto bnd = kt::TetherBoundaryd::fixed(a, b);
  for (double fraction : {0.5, 0.1}) {
    double drift[2] = {0, 0};
    for (int with_added_mass = 0; with_added_mass < 2; ++with_added_mass) {
      auto p = kelp_test::benchmark_line<double>(10);
      p.normal_drag = p.tangential_drag = 0.0;
      if (!with_added_mass) p.normal_added_mass = 0.0;  // else the default Can = 1
      const kt::TetherModeld model(p);
      kt::TetherWorkspaced ws(model);
      auto s = swinging(model);
      const double dt =
          kt::estimate_stable_dt(model, kt::Integrator::rk4, env.water_density(), fraction);
      const double e0 = kt::tether_energy(model, env, s);
      while (s.time < 20.0) {
        kt::step_rk4(model, ws, env, s, bnd, dt);
        drift[with_added_mass] =
            std::max(drift[with_added_mass], std::abs(kt::tether_energy(model, env, s) - e0));
      }
    }
    INFO("stable-dt fraction " << fraction << ": drift Can = 0 " << drift[0] << " J, Can = 1 "
                               << drift[1] << " J");
    CHECK(drift[1] <= 2.0 * drift[0]);
    CHECK(drift[1] < 0.06);
  }
}

TEST_CASE("a cable never pushes: the axial force stays >= 0 with internal damping",
          "[tether][clamp]") {
  // 20 m line, 50 segments, BA = 100 N s; the ASV end rides the waves of the moderate preset
  // 0.1 m below the surface, the AUV end is fixed at (10, 0, 5); BDF2 at 10 ms for 60 s. The
  // unclamped dashpot (compressive_damping, MoorDyn's model) pushes here.
  const auto env =
      kelp::environment::make_environment<double>(kelp::environment::presets::moderate());
  const Vector3<double> asv(0, 0, 0.1), auv(10, 0, 5);
  double min_force[2] = {0, 0};
  for (int compressive = 0; compressive < 2; ++compressive) {
    auto p = kelp_test::benchmark_line<double>(50);
    p.internal_damping = 100.0;
    p.compressive_damping = compressive == 1;
    const kt::TetherModeld model(p);
    kt::TetherWorkspaced ws(model);
    kt::TetherStated s = kt::catenary_initial_state(model, env, asv, auv);
    const double dt = 0.01;
    for (int k = 0; k < 6000; ++k) {
      auto bnd = kt::TetherBoundaryd::fixed(asv, auv);
      const double z0 = env.surface_elevation(0.0, 0.0, s.time);
      const double z1 = env.surface_elevation(0.0, 0.0, s.time + dt);
      bnd.start.position.z() = 0.1 - z0;
      bnd.start.velocity.z() = -(z1 - z0) / dt;
      kt::step(model, ws, env, s, bnd, dt, {kt::Integrator::bdf2});  // throws if not converged
      min_force[compressive] = std::min(min_force[compressive], ws.tension.minCoeff());
    }
  }
  INFO("minimum segment force: clamped " << min_force[0] << " N, compressive " << min_force[1]
                                         << " N");
  CHECK(min_force[0] >= 0.0);
  CHECK(min_force[1] < 0.0);  // the case does load the dashpot in compression
}

TEST_CASE("a smaller dt is never less accurate, at a cost linear in 1/dt",
          "[tether][implicit][accuracy]") {
  // Surge of the far end of the 50-segment benchmark line, x = A (1 − cos ωt)²/4 (smooth start:
  // no axial ringing in the reference), A = 0.5 m, 0.2 Hz, 10 s; end tensions against RK4 at
  // 0.1 ms. With a fixed velocity tolerance, BDF2 at 1 ms was 50× worse than at 10 ms.
  const kelp::environment::Environmentd env;
  const kt::TetherModeld model(kelp_test::benchmark_line<double>(50));
  const Vector3<double> a(0, 0, 0), b(10, 0, 5);
  kt::TetherStated s0;
  {
    kt::TetherWorkspaced ws(model);
    REQUIRE(kt::static_initial_state(model, ws, env, a, b, s0).converged);
  }
  const double amp = 0.5, w = 2 * kelp::pi * 0.2, duration = 10.0;
  const auto boundary_at = [&](double t) {
    kt::TetherBoundaryd bnd = kt::TetherBoundaryd::fixed(a, b);
    const double c = std::cos(w * t), sn = std::sin(w * t);
    bnd.end.position.x() += amp * (1 - c) * (1 - c) / 4;
    bnd.end.velocity.x() = amp * w * (1 - c) * sn / 2;
    bnd.end.acceleration.x() = amp * w * w * (sn * sn + (1 - c) * c) / 2;
    return bnd;
  };
  struct Run {
    std::vector<double> start, end;
    int evaluations = 0;
  };
  // Tensions every 10 ms, at the end of the step.
  const auto run = [&](double dt, kt::Integrator integ) {
    kt::TetherWorkspaced ws(model);
    auto s = s0;
    Run r;
    const int n = static_cast<int>(std::lround(duration / dt)), every = std::lround(0.01 / dt);
    for (int k = 1; k <= n; ++k) {
      r.evaluations +=
          kt::step(model, ws, env, s, boundary_at(s.time), dt, {integ}).force_evaluations;
      if (k % every) continue;
      r.start.push_back(ws.end_forces.on_start.norm());
      r.end.push_back(ws.end_forces.on_end.norm());
    }
    return r;
  };
  const auto rms = [](const std::vector<double>& x, const std::vector<double>& ref) {
    double se = 0, sr = 0;
    for (std::size_t i = 0; i < ref.size(); ++i) {
      se += (x[i] - ref[i]) * (x[i] - ref[i]);
      sr += ref[i] * ref[i];
    }
    return std::sqrt(se / sr);
  };
  const Run ref = run(1e-4, kt::Integrator::rk4);
  const Run coarse = run(0.01, kt::Integrator::bdf2), fine = run(0.001, kt::Integrator::bdf2);
  const double e_start[2] = {rms(coarse.start, ref.start), rms(fine.start, ref.start)};
  const double e_end[2] = {rms(coarse.end, ref.end), rms(fine.end, ref.end)};
  INFO("relative RMS tension error, 10 ms / 1 ms: fixed end "
       << e_start[0] << " / " << e_start[1] << ", moving end " << e_end[0] << " / " << e_end[1]);
  INFO("force evaluations per simulated second: " << coarse.evaluations / duration << " / "
                                                  << fine.evaluations / duration);
  CHECK(e_start[0] < 1e-4);
  CHECK(e_end[0] < 2e-4);
  CHECK(e_start[1] <= e_start[0]);
  CHECK(e_end[1] <= e_end[0]);
  // Ten times the steps for at most 1.5 × ten times the work.
  CHECK(fine.evaluations <= 15 * coarse.evaluations);
}

// End forces mean one thing whatever the scheme: the force on each attachment point at the end
// of the step (the state the step returns), with the end node's inertia taken off
// (ws.end_forces, F_node − M_node a_end) and without it (ws.end_node_forces, F_node): both
// recomputed here from a fresh force evaluation at the returned state. The start end accelerates
// (constant acceleration, so that the step's end motion and the boundary at its end agree), in a
// current, so that every term of the end node's force is there.
TEST_CASE("end forces: every integrator reports them at the end of the step",
          "[tether][end_forces]") {
  kelp_test::TestWater<double> env;
  env.current = Vector3<double>(0.3, 0.1, 0.0);
  const kt::TetherModeld model(kelp_test::benchmark_line<double>(20));
  const int n = model.segments();
  const Vector3<double> a(0, 0, 0.5), b(10, 0, 5);
  kt::TetherStated s0;
  {
    kt::TetherWorkspaced ws(model);
    REQUIRE(kt::static_initial_state(model, ws, env, a, b, s0).converged);
  }
  const Vector3<double> v0(0.2, -0.1, 0.1), acc(0.8, -0.4, 0.3);
  const auto boundary_at = [&](double t) {
    kt::TetherBoundaryd bnd = kt::TetherBoundaryd::fixed(a, b);
    bnd.start.position = a + t * v0 + 0.5 * t * t * acc;
    bnd.start.velocity = v0 + t * acc;
    bnd.start.acceleration = acc;
    return bnd;
  };
  const kt::Integrator schemes[] = {kt::Integrator::symplectic_euler, kt::Integrator::rk2,
                                    kt::Integrator::rk4, kt::Integrator::implicit_euler,
                                    kt::Integrator::bdf2};
  for (const kt::Integrator integ : schemes) {
    INFO(kt::integrator_name(integ));
    const bool implicit = kt::is_implicit(integ);
    const double dt = implicit ? 0.01 : 2e-4;
    kt::TetherWorkspaced ws(model);
    auto s = s0;
    for (int k = 0; k < 5; ++k) kt::step(model, ws, env, s, boundary_at(s.time), dt, {integ});
    // A fresh evaluation at the state the last step returned.
    kt::TetherWorkspaced fresh(model);
    kt::compute_forces(model, fresh, env, s.time, s.position, s.velocity);
    const kt::EndForces<double> expected =
        kt::end_forces_from_workspace(model, fresh, boundary_at(s.time));
    // Explicit: the same evaluation; implicit: the final Newton iterate's, within its tolerance.
    const double tol = implicit ? 1e-5 : 1e-12;
    const double scale = expected.on_start.norm() + expected.on_end.norm();
    CHECK((ws.end_forces.on_start - expected.on_start).norm() <= tol * scale);
    CHECK((ws.end_forces.on_end - expected.on_end).norm() <= tol * scale);
    // Without the inertia: the end nodes' net force.
    CHECK((ws.end_node_forces.on_start - fresh.force.col(0)).norm() <= tol * scale);
    CHECK((ws.end_node_forces.on_end - fresh.force.col(n)).norm() <= tol * scale);
    // The two differ by the accelerating start node's inertia M_0 a (the far end is fixed).
    const Vector3<double> q = fresh.tangent.col(0);
    const Vector3<double> inertia = fresh.mass_iso(0) * acc + fresh.mass_tan(0) * q.dot(acc) * q;
    CHECK((ws.end_node_forces.on_start - ws.end_forces.on_start - inertia).norm() <= tol * scale);
    CHECK(inertia.norm() > 1e-3 * scale);
    CHECK(ws.end_node_forces.on_end == ws.end_forces.on_end);
  }
  // An explicit step takes the previous one's end evaluation as its first stage when it starts
  // from exactly that state, in the same environment object: advance() and separate steps with
  // the boundary moved on the same way give the same bits and one evaluation per step fewer than
  // the scheme's stages plus one.
  for (const kt::Integrator integ :
       {kt::Integrator::symplectic_euler, kt::Integrator::rk2, kt::Integrator::rk4}) {
    INFO(kt::integrator_name(integ));
    kt::TetherWorkspaced ws_a(model), ws_s(model);
    auto sa = s0, ss = s0;
    const auto r = kt::advance(model, ws_a, env, sa, boundary_at(0.0), 10 * 2e-4, {2e-4, integ});
    int separate = 0;
    kt::TetherBoundaryd sub = boundary_at(0.0);
    for (int k = 0; k < 10; ++k) {
      if (k > 0) sub = sub.after(2e-4);
      separate += kt::step(model, ws_s, env, ss, sub, 2e-4, {integ}).force_evaluations;
    }
    CHECK(kelp_test::same_bits(sa.position, ss.position));
    CHECK(ws_a.end_forces.on_start == ws_s.end_forces.on_start);
    CHECK(ws_a.end_forces.on_end == ws_s.end_forces.on_end);
    const int stages = integ == kt::Integrator::rk4 ? 4 : (integ == kt::Integrator::rk2 ? 2 : 1);
    CHECK(r.force_evaluations == 10 * stages + 1);
    CHECK(separate == 10 * stages + 1);
    // Not when anything differs: another environment object (a copy of the same water), a state
    // changed between the steps, another time.
    const kelp_test::TestWater<double> other = env;
    const auto next = [&](const kelp_test::TestWater<double>& e) {
      sub = sub.after(2e-4);
      return kt::step(model, ws_s, e, ss, sub, 2e-4, {integ}).force_evaluations;
    };
    CHECK(next(other) == stages + 1);
    CHECK(next(other) == stages);
    ss.velocity(0, 5) += 1e-9;
    CHECK(next(other) == stages + 1);
    ss.time += 1e-3;
    CHECK(next(other) == stages + 1);
    // Nor after another evaluation in the same workspace: a compute_forces elsewhere, a failed
    // implicit step.
    CHECK(next(other) == stages);
    kt::compute_forces(model, ws_s, other, ss.time, s0.position, s0.velocity);
    CHECK(next(other) == stages + 1);
  }
  // kelp's Environment tells a copy or an assignment from the original (a new instance id).
  kelp::environment::Environmentd e1;
  const kelp::environment::Environmentd e2 = e1;
  CHECK(e2.instance_id() != e1.instance_id());
  const std::uint64_t before = e1.instance_id();
  e1 = e2;
  CHECK(e1.instance_id() != before);
}

TEST_CASE("waves sampled once per implicit step agree with waves sampled at every iterate",
          "[tether][implicit][waves]") {
  // The 50-segment benchmark line from a fixed point near the surface to a point 5 m down in
  // the paper's rough sea, 20 s of BDF2 at 10 ms: the default holds the water kinematics and
  // the surface elevation at the step's predicted positions through Newton's method; the
  // reference samples them at every iterate.
  const auto env = kelp::environment::make_environment<double>(kelp::environment::presets::rough());
  const kt::TetherModeld model(kelp_test::benchmark_line<double>(50));
  const Vector3<double> a(0, 0, 0.5), b(10, 0, 5);
  kt::TetherStated s0;
  kt::TetherWorkspaced ws(model);
  REQUIRE(
      kt::static_initial_state(model, ws, kelp::environment::Environmentd{}, a, b, s0).converged);
  const auto bnd = kt::TetherBoundaryd::fixed(a, b);
  kt::ImplicitOptionsd every;
  every.resample_water = true;
  // held and exact at 10 ms; fine: exact at 5 ms, the scale of the step's own error.
  auto held = s0, exact = s0, fine = s0;
  kt::StepReportd r_held, r_exact;
  double se = 0, sr = 0, se_dt = 0, dx = 0, dx_dt = 0;
  for (int k = 0; k < 2000; ++k) {
    r_held += kt::step(model, ws, env, held, bnd, 0.01, {kt::Integrator::bdf2});
    const double f_held = ws.end_forces.on_end.norm();
    r_exact += kt::step(model, ws, env, exact, bnd, 0.01, {kt::Integrator::bdf2, every});
    const double f_exact = ws.end_forces.on_end.norm();
    for (int j = 0; j < 2; ++j) kt::step(model, ws, env, fine, bnd, 0.005, {kt::Integrator::bdf2});
    const double f_fine = ws.end_forces.on_end.norm();
    se += (f_held - f_exact) * (f_held - f_exact);
    se_dt += (f_fine - f_exact) * (f_fine - f_exact);
    sr += f_exact * f_exact;
    dx = std::max(dx, (held.position - exact.position).colwise().norm().maxCoeff());
    dx_dt = std::max(dx_dt, (fine.position - exact.position).colwise().norm().maxCoeff());
  }
  const double rel = std::sqrt(se / sr), rel_dt = std::sqrt(se_dt / sr);
  INFO("held vs sampled at every iterate: relative RMS end-tension difference "
       << rel << ", node positions up to " << dx << " m apart; 10 ms vs 5 ms: " << rel_dt << " and "
       << dx_dt << " m; force evaluations " << r_held.force_evaluations << " vs "
       << r_exact.force_evaluations);
  // Holding the water costs less accuracy than the step's own truncation error. (0.58 of it
  // since the segments' wet lengths are exact: the buoyancy of a segment that pierces the surface
  // depends on the elevation at both its nodes, which the held water takes at the predicted
  // positions; 0.5 before.)
  CHECK(rel <= 0.7 * rel_dt);
  CHECK(dx <= 2 * dx_dt);
  CHECK(r_held.force_evaluations <= r_exact.force_evaluations + 100);
}

TEST_CASE("an implicit step that does not converge is retried in sub-steps, never committed",
          "[tether][implicit][retry]") {
  // A slack 50-segment line released at dt = 10 s: the full step's Newton iteration does not
  // converge; the step is split and every committed piece meets the tolerance.
  kelp_test::TestWater<double> env;
  const kt::TetherModeld model(kelp_test::benchmark_line<double>(50));
  const Vector3<double> a(0, 0, 0), b(5, 0, 2);
  const auto bnd = kt::TetherBoundaryd::fixed(a, b);
  const kt::TetherStated s0 = kt::catenary_initial_state(model, env, a, b);
  const double dt = 10.0;
  kt::ImplicitOptionsd options;
  SECTION("retried: several sub-steps, each converged") {
    kt::TetherWorkspaced ws(model);
    auto s = s0;
    const auto r = kt::step(model, ws, env, s, bnd, dt, {kt::Integrator::bdf2, options});
    INFO("sub-steps " << r.substeps << ", retries " << r.retries << ", residual " << r.residual
                      << ", rejected " << r.rejected_residual);
    CHECK(r.retries >= 1);
    CHECK(r.substeps > 1);
    CHECK(r.residual <= options.acceleration_tolerance * dt);
    CHECK(r.rejected_residual > options.acceleration_tolerance * dt);
    CHECK(s.time == dt);
    CHECK(kelp::all_finite(s.position));
  }
  SECTION("no retry allowed: throws, state unchanged bit for bit") {
    kt::TetherWorkspaced ws(model);
    auto s = s0;
    options.max_step_halvings = 0;
    CHECK_THROWS_AS(kt::step(model, ws, env, s, bnd, dt, {kt::Integrator::bdf2, options}),
                    kelp::numerical_error);
    CHECK(bitwise_equal(s, s0));
    CHECK_FALSE(s.has_history());
  }
  SECTION("the drivers pass the report on") {
    kt::TetherWorkspaced ws(model);
    auto s = s0;
    const auto r = kt::advance(model, ws, env, s, bnd, 2 * dt, {dt, kt::Integrator::bdf2});
    CHECK(r.substeps > 2);
    CHECK(r.retries >= 1);
    CHECK(r.residual <= options.acceleration_tolerance * dt);
    CHECK(s.time == Approx(2 * dt));
  }
}

TEST_CASE("round-off is not a physical failure", "[tether][implicit][roundoff]") {
  kelp_test::TestWater<double> env;
  SECTION("a slack 50-segment line steps with BDF2 at dt = 10 s") {
    // (γh)² EA/l is 1e9 times the node mass: the block factorisation used to find a block
    // 'not positive definite' here.
    const kt::TetherModeld model(kelp_test::benchmark_line<double>(50));
    const Vector3<double> a(0, 0, 0), b(5, 0, 2);
    kt::TetherWorkspaced ws(model);
    auto s = kt::catenary_initial_state(model, env, a, b);
    for (int k = 0; k < 5; ++k)
      kt::step(model, ws, env, s, kt::TetherBoundaryd::fixed(a, b), 10.0, {kt::Integrator::bdf2});
    CHECK(s.time == Approx(50.0));
    // Settled: at rest, on the static shape the static solve finds.
    CHECK(s.velocity.cwiseAbs().maxCoeff() < 1e-3);
  }
  SECTION("a 1 cm line cut into 200 segments is refused up front, naming the cause") {
    auto p = kelp_test::benchmark_line<double>(200);
    p.length = 0.01;
    const kt::TetherModeld model(p);
    const Vector3<double> a(0, 0, 5), b(0.008, 0, 5.003);
    kt::TetherWorkspaced ws(model);
    const auto s0 = kt::catenary_initial_state(model, env, a, b);
    auto s = s0;
    CHECK_THROWS_WITH(
        kt::step(model, ws, env, s, kt::TetherBoundaryd::fixed(a, b), 0.01, {kt::Integrator::bdf2}),
        Catch::Contains("cannot be resolved") && Catch::Contains("fewer, longer segments"));
    CHECK(bitwise_equal(s, s0));
    // The same line with 20 segments steps (and a looser tolerance is the user's other way out).
    auto p20 = p;
    p20.segments = 20;
    const kt::TetherModeld model20(p20);
    kt::TetherWorkspaced ws20(model20);
    auto s20 = kt::catenary_initial_state(model20, env, a, b);
    CHECK_NOTHROW(kt::step(model20, ws20, env, s20, kt::TetherBoundaryd::fixed(a, b), 1e-5,
                           {kt::Integrator::bdf2}));
  }
  SECTION("a stiff float line steps to float's resolution instead of failing at step 196") {
    // 1 m of the default line in 2 segments between (0, 0, 10) and (0.5, 0, 10.5): EA/l = 2e5 N/m
    // on coordinates rounded to ~1e-6 m in float resolves node forces to ~0.2 N, far above the
    // 0.1 m/s² Newton tolerance on a 0.06 kg node. Newton's method chased that noise and BDF2
    // at 10 ms threw numerical_error at step 196; the tolerance is now raised to the resolution
    // and the float run follows the double one.
    const auto run = [](auto scalar) {
      using S = decltype(scalar);
      kt::TetherParameters<S> p;
      p.segments = 2;
      p.length = S(1);
      const kt::TetherModel<S> model(p);
      kt::TetherWorkspace<S> ws(model);
      const kelp::environment::Environment<S> water;
      const Vector3<S> a(0, 0, 10), b(S(0.5), 0, S(10.5));
      auto s = kt::straight_line_state(model, a, b);
      const auto boundary = kt::TetherBoundary<S>::fixed(a, b);
      for (int k = 0; k < 3000; ++k)
        kt::step(model, ws, water, s, boundary, 0.01, {kt::Integrator::bdf2});
      return Vector3<double>(s.position.col(1).template cast<double>());
    };
    Vector3<double> node_f = Vector3<double>::Zero();
    REQUIRE_NOTHROW(node_f = run(0.0f));
    const Vector3<double> node_d = run(0.0);
    // At rest after 30 s, hanging below the start (the vertical segment taut): the float node
    // within a millimetre of the double one.
    CHECK((node_f - node_d).norm() < 1e-3);
    CHECK((node_d - Vector3<double>(0, 0, 10.5)).norm() < 1e-3);
  }
  SECTION("a float line its precision cannot resolve is refused up front, naming float") {
    // The same 1 m line cut into 200 segments: EA/l = 2e7 N/m rounds the axial force to ~30 N
    // in float, a million times the 2e-5 N tolerance of its lightest node. The check used
    // double's epsilon for every Scalar, so float lines were never refused.
    kt::TetherParametersf p;
    p.segments = 200;
    p.length = 1.0f;
    const kt::TetherModelf model(p);
    kt::TetherWorkspacef ws(model);
    const kelp::environment::Environmentf water;
    const Vector3<float> a(0, 0, 10), b(0.5f, 0, 10.5f);
    const auto s0 = kt::straight_line_state(model, a, b);
    auto s = s0;
    CHECK_THROWS_WITH(kt::step(model, ws, water, s, kt::TetherBoundaryf::fixed(a, b), 0.01,
                               {kt::Integrator::bdf2}),
                      Catch::Contains("cannot be resolved") &&
                          Catch::Contains("single precision") &&
                          Catch::Contains("or double precision"));
    CHECK(s.position == s0.position);
    CHECK(s.time == s0.time);
  }
  SECTION("a 10 km line with 200 segments reaches its static equilibrium") {
    auto p = kelp_test::benchmark_line<double>(200);
    p.length = 10000.0;
    const kt::TetherModeld model(p);
    kt::TetherWorkspaced ws(model);
    kt::TetherStated s;
    const auto r = kt::static_initial_state(model, ws, env, Vector3<double>(0, 0, 0),
                                            Vector3<double>(5000, 0, 2500), s);
    INFO("iterations " << r.iterations << ", residual " << r.residual << " N");
    CHECK(r.converged);
    // The vertical end loads carry the line's submerged weight: the start node is at the
    // surface, but its half segment runs down into the water and is wet but for the first half
    // diameter (the segments' wet lengths are exact).
    const double w = model.submerged_weight_per_length(env.rho, env.g);
    CHECK(ws.end_forces.on_start.z() + ws.end_forces.on_end.z() ==
          Approx(w * p.length).epsilon(1e-3));
  }
}

TEST_CASE("the integrator history lives in the state: save, step, restore, step is bitwise",
          "[tether][state][history]") {
  const kelp::environment::Environmentd env;
  const kt::TetherModeld model(kelp_test::benchmark_line<double>(20));
  const auto bnd = kt::TetherBoundaryd::fixed(Vector3<double>(0, 0, 0), Vector3<double>(10, 0, 5));
  for (auto integ : {kt::Integrator::bdf2, kt::Integrator::implicit_euler, kt::Integrator::rk4}) {
    INFO(kt::integrator_name(integ));
    const double dt = kt::is_implicit(integ) ? 0.01 : 1e-4;
    kt::TetherWorkspaced ws(model), other(model);
    auto s = swinging(model);
    for (int k = 0; k < 5; ++k) kt::step(model, ws, env, s, bnd, dt, {integ});
    const kt::TetherStated saved = s;
    REQUIRE(saved.has_history());
    std::vector<kt::TetherStated> first;
    for (int k = 0; k < 3; ++k) {
      kt::step(model, ws, env, s, bnd, dt, {integ});
      first.push_back(s);
    }
    // Restore, and step with a workspace that has meanwhile stepped another state.
    auto unrelated = swinging(model);
    kt::step(model, other, env, unrelated, bnd, 2 * dt, {integ});
    s = saved;
    for (int k = 0; k < 3; ++k) {
      kt::step(model, other, env, s, bnd, dt, {integ});
      CHECK(bitwise_equal(s, first[std::size_t(k)]));
      CHECK(kelp_test::same_bits(s.previous_position, first[std::size_t(k)].previous_position));
    }
  }
}

TEST_CASE("the clock is a double for every Scalar: 24 h of 10 ms steps end at 86400 s",
          "[tether][clock]") {
  // A float tether (one segment between two fixed points: the cheapest step there is) stepped
  // 8.64 million times by 0.01 s. A float clock read 3603.2 s after one hour and stopped
  // advancing at ~73 h.
  kelp_test::Vacuum<float> env;
  const kt::TetherModelf model(kelp_test::benchmark_line<float>(1));
  kt::TetherWorkspacef ws(model);
  const Vector3<float> a(0, 0, 0), b(20, 0, 0);
  auto s = kt::straight_line_state(model, a, b);
  const auto bnd = kt::TetherBoundaryf::fixed(a, b);
  static_assert(std::is_same<decltype(s.time), double>::value, "time is a double");
  const long steps = 8640000;
  for (long k = 0; k < steps; ++k) kt::step_symplectic_euler(model, ws, env, s, bnd, 0.01);
  CHECK(std::abs(s.time - 86400.0) <= 1e-9 * 86400.0);
}

TEST_CASE("a kinematic end running through a slack line's first node: the implicit steps converge",
          "[tether][implicit][dashpot]") {
  // The paper's tether (Fathom-class, BA = 100 N s, 0.5 m segments), slack, in deep still
  // water: the start end moves straight through the first free node, which sits a millimetre or
  // two ahead of it (on its path, or 10 µm off it). The clamped dashpot pulls along the
  // segment's direction, which turns over as the end passes the node: without the fade of the
  // dashpot on a segment folded below a tenth of its length (TetherModel::dashpot_fade), a
  // backward-Euler step across the passage has no solution (the node can neither be passed, the
  // damping then stopping the end's approach, nor be stopped, there being no damping before it
  // is passed), and Newton's method failed at every sub-step down to dt/64 (numerical_error) in
  // both cases. The system met this in a rough sea, the boat's attachment point running through
  // the first node of a slack tether.
  kelp_test::TestWater<double> env;
  env.surface_z = -100.0;  // deep
  const kt::TetherModeld model(kt::presets::rov_tether(1.5, 0.5));
  REQUIRE(model.segments() == 3);
  REQUIRE(model.dashpot_fade_length() == Approx(0.05));
  struct Case {
    double ahead, off, speed, turn;  // m, m, m/s, rad (of the second segment)
  };
  for (const Case& c : {Case{2e-3, 0.0, 1.0, 0.0}, Case{1e-3, 1e-5, 0.3, 1.5}}) {
    kt::TetherStated s(model);
    s.position.col(1) = Vector3<double>(c.ahead, c.off, 0);
    s.position.col(2) = Vector3<double>(0.2 * std::cos(c.turn), 0.2 * std::sin(c.turn), 0.1);
    s.position.col(3) = Vector3<double>(0.3, 0, 0.2);
    kt::TetherBoundaryd bnd = kt::TetherBoundaryd::fixed(s.position.col(0), s.position.col(3));
    bnd.start.velocity = Vector3<double>(c.speed, 0, 0);
    kt::TetherWorkspaced ws(model);
    const double dt = 0.01;
    kt::ImplicitOptionsd options;
    double residual = 0;
    for (int k = 0; k < 20; ++k) {
      INFO("node " << 1000 * c.ahead << " mm ahead, " << 1000 * c.off << " mm off, end at "
                   << c.speed << " m/s; step " << k << " at t = " << s.time << " s");
      kt::StepReportd r;
      REQUIRE_NOTHROW(r = kt::step_bdf2(model, ws, env, s, bnd, dt, options));
      residual = std::max(residual, r.residual);
      bnd.start = bnd.start.after(dt);
    }
    CHECK(residual <= options.acceleration_tolerance * dt);
    CHECK(kelp::all_finite(s.position));
    CHECK(kelp::all_finite(s.velocity));
  }
}
