// Fast catenary path: time per solve over a fixed grid of geometries, and the 3-D helper.
#include <benchmark/benchmark.h>

#include "grid.hpp"
#include "kelp/tether/catenary.hpp"

namespace {

void BM_CatenaryFastPath(benchmark::State& state) {
  const auto grid = kelp_bench::catenary_grid();
  for (auto _ : state) {
    for (const auto& g : grid) {
      auto r = kelp::tether::solve_catenary(g.D, g.dz, g.L);
      benchmark::DoNotOptimize(r);
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(grid.size()));
  // kIsRate | kInvert gives seconds per solve; the 1e-9 factor turns it into nanoseconds.
  state.counters["ns_per_solve"] =
      benchmark::Counter(1e-9 * static_cast<double>(state.iterations() * grid.size()),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_CatenaryFastPath);

void BM_CatenaryFastPathFloat(benchmark::State& state) {
  const auto grid = kelp_bench::catenary_grid();
  for (auto _ : state) {
    for (const auto& g : grid) {
      auto r = kelp::tether::solve_catenary(float(g.D), float(g.dz), float(g.L));
      benchmark::DoNotOptimize(r);
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(grid.size()));
}
BENCHMARK(BM_CatenaryFastPathFloat);

void BM_CatenaryReferenceCase(benchmark::State& state) {
  // The reference case of docs/equations.md, with D varied in the last digits so that nothing can
  // be hoisted.
  double D[8];
  for (int k = 0; k < 8; ++k) D[k] = 10.0 + 1e-9 * k;
  int k = 0;
  for (auto _ : state) {
    auto r = kelp::tether::solve_catenary(D[k++ & 7], 5.0, 20.0);
    benchmark::DoNotOptimize(r);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_CatenaryReferenceCase);

// The 3-D helper: plane, solve, both end forces (what a simulator needs per step).
void BM_CatenaryBetweenForces(benchmark::State& state) {
  const auto grid = kelp_bench::catenary_grid();
  const kelp::Vector3<double> start(0, 0, 0);
  for (auto _ : state) {
    for (const auto& g : grid) {
      const kelp::Vector3<double> end(0.6 * g.D, 0.8 * g.D, -g.dz);
      const auto shape = kelp::tether::catenary_between(start, end, g.L, 0.18);
      auto fs = shape.force_on_start();
      auto fe = shape.force_on_end();
      benchmark::DoNotOptimize(fs);
      benchmark::DoNotOptimize(fe);
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(grid.size()));
}
BENCHMARK(BM_CatenaryBetweenForces);

}  // namespace
