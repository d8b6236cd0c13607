// The implicit steps' simplified Newton method (ImplicitOptions::newton = simplified: the factored
// Newton matrix kept in the state and reused across iterations and steps) against Newton's
// method (exact): the same results to the tolerance in a rough sea and through a snap load, the
// matrix reused on a calm line, formed anew when a segment changes branch or γh changes, a
// failed reuse retried with fresh matrices before any step halving, the kept factor solving a
// new right-hand side as the factorisation did, and no heap allocation.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <vector>

#include "kelp/environment/environment.hpp"
#include "kelp/environment/sea_state.hpp"
#include "kelp/tether/block_solve.hpp"
#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/integrators.hpp"
#include "kelp/tether/lumped_mass.hpp"
#include "tether_test_support.hpp"

namespace kt = kelp::tether;
using kelp::Vector3;

namespace {

kt::ImplicitOptionsd with(kt::NewtonMethod m) {
  kt::ImplicitOptionsd o;
  o.newton = m;
  return o;
}

// Runs the same steps with both methods; boundary_at(t) gives the ends' motion over the step
// starting at t. Returns the relative RMS difference of the end tensions (both ends), the
// largest node distance and each method's report.
struct Comparison {
  double tension_rms = 0, worst_tension_gap = 0, peak_tension = 0, max_distance = 0;
  kt::StepReportd simplified, exact;
};

template <typename Env, typename Boundary>
Comparison compare_methods(const kt::TetherModeld& model, const Env& env,
                           const kt::TetherStated& s0, Boundary&& boundary_at, double dt,
                           int steps) {
  kt::TetherWorkspaced ws_s(model), ws_e(model);
  auto s = s0, e = s0;
  const kt::ImplicitOptionsd simplified = with(kt::NewtonMethod::simplified);
  const kt::ImplicitOptionsd exact = with(kt::NewtonMethod::exact);
  Comparison c;
  double se = 0, sr = 0;
  for (int k = 0; k < steps; ++k) {
    c.simplified +=
        kt::step(model, ws_s, env, s, boundary_at(s.time), dt, {kt::Integrator::bdf2, simplified});
    c.exact +=
        kt::step(model, ws_e, env, e, boundary_at(e.time), dt, {kt::Integrator::bdf2, exact});
    for (int end = 0; end < 2; ++end) {
      const double fs = (end ? ws_s.end_forces.on_end : ws_s.end_forces.on_start).norm();
      const double fe = (end ? ws_e.end_forces.on_end : ws_e.end_forces.on_start).norm();
      se += (fs - fe) * (fs - fe);
      sr += fe * fe;
      c.worst_tension_gap = std::max(c.worst_tension_gap, std::abs(fs - fe));
      c.peak_tension = std::max(c.peak_tension, fe);
    }
    c.max_distance =
        std::max(c.max_distance, (s.position - e.position).colwise().norm().maxCoeff());
  }
  c.tension_rms = std::sqrt(se / sr);
  return c;
}

}  // namespace

