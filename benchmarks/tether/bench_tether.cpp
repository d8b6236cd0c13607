// Lumped-mass tether benchmarks on kelp's benchmark line (TetherParameters defaults: 20 m,
// d 8 mm, 0.07 kg/m, EA 1e5 N, Cdn 1.2, Cdt 0.008, Can 1, no internal damping), ends 10 m apart
// horizontally and 5 m vertically in still seawater, started from static equilibrium with the
// far (AUV) end heaving 0.1 m at 0.2 Hz so that every step works on a moving line.
//
//   BM_TetherForces/<N>            one force evaluation (no Jacobian)
//   BM_TetherStep/<integrator>/<N> one full step at the integrator's dt: estimate_stable_dt
//                                  (0.8 × the stability limit) for symplectic Euler, RK2 (on the
//                                  line with internal damping ζ = 0.2), RK4; 10 ms for the
//                                  implicit schemes (bdf2: the default simplified Newton /
//                                  W-method with the adaptive Jacobian; bdf2_exact: Newton's
//                                  method, the symmetric matrix formed at every iteration;
//                                  bdf2_whole: Newton with the whole Jacobian, JacobianKind::whole;
//                                  bdf2_one_newton: one unchecked Newton correction per step, see
//                                  ImplicitOptions::check_convergence)
//   BM_WholeNewtonAssemble/<N>     assembly of the whole Newton matrix (kelp/tether/jacobian.hpp)
//   BM_WholeNewtonFactor/<N>       its block LU factorisation; BM_WholeNewtonSolve/<N> one solve
//   BM_WinchStep/<kind>/<N>        one system-like step of the line on a winch at its start
//                                  (kelp/tether/winch.hpp): advance_winch then a 10 ms BDF2
//                                  advance. plain: the winch holds (no re-mesh); remesh: every
//                                  10th step the winch moves at full speed across a threshold,
//                                  inserting or removing a node (restarting BDF2's history and
//                                  the kept Newton matrix); remesh_per_step = 0.1
// Counters: ns_per_node = time / (force evaluations × nodes) — for the implicit schemes this
// includes the Jacobian assembly and the block-tridiagonal solves; realtime_factor = simulated
// seconds per CPU second; evals_per_step, newton_per_step and factor_per_step (Newton matrices
// factored) for the implicit schemes.
#include <benchmark/benchmark.h>

#include <cmath>
#include <stdexcept>

#include "benchmark_line.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/integrators.hpp"
#include "kelp/tether/jacobian.hpp"
#include "kelp/tether/lumped_mass.hpp"
#include "kelp/tether/whole_newton.hpp"
#include "kelp/tether/winch.hpp"

namespace kt = kelp::tether;
using kelp::Vector3;

