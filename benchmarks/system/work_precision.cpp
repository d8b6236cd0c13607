// kelp-system-work-precision: work–precision of the coupled system's schemes (issue "speed at
// equal accuracy", item 4): the error of the tether's pull on the ROV against a converged
// reference versus the CPU time per simulated second, for each tether integrator and coupling
// at several system steps. kelp alone (no other code simulates the vehicles and the line
// together); benchmarks/system/work_precision.py plots the CSV and names the cheapest scheme at
// a given accuracy.
//
// Usage: kelp-system-work-precision [--out system_work_precision.csv] [--reps 3]
//        [--duration 20] [--cases pair,ship_tms_rov]
// The figure of record (benchmarks/README.md): --cases pair --duration 20, then
// --cases ship_tms_rov --duration 10 (its reference costs ~22 CPU s per simulated second).
//
// Cases, both in the paper's rough sea (kelp::system::presets::environment(Sea::rough): 64 wave
// components, wind, current), each vehicle holding a constant thrust, from the fleet's initial
// state (the lines' static shape):
//   pair          the paper's pair as a fleet (system::fleet_of: the same step as system::step,
//                 bit for bit): BlueBoat, BlueROV2 Heavy 5 m down, a 10 m ROV tether in 20
//                 segments; boat 5 N, ROV 10 N surge;
//   ship_tms_rov  bench_system's BM_ShipTmsRovStep: a ship's sheave (an anchor at the surface),
//                 a 60 m armoured umbilical (60 segments, EA 3 MN) to a 400 kg TMS, a 30 m ROV
//                 tether (60 segments) on the TMS's winch to a BlueROV2 Heavy; ROV 10 N surge.
// Schemes (FleetParameters): the tether integrator (bdf2, the default; implicit_euler; rk4 at
// its stable step, estimate_stable_dt) and the coupling (0 or 1 corrector passes), at system
// steps dt = 10, 5, 2.5, 1.25, 0.625 ms (the implicit tethers take one sub-step per system step,
// max_tether_dt = dt; the explicit one sub-steps within it at 0.9 of its stable step).
// Measured per run: the force of the ROV's tether on the ROV (FleetReport::force_at_end of the
// tether that ends on the ROV, each step's mean) averaged over every 10 ms, the magnitude's RMS
// difference from the reference's relative to the reference's RMS; the largest distance of the ROV
// from its reference position at those samples [m]; the CPU time of the thread per simulated
// second, the minimum over `reps` repetitions (one for a run of more than 5 CPU s); the tether's
// Newton corrections per system step. Reference: rk4 at a quarter of its stable step with one
// corrector pass at dt = 10 ms / 64; the same at 10 ms / 32 is printed against it (the reference's
// own error).
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "kelp/system/fleet.hpp"
#include "kelp/system/presets.hpp"
#include "kelp/tether/stable_dt.hpp"
#include "ship_tms_rov.hpp"

namespace ks = kelp::system;
namespace kt = kelp::tether;
namespace kv = kelp::vehicle;
using kelp::Vector3;

