// Soak test of the tethered pair: a long run in the paper's rough sea (Hs 4.5 m, wind 4.5 m/s; the
// current at 0.5 m/s, which the BlueROV2 can stem, so that both vehicles stay under control) with
// kelp's controllers flying the ROV's survey and the boat following it. After every step it checks
//  - that the state is finite and the step converged: the tether's worst Newton residual is within
//    ImplicitOptions::acceleration_tolerance · dt (a retried step counts), with the library's
//    Newton settings and no explicit fallback (the safety net is on only so that a step Newton
//    cannot converge is counted rather than ending the run: the count must be 0);
//  - that the clock does not drift: the state's time equals k·dt to 1e-9 s after k steps;
//  - that the wave phase does not drift: the surface elevation at the ROV, evaluated by the
//    environment at the state's time, equals the sum of the wave components evaluated
//    independently in long double at k·dt, to 1e-6 m (every simulated minute);
//  - that the energy stays bounded: the system's mechanical energy (vehicles' kinetic and
//    hydrostatic, tether's kinetic, elastic, weight and buoyancy) is finite, and its peak in every
//    later window of 10 minutes is within the first windows' envelope (no secular growth);
//  - flat memory: no heap allocation after the first simulated minute (the program's malloc
//    counted, tests/support/heap_counter.hpp: the library's allocations and Eigen's included), and
//    resident memory growing by less than 1 MiB (not checked under AddressSanitizer, whose shadow
//    memory grows it);
//  - that the vehicles stay under control: over the second half of the run the ROV within 20 m of
//    its survey path and the boat within 25 m of the ROV horizontally (the waves move both by a
//    few metres; a vehicle losing control to the current drifts off by a hundred).
// Usage: tethered_pair_soak [--hours H] (default 0.5 h of simulated time; 6 for the full soak).
// Prints the real-time factor (not asserted: speed is measured by benchmarks).
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <new>
#include <string>
#include <type_traits>
#include <vector>

#include "kelp/sim/closed_loop.hpp"
#include "support/heap_counter.hpp"

namespace {

// Under AddressSanitizer the resident set grows with its shadow memory and the fake stack frames
// of detect_stack_use_after_return, whatever the program does: the resident-memory check is left
// out there (the heap-allocation count still holds).
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kResidentMemoryChecked = false;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kResidentMemoryChecked = false;
#else
constexpr bool kResidentMemoryChecked = true;
#endif
#else
constexpr bool kResidentMemoryChecked = true;
#endif
}  // namespace

namespace {

long resident_kib() {
  std::ifstream statm("/proc/self/statm");
  long size = 0, resident = 0;
  statm >> size >> resident;
  return resident * 4;  // pages of 4 KiB
}

// ζ(x, y, t) of the environment's waves, summed in long double from the components' parameters
// (ζ = Σ a_j cos(k_j (x cos θ_j + y sin θ_j) + φ_j − ω_j t)).
template <typename Waves>
double reference_elevation(const Waves& waves, double x, double y, long double t) {
  long double z = 0;
  for (std::size_t j = 0; j < waves.size(); ++j) {
    const long double k = waves.wave_number_of(j), th = waves.direction(j);
    const long double arg = k * (x * std::cos(th) + y * std::sin(th)) + waves.phase(j) -
                            static_cast<long double>(waves.omega(j)) * t;
    z += waves.amplitude(j) * std::cos(arg);
  }
  return static_cast<double>(z);
}

int failures = 0;
// `what` is the message or, for the checks made at every step, a callable that builds it: passing
// checks then format nothing.
template <typename Message>
void expect(bool ok, const Message& what) {
  if (ok) return;
  if (++failures > 20) return;
  if constexpr (std::is_invocable_v<Message>)
    std::fprintf(stderr, "soak: FAILED: %s\n", std::string(what()).c_str());
  else
    std::fprintf(stderr, "soak: FAILED: %s\n", std::string(what).c_str());
}

}  // namespace