TEST_CASE("simplified and exact Newton agree to the tolerance in a rough sea and a snap load",
          "[tether][implicit][newton]") {
  const double dt = 0.01;
  SECTION("the 50-segment line from near the surface to 5 m down, paper's rough sea, 20 s") {
    const auto env =
        kelp::environment::make_environment<double>(kelp::environment::presets::rough());
    const kt::TetherModeld model(kelp_test::benchmark_line<double>(50));
    const Vector3<double> a(0, 0, 0.5), b(10, 0, 5);
    kt::TetherStated s0;
    kt::TetherWorkspaced ws(model);
    REQUIRE(
        kt::static_initial_state(model, ws, kelp::environment::Environmentd{}, a, b, s0).converged);
    const auto bnd = kt::TetherBoundaryd::fixed(a, b);
    const auto boundary_at = [&](double) { return bnd; };
    const Comparison c = compare_methods(model, env, s0, boundary_at, dt, 2000);
    // The sea drives the line through the surface band: differences at the tolerance's level
    // grow over the run, whichever method makes them. The scale: Newton's method against
    // itself with a 100 times tighter tolerance.
    kt::ImplicitOptionsd tight = with(kt::NewtonMethod::exact);
    tight.acceleration_tolerance *= 0.01;
    kt::TetherWorkspaced ws_t(model), ws_s(model), ws_e(model);
    auto t = s0, si = s0, e = s0;
    double se_s = 0, se_e = 0, sr = 0;
    for (int k = 0; k < 2000; ++k) {
      kt::step(model, ws_t, env, t, bnd, dt, {kt::Integrator::bdf2, tight});
      kt::step(model, ws_s, env, si, bnd, dt, {kt::Integrator::bdf2});
      kt::step(model, ws_e, env, e, bnd, dt, {kt::Integrator::bdf2, with(kt::NewtonMethod::exact)});
      const double ft = ws_t.end_forces.on_end.norm(), fs = ws_s.end_forces.on_end.norm(),
                   fe = ws_e.end_forces.on_end.norm();
      se_s += (fs - ft) * (fs - ft);
      se_e += (fe - ft) * (fe - ft);
      sr += ft * ft;
    }
    const double off_s = std::sqrt(se_s / sr), off_e = std::sqrt(se_e / sr);
    INFO("end tension RMS difference " << c.tension_rms << ", worst " << c.worst_tension_gap
                                       << " N, nodes up to " << c.max_distance << " m apart");
    INFO("against the tight reference: simplified " << off_s << ", exact " << off_e);
    INFO("simplified: " << c.simplified.newton_iterations << " corrections, "
                        << c.simplified.factorisations << " factorisations, "
                        << c.simplified.reused_factorisations
                        << " reuses; exact: " << c.exact.newton_iterations << " corrections, "
                        << c.exact.factorisations << " factorisations");
    CHECK(off_s <= 1.25 * off_e);
    CHECK(c.tension_rms <= 1.25 * off_e);
    CHECK(off_e < 5e-3);  // the comparison's scale: 0.5 % of end tension over 20 s at most
    CHECK(c.simplified.factorisations < c.exact.factorisations);
    CHECK(c.exact.reused_factorisations == 0);
    CHECK(c.simplified.retries == 0);
  }
  SECTION("snap load: a slack line whose end is pulled 8 m at 4 m/s, then held") {
    kelp_test::TestWater<double> env;
    auto p = kelp_test::benchmark_line<double>(40);
    p.internal_damping = 50.0;
    const kt::TetherModeld model(p);
    const Vector3<double> a(0, 0, 0), b(12, 0, 5);
    const kt::TetherStated s0 = kt::catenary_initial_state(model, env, a, b);
    const double v = 4.0, t_pull = 2.0;
    const auto boundary_at = [&](double t) {
      kt::TetherBoundaryd bnd = kt::TetherBoundaryd::fixed(a, b);
      bnd.end.position.x() += v * std::min(t, t_pull);
      bnd.end.velocity.x() = t < t_pull - 1e-9 ? v : 0.0;
      return bnd;
    };
    const Comparison c = compare_methods(model, env, s0, boundary_at, dt, 500);
    INFO("end tension RMS difference " << c.tension_rms << ", worst " << c.worst_tension_gap
                                       << " N of a peak " << c.peak_tension << " N, nodes up to "
                                       << c.max_distance << " m apart");
    INFO("simplified: " << c.simplified.newton_iterations << " corrections, "
                        << c.simplified.factorisations << " factorisations, "
                        << c.simplified.reused_factorisations
                        << " reuses; exact: " << c.exact.newton_iterations << " corrections, "
                        << c.exact.factorisations << " factorisations");
    CHECK(c.peak_tension > 1000.0);  // the line does snap taut
    CHECK(c.tension_rms < 1e-5);
    CHECK(c.max_distance < 1e-5);
    CHECK(c.simplified.factorisations < c.exact.factorisations);
  }
}

