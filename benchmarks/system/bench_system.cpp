// The coupled system in issue 10's default configuration (kelp::system::presets): BlueBoat at the
// surface, BlueROV2 Heavy 5 m down, a 10 m Fathom-class ROV tether (20 segments of 0.5 m), the
// paper's moderate or rough sea (kelp::system::presets::Sea; the scenarios paper_10m_moderate and
// paper_10m_rough) with the default wave components (64), wind and current; both vehicles hold a
// constant thrust; steps of 10 ms. Each benchmark's last part names the sea.
//
//   BM_SystemStep         one full system step; counter realtime_factor = simulated seconds per
//                         CPU second; newton_per_step = the tether's Newton corrections per step
//   BM_SystemStepSplit    the same step written out with a clock around each part (the timer
//                         costs ~50 ns a step): counters tether_us (tether advance, its water
//                         sampling included), vehicles_us (two RK4 steps in the environment, their
//                         sampling included), and, measured separately on the same states, what
//                         the environment sampling inside those costs: tether_water_us (one batch
//                         query of water and surface at the nodes, as each tether step makes) and
//                         vehicle_water_us (2 vehicles × 2 samples of their surroundings)
//   BM_SystemStepCorrected one step with one corrector pass (coupling_corrections = 1)
//   BM_FleetPairStep      the same pair as a fleet (kelp/system/fleet.hpp, system::fleet_of):
//                         what the graph's generality costs against BM_SystemStep
//   BM_ShipTmsRovStep     a work-class configuration in the rough sea: the ship's sheave (an
//                         anchor at the surface), a 60 m armoured umbilical (60 segments) to a
//                         TMS (a 400 kg point mass at ~50 m), a 30 m ROV tether (60 segments) on
//                         the TMS's winch to a BlueROV2 Heavy holding a constant thrust: 90 m
//                         of line; realtime_factor as BM_SystemStep
#include <benchmark/benchmark.h>

#include <chrono>

#include "kelp/system/fleet.hpp"
#include "kelp/system/presets.hpp"
#include "kelp/system/system.hpp"
#include "ship_tms_rov.hpp"

namespace ks = kelp::system;
namespace kt = kelp::tether;
namespace kv = kelp::vehicle;
using kelp::Vector3;

namespace {

struct Setup {
  ks::presets::PaperWorld<double> world;
  ks::SystemInputsd inputs;