int main(int argc, char** argv) {
  double hours = 0.5;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--hours" && i + 1 < argc) {
      hours = std::atof(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: %s [--hours H]\n", argv[0]);
      return 2;
    }
  }
  if (!(hours > 0 && hours <= 1000)) {
    std::fprintf(stderr, "soak: --hours must be in (0, 1000]\n");
    return 2;
  }
  namespace ke = kelp::environment;
  kelp::sim::Scenario sc;
  const ke::SeaState rough = ke::presets::rough();
  sc.sea = kelp::sim::Sea::custom;
  sc.significant_height = rough.significant_height;
  sc.peak_period = rough.peak_period;
  sc.wind_speed = rough.wind_speed;
  sc.current_speed = 0.5;
  sc.current_direction = rough.current_direction;
  sc.duration = 3600.0 * hours;
  sc.seed = 7;
  sc.explicit_fallback = true;  // counted, must not fire
  // The soak tests the numerics over hours, not the endurance: batteries that last (the
  // BlueROV2's 15.6 Ah pack is empty after some 20 min of this sea's station keeping).
  sc.auv_battery.capacity_ah = 1e4;
  sc.asv_battery.capacity_ah = 1e4;

  const double dt = 0.01;
  const long window_steps = 60000;  // 10 simulated minutes
  const long warm_up = 6000;        // one simulated minute
  struct Window {
    double e_min = INFINITY, e_max = -INFINITY;
  };
  std::vector<Window> windows;
  windows.reserve(static_cast<std::size_t>(sc.duration / 600.0) + 2);
  double worst_residual_ratio = 0, worst_clock = 0, worst_wave = 0;
  long retries = 0, fallbacks = 0, allocations_after_warm_up = 0, rss_start = 0;
  long last_allocations = 0;
  kelp::sim::SimulateOptions o;
  o.scenario_file = "(soak: rough sea, 0.5 m/s current)";
  o.on_step = [&](const kelp::sim::StepView& v) {
    Eigen::internal::set_is_malloc_allowed(true);
    const long allocated = kelp_test::heap_allocations() - last_allocations;
    if (v.step > warm_up) allocations_after_warm_up += allocated;
    if (v.step == warm_up) rss_start = resident_kib();
    const auto& p = v.model.parameters();
    const double ratio =
        v.report.tether.residual / (p.tether_options.acceleration_tolerance * p.max_tether_dt);
    worst_residual_ratio = std::max(worst_residual_ratio, ratio);
    expect(ratio <= 1.0, [&] {
      return "step " + std::to_string(v.step) + ": tether residual " + std::to_string(ratio) +
             " x tolerance";
    });
    retries += v.report.tether.retries;
    fallbacks += v.report.tether_fallbacks;
    const double clock = std::abs(v.state.time - static_cast<double>(v.step) * dt);
    worst_clock = std::max(worst_clock, clock);
    expect(clock <= 1e-9, [&] {
      return "step " + std::to_string(v.step) + ": clock off by " + std::to_string(clock) + " s";
    });
    if (v.step % 100 == 0) {  // every simulated second
      expect(kelp::all_finite(v.state.tether.position) && kelp::all_finite(v.state.tether.velocity),
             "tether state not finite");
      const double e = kelp::system::energy(v.model, v.state).total();
      expect(std::isfinite(e), "energy not finite");
      const std::size_t w = static_cast<std::size_t>((v.step - 1) / window_steps);
      if (windows.size() <= w) windows.resize(w + 1);
      windows[w].e_min = std::min(windows[w].e_min, e);
      windows[w].e_max = std::max(windows[w].e_max, e);
    }
    if (v.step % 6000 == 0) {  // every simulated minute
      const auto& waves = v.model.environment().waves();
      const double x = v.state.auv.position.x(), y = v.state.auv.position.y();
      const double ref =
          reference_elevation(waves, x, y, static_cast<long double>(v.step) * (long double)dt);
      const double err = std::abs(waves.elevation(x, y, v.state.time) - ref);
      worst_wave = std::max(worst_wave, err);
      expect(err <= 1e-6, [&] {
        return "wave elevation off by " + std::to_string(err) +
               " m at t = " + std::to_string(v.state.time) + " s";
      });
    }
    last_allocations = kelp_test::heap_allocations();
    // Between two observations only the controllers and the step run: no allocation allowed.
    Eigen::internal::set_is_malloc_allowed(v.step < warm_up);
  };
  kelp::sim::RunSummary summary;
  try {
    summary = kelp::sim::simulate(sc, o);
  } catch (const std::exception& e) {
    Eigen::internal::set_is_malloc_allowed(true);
    std::fprintf(stderr, "soak: the run threw: %s\n", e.what());
    return 1;
  }
  Eigen::internal::set_is_malloc_allowed(true);
  const long rss_growth = resident_kib() - rss_start;
  expect(allocations_after_warm_up == 0,
         std::to_string(allocations_after_warm_up) + " heap allocations after the first minute");
  expect(!kResidentMemoryChecked || rss_growth < 1024,
         "resident memory grew by " + std::to_string(rss_growth) + " KiB");
  // Energy: the peak of every later window within the envelope of the first two, widened by
  // their own spread (waves and gusts make it fluctuate; a growing instability would not stay).
  if (windows.size() >= 3) {
    const double lo = std::min(windows[0].e_min, windows[1].e_min);
    const double hi = std::max(windows[0].e_max, windows[1].e_max);
    const double spread = hi - lo;
    for (std::size_t w = 2; w < windows.size(); ++w)
      expect(windows[w].e_max <= hi + spread && windows[w].e_min >= lo - spread,
             "energy window " + std::to_string(w) + " [" + std::to_string(windows[w].e_min) + ", " +
                 std::to_string(windows[w].e_max) + "] J outside the first windows' [" +
                 std::to_string(lo) + ", " + std::to_string(hi) + "] J by more than their spread");
  }
  expect(fallbacks == 0, std::to_string(fallbacks) + " tether steps redone explicitly");
  const kelp::sim::SolverSummary& solver = summary.tether_solver;
  expect(solver.explicit_fallbacks == fallbacks && solver.retried_steps == retries,
         "summary's tether_solver disagrees with the steps' reports: " +
             kelp::sim::solver_summary_json(solver));
  const double late_auv = summary.auv.second_half_max_path_error_m;
  const double late_asv = summary.asv.second_half_max_distance_to_auv_m;
  expect(late_auv < 20.0, "ROV " + std::to_string(late_auv) + " m off its path");
  expect(late_asv < 25.0, "boat " + std::to_string(late_asv) + " m from the ROV");
  std::printf("soak: %.2f h simulated in %.1f s wall, %.0fx real time\n", hours,
              summary.wall_s.value_or(0.0), summary.realtime_factor.value_or(0.0));
  std::printf(
      "soak: worst tether residual %.3g x tolerance, %ld retried steps, %ld explicit "
      "fallbacks\n",
      worst_residual_ratio, retries, fallbacks);
  std::printf("soak: Newton iterations per step %.3f on average, at most %d (budget %d)\n",
              solver.newton_iterations_per_step_mean, solver.newton_iterations_per_step_max,
              solver.newton_budget);
  std::printf("soak: clock drift %.3g s, wave elevation error %.3g m\n", worst_clock, worst_wave);
  std::printf("soak: %ld heap allocations after the first minute, resident memory %+ld KiB%s\n",
              allocations_after_warm_up, rss_growth,
              kResidentMemoryChecked ? "" : " (not checked under AddressSanitizer)");
  for (std::size_t w = 0; w < windows.size(); ++w)
    std::printf("soak: energy window %zu: [%.1f, %.1f] J\n", w, windows[w].e_min, windows[w].e_max);
  std::printf("soak: second half: ROV within %.2f m of its path, boat within %.2f m of the ROV\n",
              late_auv, late_asv);
  if (failures > 0) {
    std::fprintf(stderr, "soak: %d check(s) failed\n", failures);
    return 1;
  }
  std::printf("soak: passed\n");
  return 0;
}