namespace {

constexpr double kSample = 0.01;  // s

double thread_cpu() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

/// A fleet configuration: its parameters, start poses and thrusts.
struct Case {
  std::string name;
  ks::FleetParametersd params;
  kelp::environment::Environmentd env;
  std::vector<kv::VehicleStated> vehicles;
  std::vector<Vector3<double>> point_masses;
  std::vector<kelp::Vector6<double>> tau;  // per vehicle, constant
  int rov = 0;                             // the ROV's vehicle index
  int rov_tether = 0;                      // the tether that ends on it
};

Case pair_case() {
  const ks::presets::PaperWorld<double> w(10.0, ks::presets::Sea::rough);
  Case c;
  c.name = "pair";
  c.params = ks::fleet_of(w.model.parameters());
  c.env = w.model.environment();
  c.vehicles = {w.state.asv, w.state.auv};
  c.tau = {kelp::Vector6<double>::Zero(), kelp::Vector6<double>::Zero()};
  c.tau[0](0) = 5;
  c.tau[1](0) = 10;
  c.rov = 1;
  c.rov_tether = 0;
  return c;
}

Case ship_tms_rov_case() {
  Case c;
  c.name = "ship_tms_rov";
  c.params = kelp_bench::ship_tms_rov_parameters();
  c.env = ks::presets::environment<double>(ks::presets::Sea::rough);
  c.vehicles.resize(1);
  c.vehicles[0].position = kelp_bench::ship_tms_rov_rov_start();
  c.point_masses = {kelp_bench::ship_tms_rov_tms_start()};
  c.tau = {kelp::Vector6<double>::Zero()};
  c.tau[0](0) = 10;
  c.rov = 0;
  c.rov_tether = 1;
  return c;
}

struct Scheme {
  std::string name;
  kt::Integrator integrator;
  int corrections;
  double explicit_fraction;  // > 0: explicit, sub-steps of this fraction of the stable step
};

/// One run's samples: the force on the ROV and its position every kSample.
struct Series {
  std::vector<Vector3<double>> force, position;
  double cpu_per_s = 0, newton_per_step = 0, tether_dt = 0;
  bool finite = true;
};

/// Runs `c` with `s` at system step dt for `duration` simulated seconds.
Series run(const Case& c, const Scheme& s, double dt, double duration) {
  ks::FleetParametersd p = c.params;
  p.tether_integrator = s.integrator;
  p.coupling_corrections = s.corrections;
  p.explicit_fallback = false;
  p.max_tether_dt = dt;
  if (s.explicit_fraction > 0) {
    // The explicit scheme's sub-step: the given fraction of the stiffest line's stable step.
    const ks::FleetModeld probe(c.params, c.env);
    double stable = dt;
    for (int k = 0; k < probe.tether_count(); ++k)
      stable = std::min(
          stable, kt::estimate_stable_dt(probe.tether(k), s.integrator, c.env.water_density()));
    p.max_tether_dt = std::min(dt, s.explicit_fraction * stable);
  }
  const ks::FleetModeld model(p, c.env);
  ks::FleetWorkspaced ws(model);
  ks::FleetStated state = ks::initial_state(model, ws, c.vehicles, c.point_masses);
  ks::FleetInputsd in(model);
  for (std::size_t i = 0; i < c.tau.size(); ++i) in.vehicles[i].tau = c.tau[i];
  const long steps_per_sample = std::lround(kSample / dt);
  if (std::abs(double(steps_per_sample) * dt - kSample) > 1e-12)
    throw std::runtime_error("dt must divide the sample period");
  const long samples = std::lround(duration / kSample);
  Series out;
  out.tether_dt = p.max_tether_dt;
  out.force.reserve(std::size_t(samples));
  out.position.reserve(std::size_t(samples));
  double newton = 0;
  const double t0 = thread_cpu();
  for (long k = 0; k < samples && out.finite; ++k) {
    // The mean force over the sample period: the sum of the steps' impulses (each step reports
    // its mean force), the same quantity whatever dt divides the period.
    Vector3<double> f = Vector3<double>::Zero();
    for (long j = 0; j < steps_per_sample; ++j) {
      try {
        const ks::FleetReportd& r = ks::step(model, ws, state, in, dt);
        newton += r.tether.newton_iterations;
        f += r.force_at_end[std::size_t(c.rov_tether)] * (dt / kSample);
      } catch (const kelp::error&) {
        out.finite = false;
        break;
      }
    }
    out.force.push_back(f);
    out.position.push_back(state.vehicles[std::size_t(c.rov)].position);
    out.finite = out.finite && f.allFinite() && f.norm() < 1e7;
  }
  out.cpu_per_s = (thread_cpu() - t0) / duration;
  out.newton_per_step = newton / (double(samples) * double(steps_per_sample));
  return out;
}

/// Relative RMS difference of the force magnitudes, and the largest position difference [m].
void errors(const Series& a, const Series& ref, double& force_rel, double& position_max) {
  double d2 = 0, r2 = 0;
  position_max = 0;
  for (std::size_t k = 0; k < ref.force.size(); ++k) {
    const double fr = ref.force[k].norm(), fa = a.force[k].norm();
    d2 += (fa - fr) * (fa - fr);
    r2 += fr * fr;
    position_max = std::max(position_max, (a.position[k] - ref.position[k]).norm());
  }
  force_rel = std::sqrt(d2 / r2);
}

}  // namespace

