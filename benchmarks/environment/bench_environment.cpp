// Environment queries: the batch water query for a tether's nodes (the target: 100 points,
// 64 wave components, ≤ 10 µs), single-point samples, both on each kernel path (the deterministic
// mode's portable one and the dispatched ones), and the calm sea's cost.
#include <benchmark/benchmark.h>

#include <limits>
#include <string>

#include "kelp/environment/environment.hpp"
#include "kelp/environment/sea_state.hpp"

using namespace kelp::environment;

namespace {
template <typename S>
Environment<S> rough_sea(double seabed, int components) {
  SeaStateOptions o;
  o.wave_components = components;
  o.spreading = 1.0;
  o.seabed_depth = seabed;
  return make_environment<S>(presets::rough(), o);
}

// 100 nodes of a 20 m tether hanging from the surface to 15 m depth.
template <typename S>
kelp::Matrix3X<S> tether_nodes(int n) {
  kelp::Matrix3X<S> p(3, n);
  for (int i = 0; i < n; ++i) p.col(i) << S(0.15 * i), S(0.05 * i), S(0.15 * i);
  return p;
}

template <typename S>
void sample_water(benchmark::State& state, double seabed) {
  const int n = static_cast<int>(state.range(0)), nc = static_cast<int>(state.range(1));
  const auto env = rough_sea<S>(seabed, nc);
  const auto pts = tether_nodes<S>(n);
  kelp::Matrix3X<S> vel(3, n), acc(3, n);
  S t = S(0);
  for (auto _ : state) {
    env.sample_water(pts, t, vel, acc);
    benchmark::DoNotOptimize(vel.data());
    benchmark::DoNotOptimize(acc.data());
    t += S(0.01);
  }
  state.SetItemsProcessed(state.iterations() * n * nc);
}

void BM_SampleWaterDeep(benchmark::State& s) {
  sample_water<double>(s, std::numeric_limits<double>::infinity());
}
void BM_SampleWaterFiniteDepth(benchmark::State& s) { sample_water<double>(s, 40.0); }
void BM_SampleWaterDeepFloat(benchmark::State& s) {
  sample_water<float>(s, std::numeric_limits<double>::infinity());
}

// Sets the kernel path of range(0): 0 portable in its SSE2 build (as on a CPU without AVX2),
// 1 portable (the deterministic mode; the widest build without FMA the CPU has), 2 AVX2 + FMA,
// 3 AVX-512; labels the benchmark with it.
kelp::simd::KernelPath kernel_arg(benchmark::State& state) {
  const int k = static_cast<int>(state.range(0));
  kelp::simd::detail::portable_build_cap().store(k == 0 ? 0 : 2);
  const auto path = static_cast<kelp::simd::KernelPath>(k == 0 ? 1 : k);
  std::string label = kelp::simd::kernel_name(path);
  if (path == kelp::simd::KernelPath::portable)
    label += std::string(" (") +
             kelp::simd::detail::portable_build_name(kelp::simd::detail::portable_build()) +
             " build)";
  state.SetLabel(label);
  return path;
}

// The batch query on each kernel path (kernel_arg); 100 points, range(1) wave components, deep
// water.
void BM_SampleWaterKernel(benchmark::State& state) {
  const auto path = kernel_arg(state);
  const int n = 100, nc = static_cast<int>(state.range(1));
  if (!kelp::simd::kernel_supported(path)) {
    state.SkipWithError("this CPU lacks this kernel path");
    return;
  }
  auto env = rough_sea<double>(std::numeric_limits<double>::infinity(), nc);
  auto waves = env.waves();
  waves.set_kernel(path);
  env.set_waves(waves);
  const auto pts = tether_nodes<double>(n);
  kelp::Matrix3X<double> vel(3, n), acc(3, n);
  double t = 0;
  for (auto _ : state) {
    env.sample_water(pts, t, vel, acc);
    benchmark::DoNotOptimize(vel.data());
    benchmark::DoNotOptimize(acc.data());
    t += 0.01;
  }
  state.SetItemsProcessed(state.iterations() * n * nc);
}

// A single-point sample (the kernel's components-in-lanes form) on each kernel path.
void BM_SamplePointKernel(benchmark::State& state) {
  const auto path = kernel_arg(state);
  if (!kelp::simd::kernel_supported(path)) {
    state.SkipWithError("this CPU lacks this kernel path");
    return;
  }
  auto env = rough_sea<double>(std::numeric_limits<double>::infinity(), 64);
  auto waves = env.waves();
  waves.set_kernel(path);
  env.set_waves(waves);
  kelp::Vector3<double> p(1.0, 2.0, 3.0);
  double t = 0;
  for (auto _ : state) {
    auto s = env.sample(p, t);
    benchmark::DoNotOptimize(s);
    t += 0.01;
  }
}

void BM_SampleWaterCalm(benchmark::State& state) {
  const Environment<double> env;
  const auto pts = tether_nodes<double>(100);
  kelp::Matrix3X<double> vel(3, 100), acc(3, 100);
  double t = 0;
  for (auto _ : state) {
    env.sample_water(pts, t, vel, acc);
    benchmark::DoNotOptimize(vel.data());
    t += 0.01;
  }
}

// Calm sea with a constant current: the water query only writes the current.
void BM_SampleWaterCalmCurrent(benchmark::State& state) {
  Environment<double> env;
  env.set_current(kelp::Vector3<double>(0.5, -0.2, 0.0));
  const auto pts = tether_nodes<double>(100);
  kelp::Matrix3X<double> vel(3, 100), acc(3, 100);
  double t = 0;
  for (auto _ : state) {
    env.sample_water(pts, t, vel, acc);
    benchmark::DoNotOptimize(vel.data());
    benchmark::DoNotOptimize(acc.data());
    t += 0.01;
  }
}

void BM_SamplePoint(benchmark::State& state) {
  const auto env = rough_sea<double>(std::numeric_limits<double>::infinity(), 64);
  kelp::Vector3<double> p(1.0, 2.0, 3.0);
  double t = 0;
  for (auto _ : state) {
    auto s = env.sample(p, t);
    benchmark::DoNotOptimize(s);
    t += 0.01;
  }
}

void BM_SamplePointCalm(benchmark::State& state) {
  const Environment<double> env;
  kelp::Vector3<double> p(1.0, 2.0, 3.0);
  double t = 0;
  for (auto _ : state) {
    auto s = env.sample(p, t);
    benchmark::DoNotOptimize(s);
    t += 0.01;
  }
}
}  // namespace

BENCHMARK(BM_SampleWaterDeep)->Args({100, 64})->Args({10, 64})->Args({100, 16});
BENCHMARK(BM_SampleWaterFiniteDepth)->Args({100, 64});
BENCHMARK(BM_SampleWaterDeepFloat)->Args({100, 64});
BENCHMARK(BM_SampleWaterKernel)->Args({0, 64})->Args({1, 64})->Args({2, 64})->Args({3, 64});
BENCHMARK(BM_SamplePointKernel)->Arg(0)->Arg(1)->Arg(2)->Arg(3);
BENCHMARK(BM_SampleWaterCalm);
BENCHMARK(BM_SampleWaterCalmCurrent);
BENCHMARK(BM_SamplePoint);
BENCHMARK(BM_SamplePointCalm);