TEST_CASE("the kept Newton matrix is reused on a calm line and formed anew when it must be",
          "[tether][implicit][newton]") {
  const kelp::environment::Environmentd env;
  const kt::TetherModeld model(kelp_test::benchmark_line<double>(20));
  kt::TetherWorkspaced ws(model);
  const Vector3<double> a(0, 0, 0), b(10, 0, 5);
  kt::TetherStated s;
  REQUIRE(kt::static_initial_state(model, ws, env, a, b, s).converged);
  // The far end heaving slowly.
  const auto heave = [&](double t) {
    kt::TetherBoundaryd bnd = kt::TetherBoundaryd::fixed(a, b);
    bnd.end.position.z() += 0.05 * std::sin(t);
    bnd.end.velocity.z() = 0.05 * std::cos(t);
    bnd.end.acceleration.z() = -0.05 * std::sin(t);
    return bnd;
  };
  const int steps = 200;
  SECTION("calm: fewer factorisations than steps; Newton's method factors at every step") {
    kt::StepReportd simplified, exact;
    auto e = s;
    kt::TetherWorkspaced ws_e(model);
    for (int k = 0; k < steps; ++k) {
      simplified += kt::step(model, ws, env, s, heave(s.time), 0.01,
                             {kt::Integrator::bdf2, with(kt::NewtonMethod::simplified)});
      exact += kt::step(model, ws_e, env, e, heave(e.time), 0.01,
                        {kt::Integrator::bdf2, with(kt::NewtonMethod::exact)});
    }
    INFO("simplified: " << simplified.factorisations << " factorisations, "
                        << simplified.reused_factorisations << " reuses, "
                        << simplified.force_evaluations
                        << " evaluations; exact: " << exact.factorisations << " factorisations, "
                        << exact.force_evaluations << " evaluations");
    CHECK(simplified.factorisations < steps / 4);
    CHECK(simplified.reused_factorisations > steps / 2);
    // About as many evaluations, most without the Jacobian terms.
    CHECK(simplified.force_evaluations <= 1.1 * exact.force_evaluations);
    CHECK(exact.factorisations >= steps);
    CHECK(exact.reused_factorisations == 0);
    CHECK(s.newton.gh > 0.0);
    CHECK(e.newton.gh == 0.0);  // Newton's method keeps none
  }
  SECTION("a new dt or a cleared history forms the matrix again") {
    // Only γh may trigger here: no residual-based refresh.
    kt::ImplicitOptionsd o = with(kt::NewtonMethod::simplified);
    o.refresh_residual = 1e30;
    // Past the first steps from the static state, where segments at the kink of the axial
    // force change branch.
    for (int k = 0; k < 20; ++k)
      kt::step(model, ws, env, s, heave(s.time), 0.01, {kt::Integrator::bdf2, o});
    const double gh = s.newton.gh;
    REQUIRE(gh == Approx(2.0 / 3.0 * 0.01));
    auto r = kt::step(model, ws, env, s, heave(s.time), 0.01, {kt::Integrator::bdf2, o});
    CHECK(r.factorisations == 0);
    // backward Euler at the new dt
    r = kt::step(model, ws, env, s, heave(s.time), 0.005, {kt::Integrator::bdf2, o});
    CHECK(r.factorisations >= 1);
    CHECK(s.newton.gh == 0.005);
    s.clear_history();
    CHECK(s.newton.gh == 0.0);
    r = kt::step(model, ws, env, s, heave(s.time), 0.005, {kt::Integrator::bdf2, o});
    CHECK(r.factorisations >= 1);
  }
  SECTION("a segment that goes slack forms the matrix again") {
    // Only the branch test may trigger: no age limit, no contraction or refresh test.
    kt::ImplicitOptionsd o = with(kt::NewtonMethod::simplified);
    o.max_matrix_age = 1000000;
    o.max_contraction = 0.999;
    o.refresh_residual = 1e30;
    // A straight line stretched 1 % between fixed ends: every segment taut.
    const Vector3<double> far(20.2, 0, 0);
    auto line = kt::straight_line_state(model, a, far);
    const auto fixed = kt::TetherBoundaryd::fixed(a, far);
    kt::StepReportd calm;
    for (int k = 0; k < 20; ++k)
      calm += kt::step(model, ws, env, line, fixed, 0.01, {kt::Integrator::bdf2, o});
    CHECK(calm.factorisations <= 3);  // backward Euler, then BDF2
    REQUIRE(line.newton.branch.minCoeff() == 2.0);
    // The far end moves in at 2 m/s: within 0.1 s the line goes slack.
    kt::TetherBoundaryd in = fixed;
    in.end.velocity.x() = -2.0;
    bool slack = false;
    for (int k = 0; k < 20 && !slack; ++k) {
      in.end.position.x() = far.x() - 2.0 * (line.time - 0.2);
      const auto r = kt::step(model, ws, env, line, in, 0.01, {kt::Integrator::bdf2, o});
      slack = line.newton.branch.minCoeff() < 2.0;
      INFO("step " << k << ": factorisations " << r.factorisations << ", reuses "
                   << r.reused_factorisations);
      if (slack) {
        CHECK(r.factorisations >= 1);
        CHECK(r.retries == 0);
      }
    }
    CHECK(slack);  // the kept matrix knows the slack segments
  }
}

