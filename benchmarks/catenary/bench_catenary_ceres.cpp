// Ceres path (TinySolver on the paper's residuals): warm-started from the fast path, from the
// previous control step, and from a naive start, over the same grid as the fast path.
#include <benchmark/benchmark.h>

#include "grid.hpp"
#include "kelp/ceres/catenary_solver.hpp"

namespace {

void BM_CeresWarmFastPath(benchmark::State& state) {
  const auto grid = kelp_bench::catenary_grid();
  kelp::ceres_solver::CatenarySolver solver;
  for (auto _ : state) {
    for (const auto& g : grid) {
      auto r = solver.solve(g.D, g.dz, g.L);
      benchmark::DoNotOptimize(r);
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(grid.size()));
}
BENCHMARK(BM_CeresWarmFastPath);

// A control loop: each geometry is solved from the solution of the geometry 1 ms earlier
// (ends moving ~1 mm, i.e. D and dz changed by 1e-4 L).
void BM_CeresWarmPreviousStep(benchmark::State& state) {
  const auto grid = kelp_bench::catenary_grid();
  std::vector<kelp::tether::CatenaryResult<double>> previous;
  for (const auto& g : grid)
    previous.push_back(kelp::tether::solve_catenary(g.D * (1 - 1e-4), g.dz - 1e-4 * g.L, g.L));
  kelp::ceres_solver::CatenarySolver solver;
  int64_t iterations = 0;
  for (auto _ : state) {
    for (size_t i = 0; i < grid.size(); ++i) {
      const auto& g = grid[i];
      auto r = solver.solve(g.D, g.dz, g.L, previous[i].a, previous[i].c);
      iterations += r.iterations;
      benchmark::DoNotOptimize(r);
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(grid.size()));
  state.counters["lm_iterations"] =
      static_cast<double>(iterations) / static_cast<double>(state.iterations() * grid.size());
}
BENCHMARK(BM_CeresWarmPreviousStep);

// For scale: Ceres from a poor guess (a doubled, the vertex moved by D/4; restarted from the fast
// path where Levenberg-Marquardt does not reach the tolerance), and from the naive start
// (a = L, c = D/2) on the reference case.
void BM_CeresPoorGuess(benchmark::State& state) {
  const auto grid = kelp_bench::catenary_grid();
  std::vector<kelp::tether::CatenaryResult<double>> exact;
  for (const auto& g : grid) exact.push_back(kelp::tether::solve_catenary(g.D, g.dz, g.L));
  kelp::ceres_solver::CatenarySolver solver;
  int64_t iterations = 0, failures = 0, restarts = 0;
  for (auto _ : state) {
    for (size_t i = 0; i < grid.size(); ++i) {
      const auto& g = grid[i];
      auto r = solver.solve(g.D, g.dz, g.L, 2.0 * exact[i].a, exact[i].c + 0.25 * g.D);
      iterations += r.iterations;
      failures += r.status != kelp::tether::CatenaryStatus::converged;
      restarts += solver.restarted();
      benchmark::DoNotOptimize(r);
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(grid.size()));
  state.counters["lm_iterations"] =
      static_cast<double>(iterations) / static_cast<double>(state.iterations() * grid.size());
  state.counters["restarted_fraction"] =
      static_cast<double>(restarts) / static_cast<double>(state.iterations() * grid.size());
  state.counters["failed_fraction"] =
      static_cast<double>(failures) / static_cast<double>(state.iterations() * grid.size());
}
BENCHMARK(BM_CeresPoorGuess);

void BM_CeresNaiveStartReferenceCase(benchmark::State& state) {
  kelp::ceres_solver::CatenarySolver solver;
  int iterations = 0;
  for (auto _ : state) {
    auto r = solver.solve(10.0, 5.0, 20.0, 20.0, 5.0);
    iterations = r.iterations;
    benchmark::DoNotOptimize(r);
  }
  state.counters["lm_iterations"] = iterations;
}
BENCHMARK(BM_CeresNaiveStartReferenceCase);

}  // namespace
