// Work–precision of kelp's tether schemes and MoorDyn v2's (measured with v2.7.1,
// https://github.com/FloatingArrayDesign/MoorDyn) on the same line and motions, in one process
// through MoorDyn's C API. Built only against a MoorDyn installation the user provides
// (benchmarks/moordyn/CMakeLists.txt), like kelp-moordyn-side-by-side.
// Usage: kelp-moordyn-work-precision [--out work_precision.csv] [--reps 3] [--duration 10]
//        [--cases surge,heave,current] [--dir /tmp/moordyn-wp]
// benchmarks/moordyn/work_precision.py plots the CSV and computes the speed-up at equal accuracy.
//
// The line: kelp's benchmark line (20 m, d 8 mm, 0.07 kg/m, EA 1e5 N, Cdn 1.2, Cdt 0.008,
// Can 1, Cat 0, no internal damping) in 20 segments, node 0 fixed at (0, 0, 50) m and node 20
// at (10, 0, 55) m (NED), deep water (1025 kg/m³, g 9.80665). Cases, 10 s each, from MoorDyn's
// stationary initial state (its IC solver, 300 s at threshold 1e-9), the far end moved
// end + A (1 − cos ωt) e, A = 0.5 m, 0.2 Hz:
//   surge    e = x (horizontal, along the line's span), still water;
//   heave    e = z (vertical), A = 0.1 m (the benchmark line's heave: with 0.5 m the end segment
//            goes slack and snaps, and the runs do not converge to one answer as dt shrinks);
//   current  surge in a uniform 0.5 m/s current along +x.
// Every run starts from the same state: MoorDyn's after its IC solve, saved once per case
// (MoorDyn_SaveState) and loaded into every MoorDyn run (MoorDyn_Init_NoIC, MoorDyn_LoadState);
// kelp's nodes are set to it. kelp runs MoorDyn's line model (TetherParameters::line_model =
// LineModel::moordyn: the same physics, see benchmarks/results/tether.md), so that the errors
// below are the schemes' alone, with the far end's exact motion (position, velocity and
// acceleration; MoorDyn moves a coupled point linearly within each of its steps, so it is
// stepped once per dt).
//
// Measured per (code, scheme, dt), dt = 10 ms / k: the end-B tension (axial force of the
// segment at the moving end, EA max(0, l_s − l)/l) every 10 ms, its RMS difference from the
// reference relative to the reference's RMS, and the CPU time (thread) per simulated second,
// the minimum over `reps` repetitions. Reference: MoorDyn RK4 at dt = 10 ms / 320 (31.25 µs,
// 1/17 of its CFL-0.1 step); kelp's RK4 at the same dt is printed against it as a check.
// A run that goes non-finite or whose tension exceeds 1e6 N is reported as unstable.
// Also printed: kelp's own line model (LineModel::kelp) with BDF2 and RK4 against MoorDyn RK4
// at its CFL-0.1 dt in the surge case, the agreement criterion.
#include <fcntl.h>
#include <moordyn/MoorDyn2.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "kelp/core/constants.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/tether/integrators.hpp"
#include "kelp/tether/lumped_mass.hpp"
#include "line_input.hpp"

namespace kt = kelp::tether;
using kelp::Vector3;