TEST_CASE("a step that fails with a reused matrix is retried with fresh ones before halving",
          "[tether][implicit][newton]") {
  // Two corrections per step and a kept matrix that is never refreshed by the residual or age
  // tests: on a slowly heaving line (where two Newton corrections from the predictor meet the
  // tolerance) the ageing matrix leaves the residual above it, and the step is attempted again
  // with Newton's method (a fresh matrix), not split.
  const kelp::environment::Environmentd env;
  const kt::TetherModeld model(kelp_test::benchmark_line<double>(20));
  kt::TetherWorkspaced ws(model);
  const Vector3<double> a(0, 0, 0), b(10, 0, 5);
  kt::TetherStated s;
  REQUIRE(kt::static_initial_state(model, ws, env, a, b, s).converged);
  kt::ImplicitOptionsd o = with(kt::NewtonMethod::simplified);
  o.max_iterations = 2;
  o.max_matrix_age = 1000000;
  o.max_contraction = 0.999;
  o.refresh_residual = 1e30;
  kt::StepReportd total;
  int fallbacks = 0;
  for (int k = 0; k < 100; ++k) {
    kt::TetherBoundaryd bnd = kt::TetherBoundaryd::fixed(a, b);
    bnd.end.position.z() += 0.05 * std::sin(s.time);
    bnd.end.velocity.z() = 0.05 * std::cos(s.time);
    bnd.end.acceleration.z() = -0.05 * std::sin(s.time);
    const auto r = kt::step(model, ws, env, s, bnd, 0.01, {kt::Integrator::bdf2, o});
    if (r.reused_factorisations > 0 && r.factorisations > 0) ++fallbacks;
    total += r;
  }
  INFO("fallbacks " << fallbacks << ", retries " << total.retries << ", worst residual "
                    << total.residual);
  CHECK(fallbacks > 0);
  CHECK(total.retries == 0);
  CHECK(total.substeps == 100);
  CHECK(total.residual <= o.acceleration_tolerance * 0.01);
}