  explicit Setup(ks::presets::Sea sea, int corrections = 0) : world(10.0, sea) {
    if (corrections > 0) {
      auto p = world.model.parameters();
      p.coupling_corrections = corrections;
      world.model = ks::SystemModeld(p, world.model.environment());
    }
    inputs.auv.tau << 10, 0, 0, 0, 0, 0;
    inputs.asv.tau << 5, 0, 0, 0, 0, 0;
    for (int k = 0; k < 200; ++k) step();  // settle in
  }
  ks::SystemReportd step() {
    return ks::step(world.model, world.workspace, world.state, inputs, 0.01);
  }
};

// Full steps with `corrections` corrector passes; counters realtime_factor, newton_per_step.
void run_steps(benchmark::State& st, ks::presets::Sea sea, int corrections) {
  Setup s(sea, corrections);
  double newton = 0;
  for (auto _ : st) {
    newton += s.step().tether.newton_iterations;
    benchmark::DoNotOptimize(s.world.state.auv.position.data());
  }
  const double iters = static_cast<double>(st.iterations());
  st.counters["realtime_factor"] = benchmark::Counter(0.01 * iters, benchmark::Counter::kIsRate);
  st.counters["newton_per_step"] = newton / iters;
}

void BM_SystemStep(benchmark::State& st, ks::presets::Sea sea) { run_steps(st, sea, 0); }

void BM_SystemStepCorrected(benchmark::State& st, ks::presets::Sea sea) { run_steps(st, sea, 1); }

void BM_SystemStepSplit(benchmark::State& st, ks::presets::Sea sea) {
  Setup s(sea);
  auto& w = s.world;
  const auto& p = w.model.parameters();
  const auto& env = w.model.environment();
  const double dt = 0.01;
  using clock = std::chrono::steady_clock;
  double tether = 0, vehicles = 0, tether_water = 0, vehicle_water = 0;
  kelp::Matrix3X<double> vel(3, w.model.tether().nodes()), acc(3, w.model.tether().nodes());
  kelp::VectorX<double> zeta(w.model.tether().nodes());
  for (auto _ : st) {
    const double t = w.state.time;
    const auto t0 = clock::now();
    kt::TetherBoundaryd ends;
    ends.start = ks::detail::predicted_end(w.state.asv, w.state.asv_nu_dot, p.asv_attachment);
    ends.end = ks::detail::predicted_end(w.state.auv, w.state.auv_nu_dot, p.auv_attachment);
    kt::advance(w.model.tether(), w.workspace.tether, env, w.state.tether, ends, dt,
                {p.max_tether_dt, p.tether_integrator, p.tether_options});
    const Vector3<double> fa = w.workspace.tether.end_impulse.on_start / dt;
    const Vector3<double> fb = w.workspace.tether.end_impulse.on_end / dt;
    const auto t1 = clock::now();
    w.state.asv_nu_dot = ks::detail::step_vehicle(w.model.asv(), w.workspace.asv, w.state.asv, env,
                                                  t, dt, s.inputs.asv, p.asv_attachment, fa);
    w.state.auv_nu_dot = ks::detail::step_vehicle(w.model.auv(), w.workspace.auv, w.state.auv, env,
                                                  t, dt, s.inputs.auv, p.auv_attachment, fb);
    const auto t2 = clock::now();
    env.sample_water(w.state.tether.position, t, vel, acc, zeta);
    const auto t3 = clock::now();
    for (int sample = 0; sample < 2; ++sample) {
      benchmark::DoNotOptimize(kv::surroundings(w.model.asv(), env, w.state.asv, t));
      benchmark::DoNotOptimize(kv::surroundings(w.model.auv(), env, w.state.auv, t));
    }
    const auto t4 = clock::now();
    // The system's clock follows the tether's, as system::step keeps it (the vehicles' own
    // clocks were advanced by their steps).
    w.state.time = w.state.tether.time;
    tether += std::chrono::duration<double, std::micro>(t1 - t0).count();
    vehicles += std::chrono::duration<double, std::micro>(t2 - t1).count();
    tether_water += std::chrono::duration<double, std::micro>(t3 - t2).count();
    vehicle_water += std::chrono::duration<double, std::micro>(t4 - t3).count();
  }
  const double n = static_cast<double>(st.iterations());
  st.counters["tether_us"] = tether / n;
  st.counters["vehicles_us"] = vehicles / n;
  st.counters["tether_water_us"] = tether_water / n;
  st.counters["vehicle_water_us"] = vehicle_water / n;
}

// Fleet steps of `model` from `state` under `inputs` (settled in for 2 s first).
void run_fleet(benchmark::State& st, const ks::FleetModeld& model, ks::FleetStated state,
               const ks::FleetInputsd& inputs) {
  ks::FleetWorkspaced ws(model);
  for (int k = 0; k < 200; ++k) ks::step(model, ws, state, inputs, 0.01);
  double newton = 0;
  for (auto _ : st) {
    newton += ks::step(model, ws, state, inputs, 0.01).tether.newton_iterations;
    benchmark::DoNotOptimize(state.vehicles.back().position.data());
  }
  const double iters = static_cast<double>(st.iterations());
  st.counters["realtime_factor"] = benchmark::Counter(0.01 * iters, benchmark::Counter::kIsRate);
  st.counters["newton_per_step"] = newton / iters;
}

void BM_FleetPairStep(benchmark::State& st, ks::presets::Sea sea) {
  const ks::presets::PaperWorld<double> w(10.0, sea);
  const ks::FleetModeld model(ks::fleet_of(w.model.parameters()), w.model.environment());
  ks::FleetWorkspaced ws(model);
  const ks::FleetStated s = ks::initial_state(model, ws, {w.state.asv, w.state.auv});
  ks::FleetInputsd in(model);
  in.vehicles[1].tau << 10, 0, 0, 0, 0, 0;
  in.vehicles[0].tau << 5, 0, 0, 0, 0, 0;
  run_fleet(st, model, s, in);
}

void BM_ShipTmsRovStep(benchmark::State& st) {
  const ks::FleetModeld model(kelp_bench::ship_tms_rov_parameters(),
                              ks::presets::environment<double>(ks::presets::Sea::rough));
  ks::FleetWorkspaced ws(model);
  std::vector<kv::VehicleStated> rov(1);
  rov[0].position = kelp_bench::ship_tms_rov_rov_start();
  const ks::FleetStated s =
      ks::initial_state(model, ws, rov, {kelp_bench::ship_tms_rov_tms_start()});
  ks::FleetInputsd in(model);
  in.vehicles[0].tau << 10, 0, 0, 0, 0, 0;
  run_fleet(st, model, s, in);
}

}  // namespace

BENCHMARK_CAPTURE(BM_FleetPairStep, rough, ks::presets::Sea::rough)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ShipTmsRovStep)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_SystemStep, moderate, ks::presets::Sea::moderate)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_SystemStep, rough, ks::presets::Sea::rough)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_SystemStepSplit, moderate, ks::presets::Sea::moderate)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_SystemStepSplit, rough, ks::presets::Sea::rough)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_SystemStepCorrected, moderate, ks::presets::Sea::moderate)
    ->Unit(benchmark::kMicrosecond);
