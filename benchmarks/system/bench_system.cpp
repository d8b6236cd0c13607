// The coupled system near issue 10's default configuration: BlueBoat at the surface, BlueROV2
// Heavy 5 m down, a 10 m ROV tether (40 segments; made heavier so that it stays under water, see
// params()), the moderate sea of the paper with the default wave components, both vehicles
// holding a constant thrust; steps of 10 ms.
//
//   BM_SystemStep               one full system step (counter realtime_factor = simulated seconds
//                               per CPU second)
//   BM_SystemTetherPart         the tether's share: its BDF2 advance over the step
//   BM_SystemVehiclePart        the vehicles' share: two RK4 steps in the environment
//   BM_SystemSurroundings       the environment sampling inside those: 2 vehicles × 4 stages
#include <benchmark/benchmark.h>

#include <stdexcept>

#include "kelp/environment/sea_state.hpp"
#include "kelp/system/system.hpp"
#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/presets.hpp"
#include "kelp/vehicle/presets.hpp"

namespace ks = kelp::system;
namespace kt = kelp::tether;
namespace kv = kelp::vehicle;
using kelp::Vector3;

namespace {

struct Setup {
  ks::SystemModeld model;
  ks::SystemWorkspaced ws;
  ks::SystemStated state;
  ks::SystemInputsd inputs;

  static ks::SystemParametersd params() {
    ks::SystemParametersd p;
    p.asv = kv::blueboat<double>().parameters;
    p.auv = kv::bluerov2_heavy<double>().parameters;
    p.asv_attachment = Vector3<double>(-0.5, 0, 0);
    p.auv_attachment = Vector3<double>(0, 0, -0.15);
    p.tether = kt::presets::rov_tether(10.0);
    // Heavier than the Fathom-class line (0.0454 kg/m, buoyant in seawater): a line floating at
    // the surface in the moderate sea still stalls Newton's method (open in issue 10).
    p.tether.mass_per_length = 0.07;
    return p;
  }
  Setup()
      : model(params(),
              kelp::environment::make_environment<double>(kelp::environment::presets::moderate())),
        ws(model) {
    state.auv.position = Vector3<double>(6, 0, 5);
    const Vector3<double> a = state.asv.point_position(model.parameters().asv_attachment);
    const Vector3<double> b = state.auv.point_position(model.parameters().auv_attachment);
    if (!kt::static_initial_state(model.tether(), ws.tether, kelp::environment::Environmentd{}, a,
                                  b, state.tether)
             .converged)
      throw std::runtime_error("bench_system: static initial state did not converge");
    inputs.auv.control << 10, 0, 0, 0, 0, 0;
    inputs.asv.control << 5, 0, 0, 0, 0, 0;
    for (int k = 0; k < 100; ++k) ks::step(model, ws, state, inputs, 0.01);  // settle in
  }
};

void BM_SystemStep(benchmark::State& st) {
  Setup s;
  for (auto _ : st) {
    ks::step(s.model, s.ws, s.state, s.inputs, 0.01);
    benchmark::DoNotOptimize(s.state.auv.position.data());
  }
  st.counters["realtime_factor"] =
      benchmark::Counter(0.01 * static_cast<double>(st.iterations()), benchmark::Counter::kIsRate);
}

void BM_SystemTetherPart(benchmark::State& st) {
  Setup s;
  const auto& p = s.model.parameters();
  for (auto _ : st) {
    kt::TetherBoundaryd ends;
    ends.start = ks::detail::predicted_end(s.state.asv, s.state.asv_nu_dot, p.asv_attachment);
    ends.end = ks::detail::predicted_end(s.state.auv, s.state.auv_nu_dot, p.auv_attachment);
    // The vehicles stay put, the tether goes on moving in the waves.
    kt::advance(s.model.tether(), s.ws.tether, s.model.environment(), s.state.tether, ends, 0.01,
                p.max_tether_dt, p.tether_integrator, p.tether_options);
    benchmark::DoNotOptimize(s.state.tether.position.data());
  }
}

void BM_SystemVehiclePart(benchmark::State& st) {
  Setup s;
  const auto& p = s.model.parameters();
  const Vector3<double> f(0, 0, 1);
  double t = s.state.time();
  for (auto _ : st) {
    ks::detail::step_vehicle(s.model.asv(), s.ws.asv, s.state.asv, s.model.environment(), t, 0.01,
                             s.inputs.asv, p.asv_attachment, f);
    ks::detail::step_vehicle(s.model.auv(), s.ws.auv, s.state.auv, s.model.environment(), t, 0.01,
                             s.inputs.auv, p.auv_attachment, f);
    t += 0.01;
    benchmark::DoNotOptimize(s.state.auv.position.data());
  }
}

void BM_SystemSurroundings(benchmark::State& st) {
  Setup s;
  double t = s.state.time();
  for (auto _ : st) {
    for (int stage = 0; stage < 4; ++stage) {
      auto a = kv::surroundings(s.model.environment(), s.state.asv, t);
      auto b = kv::surroundings(s.model.environment(), s.state.auv, t);
      benchmark::DoNotOptimize(a.water_velocity.data());
      benchmark::DoNotOptimize(b.water_velocity.data());
    }
    t += 0.01;
  }
}

}  // namespace

BENCHMARK(BM_SystemStep)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SystemTetherPart)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SystemVehiclePart)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SystemSurroundings)->Unit(benchmark::kMicrosecond);