TEST_CASE("a kept factor solves a new right-hand side as the factorisation solved its own",
          "[tether][implicit][newton][block_solve]") {
  // For every end-mode combination and a range of sizes: factor_solve_block_tridiagonal with
  // its factor kept, then solve_factored_block_tridiagonal on the same rhs (bit for bit the same
  // δ) and on another rhs (the same δ as a fresh factorisation with that rhs, to round-off).
  const kelp::environment::Environmentd env;
  for (int n : {1, 2, 3, 4, 7, 20, 51}) {
    for (int mode = 0; mode < 4; ++mode) {
      auto p = kelp_test::benchmark_line<double>(n);
      p.start_mode = mode & 1 ? kt::EndMode::free : kt::EndMode::kinematic;
      p.end_mode = mode & 2 ? kt::EndMode::free : kt::EndMode::kinematic;
      const kt::TetherModeld model(p);
      kt::TetherWorkspaced ws(model);
      auto s = kt::catenary_initial_state(model, env, Vector3<double>(0, 0, 0),
                                          Vector3<double>(10, 0, 5));
      for (int i = 0; i < model.nodes(); ++i) s.velocity.col(i) = Vector3<double>(0.1 * i, 0, 0.2);
      kt::compute_forces<true>(model, ws, env, 0.0, s.position, s.velocity);
      const double gh = 2.0 / 3.0 * 0.01;
      kelp::Matrix3X<double> rhs1(3, model.nodes()), rhs2(3, model.nodes());
      for (int i = 0; i < model.nodes(); ++i) {
        rhs1.col(i) = Vector3<double>(std::cos(i), 1.0, std::sin(0.5 * i));
        rhs2.col(i) = Vector3<double>(0.3 - 0.01 * i, std::sin(i), -2.0);
      }
      ws.rhs = rhs1;
      ws.delta.setZero();
      kt::detail::factor_solve_block_tridiagonal(model, ws, 1.0, gh, gh * gh,
                                                 ws.newton_factor.data(), true);
      const kelp::Matrix3X<double> d1 = ws.delta;
      ws.rhs = rhs2;
      ws.delta.setZero();
      kt::detail::solve_block_tridiagonal(model, ws, 1.0, gh, gh * gh);
      const kelp::Matrix3X<double> d2 = ws.delta;
      kelp::Matrix3X<double> k1 = kelp::Matrix3X<double>::Zero(3, model.nodes()), k2 = k1;
      kt::detail::solve_factored_block_tridiagonal(model, ws.newton_factor.data(), rhs1, k1);
      kt::detail::solve_factored_block_tridiagonal(model, ws.newton_factor.data(), rhs2, k2);
      INFO("N = " << n << ", start " << (mode & 1 ? "free" : "kinematic") << ", end "
                  << (mode & 2 ? "free" : "kinematic"));
      CHECK(std::memcmp(k1.data(), d1.data(), sizeof(double) * std::size_t(d1.size())) == 0);
      CHECK((k2 - d2).cwiseAbs().maxCoeff() <= 1e-12 * d2.cwiseAbs().maxCoeff());
    }
  }
}

TEMPLATE_TEST_CASE("the simplified Newton steps allocate nothing on the heap",
                   "[tether][implicit][newton][malloc]", double, float) {
  using S = TestType;
  kelp::environment::Environment<S> env;
  env.set_current(Vector3<S>(S(0.3), S(0.1), S(0)));
  const kt::TetherModel<S> model(kelp_test::benchmark_line<S>(30));
  kt::TetherWorkspace<S> ws(model);
  const Vector3<S> a(0, 0, 0), b(10, 0, 5);
  auto state = kt::catenary_initial_state(model, env, a, b);
  auto boundary = kt::TetherBoundary<S>::fixed(a, b);
  boundary.end.velocity = Vector3<S>(S(0), S(0), S(0.2));
  kt::ImplicitOptions<S> o;
  o.newton = kt::NewtonMethod::simplified;
  kt::StepReport<S> r;
  Eigen::internal::set_is_malloc_allowed(false);
  for (int k = 0; k < 30; ++k)
    r += kt::step(model, ws, env, state, boundary, S(0.01), {kt::Integrator::bdf2, o});
  for (int k = 0; k < 3; ++k)
    r += kt::step(model, ws, env, state, boundary, S(0.005), {kt::Integrator::bdf2, o});
  Eigen::internal::set_is_malloc_allowed(true);
  CHECK(r.reused_factorisations > 0);
  CHECK(r.factorisations > 0);
  CHECK(kelp::all_finite(state.position));
}