namespace {

using Setup = kelp_bench::BenchmarkLine;

void BM_TetherForces(benchmark::State& st) {
  const int n = static_cast<int>(st.range(0));
  Setup s(n);
  for (auto _ : st) {
    kt::compute_forces(s.model, s.ws, s.env, 0.0, s.state.position, s.state.velocity);
    benchmark::DoNotOptimize(s.ws.force.data());
    benchmark::ClobberMemory();
  }
  st.counters["ns_per_node"] =
      benchmark::Counter(1e-9 * static_cast<double>(st.iterations()) * (n + 1),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_TetherStep(benchmark::State& st, kt::Integrator integ, bool linearly_implicit = false,
                   kt::NewtonMethod newton_method = kt::NewtonMethod::simplified,
                   kt::JacobianKind jacobian = kt::JacobianKind::adaptive) {
  const int n = static_cast<int>(st.range(0));
  // RK2 (explicit midpoint) is unstable on an undamped line at any step (estimate_stable_dt
  // refuses it): it runs on the line with internal damping ζ = 0.2 at its highest mode.
  Setup s(n, integ == kt::Integrator::rk2 ? 0.2 : 0.0);
  const double dt =
      kt::is_implicit(integ) ? 0.01 : kt::estimate_stable_dt(s.model, integ, s.env.water_density());
  kt::ImplicitOptionsd options;
  options.newton = newton_method;
  options.jacobian = jacobian;
  if (linearly_implicit) {
    options.max_iterations = 1;
    options.check_convergence = false;
  }
  double evals = 0, newton = 0, factorisations = 0;
  for (auto _ : st) {
    const kt::StepReportd r =
        kt::step(s.model, s.ws, s.env, s.state, s.boundary(s.state.time), dt, {integ, options});
    evals += r.force_evaluations;
    newton += r.newton_iterations;
    factorisations += r.factorisations;
    benchmark::DoNotOptimize(s.state.position.data());
  }
  const double iters = static_cast<double>(st.iterations());
  st.counters["ns_per_node"] = benchmark::Counter(
      1e-9 * evals * (n + 1), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  st.counters["realtime_factor"] = benchmark::Counter(iters * dt, benchmark::Counter::kIsRate);
  st.counters["dt_us"] = dt * 1e6;
  if (kt::is_implicit(integ)) {
    st.counters["evals_per_step"] = evals / iters;
    st.counters["newton_per_step"] = newton / iters;
    st.counters["factor_per_step"] = factorisations / iters;
  }
}

void BM_WinchStep(benchmark::State& st, bool remesh) {
  const int n = static_cast<int>(st.range(0));
  Setup s(n);
  kt::WinchParameters<double> w;
  w.min_length = 0.5 * s.model.parameters().length;
  w.max_length = 2 * s.model.parameters().length;
  w.max_acceleration = 1000;  // the speed reverses within a step
  const kt::WinchModel<double> wm(s.model.parameters(), w);
  kt::WinchWorkspace<double> wws(wm);
  kt::TetherWorkspaced ws(wm.line(n));
  kt::TetherStated state = s.state;
  const double l = wm.segment_length(), dt = 0.01;
  // Just under the insertion threshold: paying out at 0.5 m/s crosses it in one step, and
  // reeling in after the insertion (segment 0 then just over 0.5 l) removes the node again.
  state.winch_length = 1.5 * l - 0.5 * w.max_speed * dt;
  double remeshes = 0, newton = 0, substeps = 0, whole = 0;
  long k = 0;
  for (auto _ : st) {
    // remesh: one step paying out (a node inserted), 9 holding, one reeling in (the node
    // removed), 9 holding: a re-mesh every 10 steps, BDF2 and the kept Newton matrix recovering
    // in between (a re-mesh at every step drives the line at the step's frequency).
    const long phase = k++ % 20;
    const double command =
        !remesh ? 0.0 : (phase == 0 ? w.max_speed : (phase == 10 ? -w.max_speed : 0.0));
    const kt::RemeshReport<double> r = kt::advance_winch(wm, wws, state, ws, command, dt);
    remeshes += r.inserted + r.removed;
    const kt::StepReportd rep =
        kt::advance(wm.line_of(state), ws, s.env, state, s.boundary(state.time), dt);
    newton += rep.newton_iterations;
    substeps += rep.substeps;
    whole += rep.whole_jacobian_attempts;
    benchmark::DoNotOptimize(state.position.data());
  }
  const double iters = static_cast<double>(st.iterations());
  st.counters["newton_per_step"] = newton / iters;
  st.counters["substeps_per_step"] = substeps / iters;
  st.counters["whole_per_step"] = whole / iters;
  st.counters["remesh_per_step"] = remeshes / static_cast<double>(st.iterations());
  st.counters["realtime_factor"] =
      benchmark::Counter(static_cast<double>(st.iterations()) * dt, benchmark::Counter::kIsRate);
}

void sizes(benchmark::internal::Benchmark* b) {
  for (int n : {10, 20, 50, 100, 200}) b->Arg(n);
  b->Unit(benchmark::kMicrosecond);
}

}  // namespace

BENCHMARK(BM_TetherForces)->Apply(sizes)->Unit(benchmark::kNanosecond);
BENCHMARK_CAPTURE(BM_WinchStep, plain, false)->Arg(20)->Arg(100)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_WinchStep, remesh, true)->Arg(20)->Arg(100)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_TetherStep, symplectic_euler, kt::Integrator::symplectic_euler)->Apply(sizes);
BENCHMARK_CAPTURE(BM_TetherStep, rk2, kt::Integrator::rk2)->Apply(sizes);
BENCHMARK_CAPTURE(BM_TetherStep, rk4, kt::Integrator::rk4)->Apply(sizes);
BENCHMARK_CAPTURE(BM_TetherStep, implicit_euler, kt::Integrator::implicit_euler)->Apply(sizes);
BENCHMARK_CAPTURE(BM_TetherStep, bdf2, kt::Integrator::bdf2)->Apply(sizes);
// Newton's method with the matrix formed at every iteration (ImplicitOptions::newton = exact).
BENCHMARK_CAPTURE(BM_TetherStep, bdf2_exact, kt::Integrator::bdf2, false, kt::NewtonMethod::exact)
    ->Apply(sizes);
// One unchecked Newton correction per step (ImplicitOptions::check_convergence = false).
BENCHMARK_CAPTURE(BM_TetherStep, bdf2_one_newton, kt::Integrator::bdf2, true)->Apply(sizes);
// Exact Newton: the whole Jacobian (ImplicitOptions::jacobian = JacobianKind::whole).
BENCHMARK_CAPTURE(BM_TetherStep, bdf2_whole, kt::Integrator::bdf2, false, kt::NewtonMethod::exact,
                  kt::JacobianKind::whole)
    ->Apply(sizes);

namespace {

// BM_BlockSolve/<N>: one block-tridiagonal Newton solve (kt::detail::solve_block_tridiagonal) on
// the benchmark line's Jacobian after 20 BDF2 steps at 10 ms (c_m = 1, c_v = γh, c_x = (γh)²,
// γ = 2/3). ns_per_node = time / free nodes.
// BM_BlockSolveKept/<N>: the same system solved with the factor kept by a first solve
// (kt::detail::solve_factored_block_tridiagonal: forward elimination and back substitution only,
// what the simplified Newton method does while its matrix serves).
void BM_BlockSolve(benchmark::State& st, bool kept) {
  const int n = static_cast<int>(st.range(0));
  Setup s(n);
  const double dt = 0.01, gh = 2.0 / 3.0 * dt;
  for (int k = 0; k < 20; ++k)
    kt::step(s.model, s.ws, s.env, s.state, s.boundary(s.state.time), dt, {kt::Integrator::bdf2});
  kt::compute_forces<true>(s.model, s.ws, s.env, s.state.time, s.state.position, s.state.velocity);
  for (int i = 0; i < s.model.nodes(); ++i)
    s.ws.rhs.col(i) = Vector3<double>(std::cos(i), 1.0, std::sin(0.5 * i));
  kt::detail::factor_solve_block_tridiagonal(s.model, s.ws, 1.0, gh, gh * gh,
                                             s.ws.newton_factor.data(), true);
  for (auto _ : st) {
    if (kept)
      kt::detail::solve_factored_block_tridiagonal(s.model, s.ws.newton_factor.data(), s.ws.rhs,
                                                   s.ws.delta);
    else
      kt::detail::solve_block_tridiagonal(s.model, s.ws, 1.0, gh, gh * gh);
    benchmark::DoNotOptimize(s.ws.delta.data());
    benchmark::ClobberMemory();
  }
  const int free_nodes = s.model.last_free_node() - s.model.first_free_node() + 1;
  st.counters["ns_per_node"] =
      benchmark::Counter(1e-9 * static_cast<double>(st.iterations()) * free_nodes,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

}  // namespace

namespace {

// The whole Newton matrix of the benchmark line after 20 BDF2 steps at 10 ms (γh = 2/3 · 10 ms):
// assembly (BM_WholeNewtonAssemble), factorisation (BM_WholeNewtonFactor, assembly excluded by
// restoring the assembled matrix) and one solve (BM_WholeNewtonSolve). ns_per_node = time / nodes.
struct WholeNewtonSetup {
  Setup s;
  kelp::Matrix3X<double> d;
  double gh = 2.0 / 3.0 * 0.01;
  explicit WholeNewtonSetup(int n) : s(n) {
    for (int k = 0; k < 20; ++k)
      kt::step(s.model, s.ws, s.env, s.state, s.boundary(s.state.time), 0.01,
               {kt::Integrator::bdf2});
    kt::compute_forces<true>(s.model, s.ws, s.env, s.state.time, s.state.position,
                             s.state.velocity);
    d = 0.01 * s.state.velocity;
    for (int i = 0; i < s.model.nodes(); ++i)
      s.ws.rhs.col(i) = Vector3<double>(std::cos(i), 1.0, std::sin(0.5 * i));
    kt::assemble_whole_newton_matrix(s.model, s.ws, s.env, s.state.position, s.state.velocity, d,
                                     gh);
  }
};

void per_node(benchmark::State& st, int nodes) {
  st.counters["ns_per_node"] =
      benchmark::Counter(1e-9 * static_cast<double>(st.iterations()) * nodes,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_WholeNewtonAssemble(benchmark::State& st) {
  WholeNewtonSetup w(static_cast<int>(st.range(0)));
  for (auto _ : st) {
    kt::assemble_whole_newton_matrix(w.s.model, w.s.ws, w.s.env, w.s.state.position,
                                     w.s.state.velocity, w.d, w.gh);
    benchmark::DoNotOptimize(w.s.ws.newton_lu.data());
    benchmark::ClobberMemory();
  }
  per_node(st, w.s.model.nodes());
}

void BM_WholeNewtonFactor(benchmark::State& st) {
  WholeNewtonSetup w(static_cast<int>(st.range(0)));
  const Eigen::Matrix<double, 9, Eigen::Dynamic> assembled = w.s.ws.newton_lu;
  for (auto _ : st) {
    st.PauseTiming();
    w.s.ws.newton_lu = assembled;
    st.ResumeTiming();
    kt::factor_whole_newton_matrix(w.s.model, w.s.ws);
    benchmark::DoNotOptimize(w.s.ws.newton_lu.data());
    benchmark::ClobberMemory();
  }
  per_node(st, w.s.model.nodes());
}

void BM_WholeNewtonSolve(benchmark::State& st) {
  WholeNewtonSetup w(static_cast<int>(st.range(0)));
  kt::factor_whole_newton_matrix(w.s.model, w.s.ws);
  for (auto _ : st) {
    kt::solve_whole_newton_matrix(w.s.model, w.s.ws, w.s.ws.rhs, w.s.ws.delta);
    benchmark::DoNotOptimize(w.s.ws.delta.data());
    benchmark::ClobberMemory();
  }
  per_node(st, w.s.model.nodes());
}

}  // namespace

BENCHMARK(BM_WholeNewtonAssemble)->Arg(20)->Arg(100)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_WholeNewtonFactor)->Arg(20)->Arg(100)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_WholeNewtonSolve)->Arg(20)->Arg(100)->Unit(benchmark::kNanosecond);
BENCHMARK_CAPTURE(BM_BlockSolve, factor, false)
    ->Arg(20)
    ->Arg(50)
    ->Arg(100)
    ->Arg(200)
    ->Unit(benchmark::kNanosecond);
BENCHMARK_CAPTURE(BM_BlockSolve, kept, true)
    ->Arg(20)
    ->Arg(50)
    ->Arg(100)
    ->Arg(200)
    ->Unit(benchmark::kNanosecond);