namespace {

constexpr int kSegments = 20;
constexpr double kLength = 20.0, kEA = 1e5;
constexpr double kSample = 0.01;  // s

double thread_cpu() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

struct Case {
  std::string name;
  int axis;  // 0: x (surge), 2: z (heave)
  double amplitude, frequency, current;
  double omega() const { return 2 * kelp::pi * frequency; }
  Vector3<double> start() const { return {0, 0, 50}; }
  Vector3<double> end0() const { return {10, 0, 55}; }
  Vector3<double> end(double t) const {
    Vector3<double> e = end0();
    e(axis) += amplitude * (1 - std::cos(omega() * t));
    return e;
  }
  Vector3<double> end_velocity(double t) const {
    Vector3<double> v = Vector3<double>::Zero();
    v(axis) = amplitude * omega() * std::sin(omega() * t);
    return v;
  }
  Vector3<double> end_acceleration(double t) const {
    Vector3<double> a = Vector3<double>::Zero();
    a(axis) = amplitude * omega() * omega() * std::cos(omega() * t);
    return a;
  }
};

double tension(const Vector3<double>& p0, const Vector3<double>& p1) {
  const double l = kLength / kSegments;
  return kEA * std::max(0.0, (p1 - p0).norm() - l) / l;
}

struct Run {
  std::vector<double> tension;  // every kSample
  double cpu_per_s = 0;         // CPU seconds per simulated second (min over repetitions)
  bool stable = true;
};

// --------------------------------------------------------------------------------------------
// MoorDyn, its output silenced while it reads its input and initialises.
struct Quiet {
  int saved, devnull;
  Quiet() {
    std::fflush(stdout);
    saved = dup(1);
    devnull = open("/dev/null", O_WRONLY);
    dup2(devnull, 1);
  }
  ~Quiet() {
    std::fflush(stdout);
    dup2(saved, 1);
    close(saved);
    close(devnull);
  }
};

std::string write_input(const Case& c, const std::string& dir, const char* scheme, double dt) {
  const std::string sub = dir + "/" + c.name;
  std::system(("mkdir -p " + sub).c_str());
  char name[96];
  std::snprintf(name, sizeof name, "/line_%s_%.9g.txt", scheme, dt);
  const std::string path = sub + name;
  kelp_bench::LineInput input;
  input.title = std::string("kelp work-precision case ") + c.name;
  for (int i = 0; i < 3; ++i) {
    input.start[i] = c.start()(i);
    input.end[i] = c.end0()(i);
  }
  input.segments = kSegments;
  input.scheme = scheme;
  input.dt = dt;
  input.current = c.current;
  kelp_bench::write_moordyn_line(input, sub, path);
  return path;
}

void md_kinematics(const Case& c, double t, double* x, double* xd) {
  const Vector3<double> e = c.end(t), v = c.end_velocity(t);
  x[0] = e(0);
  x[1] = e(1);
  x[2] = -e(2);
  xd[0] = v(0);
  xd[1] = v(1);
  xd[2] = -v(2);
}

kelp::Matrix3X<double> md_nodes(MoorDynLine line) {
  kelp::Matrix3X<double> m(3, kSegments + 1);
  for (int i = 0; i <= kSegments; ++i) {
    double p[3];
    MoorDyn_GetLineNodePos(line, i, p);
    m.col(i) = Vector3<double>(p[0], p[1], -p[2]);
  }
  return m;
}

// MoorDyn's stationary initial state of a case, saved to `state_file`; its nodes (NED).
kelp::Matrix3X<double> md_initial_state(const Case& c, const std::string& dir,
                                        const std::string& state_file) {
  const std::string path = write_input(c, dir, "RK4", 1e-4);
  Quiet q;
  MoorDyn sys = MoorDyn_Create(path.c_str());
  if (!sys) throw std::runtime_error("MoorDyn_Create failed");
  MoorDyn_SetVerbosity(sys, 0);
  double x[3], xd[3];
  md_kinematics(c, 0, x, xd);
  if (MoorDyn_Init(sys, x, xd) != MOORDYN_SUCCESS) throw std::runtime_error("MoorDyn_Init failed");
  if (MoorDyn_SaveState(sys, state_file.c_str()) != MOORDYN_SUCCESS)
    throw std::runtime_error("MoorDyn_SaveState failed");
  const kelp::Matrix3X<double> x0 = md_nodes(MoorDyn_GetLine(sys, 1));
  MoorDyn_Close(sys);
  return x0;
}

Run run_moordyn(const Case& c, const std::string& dir, const std::string& state_file,
                const char* scheme, int k, double duration, int reps) {
  const double dt = kSample / k;
  const std::string path = write_input(c, dir, scheme, dt);
  const long samples = std::lround(duration / kSample);
  Run r;
  r.cpu_per_s = 1e300;
  for (int rep = 0; rep < reps && r.stable; ++rep) {
    MoorDyn sys;
    double x[3], xd[3], f[3];
    {
      Quiet q;
      sys = MoorDyn_Create(path.c_str());
      if (!sys) throw std::runtime_error("MoorDyn_Create failed");
      MoorDyn_SetVerbosity(sys, 0);
      md_kinematics(c, 0, x, xd);
      if (MoorDyn_Init_NoIC(sys, x, xd) != MOORDYN_SUCCESS)
        throw std::runtime_error("MoorDyn_Init_NoIC failed");
      if (MoorDyn_LoadState(sys, state_file.c_str()) != MOORDYN_SUCCESS)
        throw std::runtime_error("MoorDyn_LoadState failed");
    }
    MoorDynLine line = MoorDyn_GetLine(sys, 1);
    std::vector<double> ten;
    ten.reserve(samples);
    double t = 0, cpu = 0;
    for (long s = 1; s <= samples && r.stable; ++s) {
      const double c0 = thread_cpu();
      for (int j = 0; j < k; ++j) {
        md_kinematics(c, t, x, xd);
        double h = dt;
        if (MoorDyn_Step(sys, x, xd, f, &t, &h) != MOORDYN_SUCCESS) {
          r.stable = false;
          break;
        }
      }
      cpu += thread_cpu() - c0;
      double p0[3], p1[3];
      MoorDyn_GetLineNodePos(line, kSegments - 1, p0);
      MoorDyn_GetLineNodePos(line, kSegments, p1);
      const double tn =
          tension(Vector3<double>(p0[0], p0[1], p0[2]), Vector3<double>(p1[0], p1[1], p1[2]));
      if (!std::isfinite(tn) || tn > 1e6) r.stable = false;
      ten.push_back(tn);
    }
    MoorDyn_Close(sys);
    if (rep == 0) r.tension = ten;
    r.cpu_per_s = std::min(r.cpu_per_s, cpu / duration);
  }
  return r;
}

// --------------------------------------------------------------------------------------------
// kelp.
// linear_end: the far end moved as MoorDyn moves a coupled point, at constant velocity within
// each step (its position and velocity at the step's start, no acceleration), instead of exactly.
Run run_kelp(const Case& c, const kelp::Matrix3X<double>& x0, kt::LineModel lm,
             kt::Integrator integ, double dt, int k, double duration, int reps,
             bool linear_end = false) {
  kt::TetherParametersd p;
  p.segments = kSegments;
  p.line_model = lm;
  const kt::TetherModeld model(p);
  kt::TetherWorkspaced ws(model);
  kelp::environment::Environmentd env;
  if (c.current != 0) env.set_current(Vector3<double>(c.current, 0, 0));
  const long samples = std::lround(duration / kSample);
  Run r;
  r.cpu_per_s = 1e300;
  for (int rep = 0; rep < reps && r.stable; ++rep) {
    kt::TetherStated st(model);
    st.position = x0;
    st.velocity.setZero();
    st.time = 0;
    st.clear_history();
    std::vector<double> ten;
    ten.reserve(samples);
    double cpu = 0;
    try {
      for (long s = 1; s <= samples && r.stable; ++s) {
        const double c0 = thread_cpu();
        for (int j = 0; j < k; ++j) {
          const double t = st.time;
          kt::TetherBoundaryd b = kt::TetherBoundaryd::fixed(c.start(), c.end(t));
          b.end.velocity = c.end_velocity(t);
          b.end.acceleration = linear_end ? Vector3<double>::Zero().eval() : c.end_acceleration(t);
          kt::step(model, ws, env, st, b, dt, {integ});
        }
        cpu += thread_cpu() - c0;
        const double tn = tension(st.position.col(kSegments - 1), st.position.col(kSegments));
        if (!std::isfinite(tn) || tn > 1e6) r.stable = false;
        ten.push_back(tn);
      }
    } catch (const std::exception&) {
      r.stable = false;
    }
    if (rep == 0) r.tension = ten;
    r.cpu_per_s = std::min(r.cpu_per_s, cpu / duration);
  }
  return r;
}

double relative_rms(const std::vector<double>& a, const std::vector<double>& ref) {
  if (a.size() != ref.size()) return std::numeric_limits<double>::quiet_NaN();
  double e = 0, r = 0;
  for (size_t i = 0; i < ref.size(); ++i) {
    e += (a[i] - ref[i]) * (a[i] - ref[i]);
    r += ref[i] * ref[i];
  }
  return std::sqrt(e / r);
}

}  // namespace