TEST_CASE(
    "BDF2 predicts from the accelerations the last step left: M⁻¹F at its state; the kept "
    "matrix serves longer for it, and a fast line falls back to the linear predictor",
    "[tether][implicit][newton]") {
  const kelp::environment::Environmentd env;
  // 100 segments (20 cm): stiff enough axially that the linear predictor's O(h²) error keeps
  // the kept matrix for a few steps only. No added mass: M = m I, so the residual test bounds
  // |a − M⁻¹F| directly.
  auto p = kelp_test::benchmark_line<double>(100);
  p.normal_added_mass = 0.0;
  p.tangential_added_mass = 0.0;
  const kt::TetherModeld model(p);
  kt::TetherWorkspaced ws(model), check(model);
  const Vector3<double> a(0, 0, 0), b(10, 0, 5);
  kt::TetherStated s0;
  REQUIRE(kt::static_initial_state(model, ws, env, a, b, s0).converged);
  const kt::ImplicitOptionsd o = with(kt::NewtonMethod::simplified);
  const double dt = 0.01, tol = o.acceleration_tolerance;
  // The far end heaving, 0.1 m (1 − cos ωt); `forget`: the accelerations dropped before each step
  // (the linear predictor 2v_n − v_{n−1} throughout).
  struct Run {
    kt::StepReportd report;
    kt::TetherStated state;
    double worst = 0, scale = 0;  // largest |a − M⁻¹F| and |M⁻¹F| on the free nodes [m/s²]
    int linear_steps = 0;         // steps that started from the linear predictor
  };
  const auto run = [&](double omega, bool forget) {
    Run r;
    r.state = s0;
    kt::TetherStated& s = r.state;
    for (int k = 0; k < 600; ++k) {
      kt::TetherBoundaryd bnd = kt::TetherBoundaryd::fixed(a, b);
      bnd.end.position.z() += 0.1 * (1 - std::cos(omega * s.time));
      bnd.end.velocity.z() = 0.1 * omega * std::sin(omega * s.time);
      bnd.end.acceleration.z() = 0.1 * omega * omega * std::cos(omega * s.time);
      if (forget) s.has_acceleration = false;
      if (s.has_acceleration && !s.predict_from_acceleration) ++r.linear_steps;
      r.report += kt::step(model, ws, env, s, bnd, dt, {kt::Integrator::bdf2, o});
      REQUIRE(s.has_acceleration);
      // The converged residual R = M(v − v̂) − γh F, |R_ik| ≤ m_i tol dt, leaves
      // |a − M⁻¹F| ≤ √3 tol dt/(γh) per node.
      kt::compute_forces(model, check, env, s.time, s.position, s.velocity);
      kelp::Matrix3X<double> acc(3, model.nodes());
      const Vector3<double> zero = Vector3<double>::Zero();
      kt::accelerations_from_forces(model, check, zero, zero, acc);
      for (int i = 1; i < model.segments(); ++i) {
        r.worst = std::max(r.worst, (s.acceleration.col(i) - acc.col(i)).norm());
        r.scale = std::max(r.scale, acc.col(i).norm());
      }
    }
    return r;
  };
  for (const double omega : {2 * kelp::pi * 0.2, 10.0}) {
    const Run kept = run(omega, false), forgotten = run(omega, true);
    INFO("ω " << omega << " rad/s: largest |a − M⁻¹F| " << kept.worst << " m/s² (largest |a| "
              << kept.scale << "); factorisations " << kept.report.factorisations
              << " with the accelerations (" << kept.linear_steps << " steps predicted linearly), "
              << forgotten.report.factorisations << " without; evaluations "
              << kept.report.force_evaluations << ", " << forgotten.report.force_evaluations);
    CHECK(kept.worst <= std::sqrt(3.0) * 1.5 * tol);
    CHECK(kept.scale > 1e3 * tol);  // the bound is not met by accelerations near zero
    if (omega < 2.0) {
      // Both stop on the same residual test, so they agree to the tolerance.
      CHECK((kept.state.position - forgotten.state.position).cwiseAbs().maxCoeff() < 1e-5);
      // The benchmark line's heave: the accelerations' predictor (chosen at almost every step)
      // lets the kept matrix make many more steps in one correction.
      CHECK(kept.linear_steps < 60);
      CHECK(4 * kept.report.factorisations < forgotten.report.factorisations);
      CHECK(kept.report.force_evaluations <= forgotten.report.force_evaluations);
    } else {
      // A fast one (ωh = 0.1, its stiff modes ringing): the accelerations overshoot, the steps
      // turn to the linear predictor and cost no more than with it alone. (The two runs part
      // by centimetres here: the violent heave grows differences at the tolerance's level.)
      CHECK(kept.linear_steps > 100);
      CHECK(kept.report.factorisations <= 1.05 * forgotten.report.factorisations);
      CHECK(kept.report.force_evaluations <= 1.05 * forgotten.report.force_evaluations);
    }
  }
}
