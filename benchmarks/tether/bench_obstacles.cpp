// Cost of the tether's obstacle contact (kelp/tether/contact.hpp) per BDF2 step of the
// benchmark line (100 segments, 10 ms steps, its far end heaving): no obstacles, then 1, 10 and
// 100 obstacles of which one — a horizontal cylinder under the middle of the line, which the
// line rests on — is near and the others are piles scattered 50–500 m away (the broad phase,
// ObstacleSet::for_each_near, should make them cost next to nothing), and the same counts all
// far (the broad phase alone). Also the force evaluation alone (compute_forces).
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "benchmark_line.hpp"
#include "kelp/environment/obstacles.hpp"
#include "kelp/tether/integrators.hpp"

namespace {

namespace ke = kelp::environment;
namespace kt = kelp::tether;

// `count` obstacles: with `near`, the first is a horizontal cylinder (radius 0.3 m) pressed 2 cm
// into the line's middle from below; the rest are vertical piles 50–500 m from the line.
ke::ObstacleSet obstacles(const kelp_bench::BenchmarkLine& line, int count, bool near) {
  ke::ObstacleSet set;
  const int n = line.model.segments();
  const Eigen::Vector3d mid = line.state.position.col(n / 2);
  const double r = 0.3;
  if (near && count > 0) {
    ke::Cylinder c;
    c.name = "near";
    c.from = mid + Eigen::Vector3d(0, -3, r - 0.02);
    c.to = mid + Eigen::Vector3d(0, 3, r - 0.02);
    c.radius = r;
    c.contact.friction = 0.3;
    set.add(c);
  }
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  while (set.size() < count) {
    const double range = 50 + 450 * u(rng), bearing = 2 * kelp::pi * u(rng);
    ke::Cylinder c;
    c.name = "far " + std::to_string(set.size());
    c.from = Eigen::Vector3d(range * std::cos(bearing), range * std::sin(bearing), 0);
    c.to = c.from + Eigen::Vector3d(0, 0, 30);
    c.radius = 0.5;
    set.add(c);
  }
  return set;
}

void BM_ContactStep(benchmark::State& st) {
  const int count = static_cast<int>(st.range(0));
  const bool near = st.range(1) != 0;
  kelp_bench::BenchmarkLine line(100);
  line.env.set_obstacles(obstacles(line, count, near));
  const double dt = 0.01;
  // Settle on the near cylinder first (the first steps after it appears are an impact).
  for (int k = 0; k < 300; ++k)
    kt::step(line.model, line.ws, line.env, line.state, line.boundary(line.state.time), dt);
  double newton = 0, contacts = 0;
  for (auto _ : st) {
    const kt::StepReportd rep =
        kt::step(line.model, line.ws, line.env, line.state, line.boundary(line.state.time), dt);
    newton += rep.newton_iterations;
    contacts += (line.ws.segment_contact.array() > 0).count();
    benchmark::DoNotOptimize(line.state.position.data());
  }
  const double iters = static_cast<double>(st.iterations());
  st.counters["newton_per_step"] = newton / iters;
  st.counters["segments_in_contact"] = contacts / iters;
}

void BM_ContactForces(benchmark::State& st) {
  const int count = static_cast<int>(st.range(0));
  const bool near = st.range(1) != 0;
  kelp_bench::BenchmarkLine line(100);
  line.env.set_obstacles(obstacles(line, count, near));
  for (auto _ : st) {
    kt::compute_forces(line.model, line.ws, line.env, 0.0, line.state.position,
                       line.state.velocity);
    benchmark::DoNotOptimize(line.ws.force.data());
  }
}

void counts(benchmark::internal::Benchmark* b) {
  b->Args({0, 0});
  for (int near : {1, 0})
    for (int count : {1, 10, 100}) b->Args({count, near});
  b->ArgNames({"obstacles", "near"});
}

}  // namespace

BENCHMARK(BM_ContactStep)->Apply(counts)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ContactForces)->Apply(counts)->Unit(benchmark::kNanosecond);