int main(int argc, char** argv) {
  std::string out = "work_precision.csv", dir = "/tmp/moordyn-wp",
              case_list = "surge,heave,current";
  int reps = 3;
  double duration = 10.0;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--out")
      out = argv[i + 1];
    else if (a == "--reps")
      reps = std::atoi(argv[i + 1]);
    else if (a == "--duration")
      duration = std::atof(argv[i + 1]);
    else if (a == "--cases")
      case_list = argv[i + 1];
    else if (a == "--dir")
      dir = argv[i + 1];
    else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      return 2;
    }
  }
  std::system(("mkdir -p " + dir).c_str());
  const std::vector<Case> all = {
      {"surge", 0, 0.5, 0.2, 0.0}, {"heave", 2, 0.1, 0.2, 0.0}, {"current", 0, 0.5, 0.2, 0.5}};
  std::FILE* csv = std::fopen(out.c_str(), "w");
  if (!csv) throw std::runtime_error("cannot write " + out);
  std::fprintf(csv, "case,code,scheme,dt_s,cpu_s_per_sim_s,rel_rms_error,stable\n");
  const int ref_k = 320;
  for (const Case& c : all) {
    if (case_list.find(c.name) == std::string::npos) continue;
    const std::string state_file = dir + "/" + c.name + "_state.bin";
    const kelp::Matrix3X<double> x0 = md_initial_state(c, dir, state_file);
    const Run ref = run_moordyn(c, dir, state_file, "RK4", ref_k, duration, 1);
    if (!ref.stable) throw std::runtime_error("reference run unstable");
    const auto emit = [&](const char* code, const char* scheme, double dt, const Run& r) {
      const double e = r.stable ? relative_rms(r.tension, ref.tension) : NAN;
      std::fprintf(csv, "%s,%s,%s,%.9g,%.6g,%.6g,%d\n", c.name.c_str(), code, scheme, dt,
                   r.cpu_per_s, e, r.stable ? 1 : 0);
      std::fflush(csv);
      std::printf("%-8s %-8s %-15s dt %9.3f us  CPU/sim %.4g s/s (RTF %.4g)  error %.3e%s\n",
                  c.name.c_str(), code, scheme, dt * 1e6, r.cpu_per_s, 1 / r.cpu_per_s, e,
                  r.stable ? "" : "  UNSTABLE");
      std::fflush(stdout);
    };
    {
      const Run check = run_kelp(c, x0, kt::LineModel::moordyn, kt::Integrator::rk4,
                                 kSample / ref_k, ref_k, duration, 1);
      std::printf(
          "%-8s reference MoorDyn RK4 at %.3f us; kelp RK4 (MoorDyn's line) at the same dt "
          "against it: %.3e\n",
          c.name.c_str(), kSample / ref_k * 1e6, relative_rms(check.tension, ref.tension));
    }
    for (int k : {10, 12, 16, 20, 30, 40, 80, 160}) {
      emit("moordyn", "RK2", kSample / k,
           run_moordyn(c, dir, state_file, "RK2", k, duration, reps));
      emit("moordyn", "RK4", kSample / k,
           run_moordyn(c, dir, state_file, "RK4", k, duration, reps));
      emit("kelp", "RK4", kSample / k,
           run_kelp(c, x0, kt::LineModel::moordyn, kt::Integrator::rk4, kSample / k, k, duration,
                    reps));
    }
    for (int k : {1, 2, 4, 8, 16, 32, 64}) {
      emit("kelp", "implicit_euler", kSample / k,
           run_kelp(c, x0, kt::LineModel::moordyn, kt::Integrator::implicit_euler, kSample / k, k,
                    duration, reps));
      emit("kelp", "BDF2", kSample / k,
           run_kelp(c, x0, kt::LineModel::moordyn, kt::Integrator::bdf2, kSample / k, k, duration,
                    reps));
    }
    if (c.name == "surge") {
      // kelp's own line (LineModel::kelp) against MoorDyn RK4 at its CFL-0.1 dt (k = 19:
      // 526 µs; MoorDyn's own CFL step of this line is 525.7 µs), with the far end's exact
      // motion and with MoorDyn's (linear within each step): the first includes MoorDyn's
      // error from its end motion, the second compares the two codes' line dynamics alone.
      const Run md = run_moordyn(c, dir, state_file, "RK4", 19, duration, 1);
      for (kt::Integrator integ : {kt::Integrator::bdf2, kt::Integrator::rk4})
        for (int k : {1, 4, 19})
          for (bool linear_end : {false, true}) {
            if (integ == kt::Integrator::rk4 ? k != 19 : linear_end) continue;
            for (kt::LineModel lm : {kt::LineModel::kelp, kt::LineModel::moordyn}) {
              const Run kr = run_kelp(c, x0, lm, integ, kSample / k, k, duration, 1, linear_end);
              std::printf(
                  "surge    kelp %s line, %s at %.3f ms, %s end motion, against MoorDyn RK4 at "
                  "0.526 ms: end-B tension RMS difference %.3e of its RMS\n",
                  lm == kt::LineModel::kelp ? "kelp's" : "MoorDyn's",
                  integ == kt::Integrator::bdf2 ? "BDF2" : "RK4", kSample / k * 1e3,
                  linear_end ? "MoorDyn's" : "exact", relative_rms(kr.tension, md.tension));
            }
          }
    }
  }
  std::fclose(csv);
  std::printf("wrote %s\n", out.c_str());
  return 0;
}