int main(int argc, char** argv) try {
  std::string out_path = "system_work_precision.csv", cases_arg = "pair,ship_tms_rov";
  int reps = 3;
  double duration = 20;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
      return argv[++i];
    };
    if (a == "--out")
      out_path = value();
    else if (a == "--reps")
      reps = std::stoi(value());
    else if (a == "--duration")
      duration = std::stod(value());
    else if (a == "--cases")
      cases_arg = value();
    else {
      std::fprintf(stderr,
                   "usage: kelp-system-work-precision [--out FILE] [--reps N] [--duration S] "
                   "[--cases pair,ship_tms_rov]\n");
      return 2;
    }
  }
  if (reps < 1 || !(duration >= kSample)) {
    std::fprintf(stderr, "kelp-system-work-precision: --reps >= 1 and --duration >= 0.01\n");
    return 2;
  }
  std::vector<Case> cases;
  if (cases_arg.find("pair") != std::string::npos) cases.push_back(pair_case());
  if (cases_arg.find("ship_tms_rov") != std::string::npos) cases.push_back(ship_tms_rov_case());
  if (cases.empty()) throw std::runtime_error("--cases names neither pair nor ship_tms_rov");
  const std::vector<Scheme> schemes = {
      {"bdf2", kt::Integrator::bdf2, 0, 0},
      {"bdf2_corrected", kt::Integrator::bdf2, 1, 0},
      {"implicit_euler", kt::Integrator::implicit_euler, 0, 0},
      {"rk4", kt::Integrator::rk4, 0, 0.9},
      {"rk4_corrected", kt::Integrator::rk4, 1, 0.9},
  };
  const std::vector<double> steps = {0.01, 0.005, 0.0025, 0.00125, 0.000625};
  std::ofstream csv(out_path);
  if (!csv) {
    std::fprintf(stderr, "kelp-system-work-precision: cannot write %s\n", out_path.c_str());
    return 1;
  }
  csv << "case,scheme,dt,tether_dt,cpu_per_simulated_s,force_rel_rms,position_max_m,"
         "newton_per_step,stable\n";
  for (const Case& c : cases) {
    const Scheme reference{"reference", kt::Integrator::rk4, 1, 0.25};
    const Series ref = run(c, reference, kSample / 64, duration);
    const Series check = run(c, reference, kSample / 32, duration);
    if (!ref.finite || !check.finite) {
      std::fprintf(stderr, "%s: the reference run did not stay finite\n", c.name.c_str());
      return 1;
    }
    double fe = 0, pe = 0;
    errors(check, ref, fe, pe);
    std::printf(
        "%s: reference rk4 at %.3g s (tether %.3g s), %.2f CPU s per simulated s; at "
        "twice its step: force %.2e relative RMS, position %.2e m\n",
        c.name.c_str(), kSample / 64, ref.tether_dt, ref.cpu_per_s, fe, pe);
    csv << c.name << ",reference_check," << kSample / 32 << ',' << check.tether_dt << ','
        << check.cpu_per_s << ',' << fe << ',' << pe << ",0,1\n";
    for (const Scheme& s : schemes)
      for (const double dt : steps) {
        Series best;
        for (int r = 0; r < reps; ++r) {
          Series x = run(c, s, dt, duration);
          if (r == 0 || x.cpu_per_s < best.cpu_per_s) best = std::move(x);
          // A run of more than 5 CPU s is timed once: its noise is small against its cost.
          if (!best.finite || best.cpu_per_s * duration > 5.0) break;
        }
        double f_err = NAN, p_err = NAN;
        if (best.finite && best.force.size() == ref.force.size()) errors(best, ref, f_err, p_err);
        std::printf(
            "%-13s %-15s dt %7.5f s (tether %.2e s): %8.4f CPU s/s  force %.2e  "
            "position %.2e m  Newton %.2f%s\n",
            c.name.c_str(), s.name.c_str(), dt, best.tether_dt, best.cpu_per_s, f_err, p_err,
            best.newton_per_step, best.finite ? "" : "  UNSTABLE");
        std::fflush(stdout);
        csv << c.name << ',' << s.name << ',' << dt << ',' << best.tether_dt << ','
            << best.cpu_per_s << ',' << f_err << ',' << p_err << ',' << best.newton_per_step << ','
            << (best.finite ? 1 : 0) << '\n';
      }
  }
  std::printf("wrote %s\n", out_path.c_str());
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "kelp-system-work-precision: %s\n", e.what());
  return 2;
}
