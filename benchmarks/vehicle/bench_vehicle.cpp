// BlueROV2 Heavy in double: one forward-dynamics evaluation (target ≤ 100 ns) and one RK4 step
// (target ≤ 500 ns), plus the semi-implicit Euler step and the thruster allocation for context.
// Run with e.g. --benchmark_repetitions=10 --benchmark_report_aggregates_only=true.
#include <benchmark/benchmark.h>

#include "kelp/core/rotation.hpp"
#include "kelp/environment/sea_state.hpp"
#include "kelp/vehicle/integrators.hpp"
#include "kelp/vehicle/model.hpp"
#include "kelp/vehicle/presets.hpp"
#include "kelp/vehicle/thrusters.hpp"

namespace kv = kelp::vehicle;
using kelp::Vector3;
using kelp::Vector6;

namespace {

struct Fixture {
  kv::VehiclePreset<double> preset = kv::bluerov2_heavy<double>();
  kv::VehicleModel<double> model{preset.parameters};
  kv::VehicleWorkspace<double> ws;
  kv::VehicleState<double> x;
  Vector6<double> tau, tau_ext;
  Vector3<double> current{0.3, -0.1, 0.0};
  Fixture() {
    x.position << 1, 2, 5;
    x.attitude = kelp::quaternion_from_euler(0.05, -0.1, 0.7);
    x.nu << 0.4, -0.1, 0.05, 0.02, -0.03, 0.1;
    tau << 20, -5, 10, 0.2, -0.1, 1.0;
    tau_ext << 1, 0.5, -2, 0, 0.1, 0;
  }
};

void BM_ForwardDynamics(benchmark::State& st) {
  Fixture f;
  for (auto _ : st) {
    benchmark::DoNotOptimize(f.x);
    Vector6<double> a = kv::forward_dynamics(f.model, f.ws, f.x, f.tau, f.tau_ext, f.current);
    benchmark::DoNotOptimize(a);
  }
}
BENCHMARK(BM_ForwardDynamics);

void BM_Rk4Step(benchmark::State& st) {
  Fixture f;
  const kv::VehicleState<double> x0 = f.x;
  int k = 0;
  for (auto _ : st) {
    kv::step_rk4(f.model, f.ws, f.x, {f.tau, f.tau_ext}, 0.001, f.current);
    benchmark::DoNotOptimize(f.x);
    if (++k == 100000) {  // stay near the fixture's state
      f.x = x0;
      k = 0;
    }
  }
}
BENCHMARK(BM_Rk4Step);

// One RK4 step in the environment: the surroundings (current, 64-component JONSWAP orbital
// velocity and acceleration, elevation, wind; the slope too for the boat) sampled at each of the
// four stages, in the paper's moderate sea state. Arg 0: BlueROV2 Heavy at 5 m; 1: BlueBoat.
void BM_Rk4StepInEnvironment(benchmark::State& st) {
  Fixture f;
  const auto env =
      kelp::environment::make_environment<double>(kelp::environment::presets::moderate());
  const bool boat = st.range(0) == 1;
  const kv::VehiclePreset<double> preset = boat ? kv::blueboat<double>() : f.preset;
  const kv::VehicleModel<double> model(preset.parameters);
  if (boat) {
    f.x.position.z() = 0.0;
    f.x.attitude = kelp::quaternion_from_euler(0.0, 0.0, 0.7);
    f.x.nu.setZero();
  }
  const kv::VehicleState<double> x0 = f.x;
  int k = 0;
  for (auto _ : st) {
    kv::step_rk4(model, f.ws, env, f.x, {f.tau, f.tau_ext}, 0.01);
    benchmark::DoNotOptimize(f.x);
    if (++k == 10000) {  // stay near the fixture's state
      f.x = x0;
      k = 0;
    }
  }
}
BENCHMARK(BM_Rk4StepInEnvironment)->Arg(0)->Arg(1);

void BM_SemiImplicitEulerStep(benchmark::State& st) {
  Fixture f;
  const kv::VehicleState<double> x0 = f.x;
  int k = 0;
  for (auto _ : st) {
    kv::step_symplectic_euler(f.model, f.ws, f.x, {f.tau, f.tau_ext}, 0.001, f.current);
    benchmark::DoNotOptimize(f.x);
    if (++k == 100000) {
      f.x = x0;
      k = 0;
    }
  }
}
BENCHMARK(BM_SemiImplicitEulerStep);

void BM_ThrusterWrench(benchmark::State& st) {
  Fixture f;
  const kv::ThrusterAllocation<double> alloc(f.preset.thruster_positions,
                                             f.preset.thruster_directions);
  Eigen::VectorXd u = Eigen::VectorXd::LinSpaced(8, -0.8, 0.9), forces(8);
  for (auto _ : st) {
    benchmark::DoNotOptimize(u.data());
    for (int i = 0; i < 8; ++i) forces(i) = kv::t200_thrust(u(i));
    Vector6<double> w = alloc.wrench(forces);
    benchmark::DoNotOptimize(w);
  }
}
BENCHMARK(BM_ThrusterWrench);

}  // namespace
