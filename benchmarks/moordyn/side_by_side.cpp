// Side-by-side timing of kelp's lumped-mass tether and MoorDyn v2 (measured with v2.7.1,
// https://github.com/FloatingArrayDesign/MoorDyn) in one process, through MoorDyn's C API.
// Built only against a MoorDyn installation the user provides (benchmarks/moordyn/CMakeLists.txt).
// Usage: kelp-moordyn-side-by-side [--sizes 20,50,100,200] [--rounds 5] [--min-time 0.3]
//        [--check-time 5] [--no-check|--no-timing|--no-validation] [--dir /tmp/moordyn-bench]
//        [--write-reference tests/tether/moordyn_reference.hpp]
//
// First the validation cases of tests/tether/moordyn_cases.hpp (surge, snap loads, static shape
// in a current): kelp's default line, the same with compressive_damping, and
// TetherParameters::line_model = LineModel::moordyn against MoorDyn (benchmarks/results/tether.md,
// "kelp's line and MoorDyn's"); --write-reference stores MoorDyn's results for
// tests/tether/test_moordyn_reference.cpp.
//
// The benchmark line of kelp (benchmarks/tether/bench_tether.cpp): 20 m, d 8 mm, 0.07 kg/m,
// EA 1e5 N, Cdn 1.2, Cdt 0.008, Can 1, Cat 0, no internal damping, no bending, ends 10 m apart
// horizontally and 5 m vertically in still seawater (1025 kg/m3, g 9.80665, no seabed in reach),
// started from static equilibrium, far end heaving 0.1 m at 0.2 Hz.
// kelp works in NED (z down), MoorDyn in z up: kelp (x, y, z) <-> MoorDyn (x, y, -z).
//
// Common dt per N: MoorDyn's CFL 0.1 dt (0.1 x its segment natural period 2 pi sqrt(m l / EA)),
// rounded down to a multiple of 2^-24 s so that sums of steps are exact in binary.
//
// Per N and round r (r = 0..R-1), in this order: MoorDyn RK4 (one MoorDyn_Step per dtM),
// MoorDyn RK4 (one MoorDyn_Step per ~10 ms coupling interval, K internal dtM steps), kelp RK4
// at dt, kelp bare compute_forces (without and with the Jacobian terms), kelp BDF2 at 10 ms (to
// tolerance with the default simplified Newton / W-method, the same on LineModel::moordyn, to
// tolerance with Newton's method, then one unchecked correction per step), and kelp's force
// evaluation and BDF2 step again on the force passes' baseline build
// (kelp::tether::detail::wide_force_passes off: SSE2 where the AVX2 build is dispatched). Each
// measurement runs >= min_time of wall clock (steady_clock); thread CPU time is recorded as well.
#include <fcntl.h>
#include <moordyn/MoorDyn2.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "../../tests/tether/moordyn_cases.hpp"
#include "../tether/benchmark_line.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/integrators.hpp"
#include "kelp/tether/lumped_mass.hpp"
#include "line_input.hpp"

namespace kt = kelp::tether;
using kelp::Vector3;

namespace {

// The far end's heave in NED (z down), shared with bench_tether.
double heave_z(double t) { return kelp_bench::Heave::z(t); }
double heave_vz(double t) { return kelp_bench::Heave::vz(t); }

double thread_cpu() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

struct Timing {
  double wall = 0, cpu = 0;  // seconds
  long iters = 0;
};

// Runs body(k) for batches of `batch` calls until min_time of wall clock has passed.
template <typename F>
Timing run_for(double min_time, long batch, F&& body) {
  using clk = std::chrono::steady_clock;
  Timing t;
  const auto w0 = clk::now();
  const double c0 = thread_cpu();
  double el = 0;
  do {
    for (long k = 0; k < batch; ++k) body();
    t.iters += batch;
    el = std::chrono::duration<double>(clk::now() - w0).count();
  } while (el < min_time);
  t.wall = el;
  t.cpu = thread_cpu() - c0;
  return t;
}

// ---------------------------------------------------------------------------------------------
// The benchmark line in kelp, with a step at the current time.
struct Kelp : kelp_bench::BenchmarkLine {
  using BenchmarkLine::BenchmarkLine;
  kt::StepReportd step(double dt, kt::Integrator integ, const kt::ImplicitOptionsd& o = {}) {
    return kt::step(model, ws, env, state, boundary(state.time), dt, {integ, o});
  }
  // A step with the far end moving as MoorDyn moves a coupled point: linearly within the step,
  // at the velocity of its start (no acceleration).
  void step_linear_end(double dt, kt::Integrator integ) {
    kt::TetherBoundaryd linear = boundary(state.time);
    linear.end.acceleration.setZero();
    kt::step(model, ws, env, state, linear, dt, {integ});
  }
};

// BDF2 with Newton's method: the matrix formed at every iteration (kt::NewtonMethod::exact).
kt::ImplicitOptionsd exact_newton() {
  kt::ImplicitOptionsd o;
  o.newton = kt::NewtonMethod::exact;
  return o;
}

// BDF2 with one unchecked Newton correction per step (linearly implicit; see
// kt::ImplicitOptions::check_convergence).
kt::ImplicitOptionsd one_newton() {
  kt::ImplicitOptionsd o;
  o.max_iterations = 1;
  o.check_convergence = false;
  return o;
}

// ---------------------------------------------------------------------------------------------
struct Md {
  MoorDyn sys = nullptr;
  MoorDynLine line = nullptr;
  int n;
  double t = 0;
  double x[3], xd[3], f[3];
  Md(int n_, double dtM, const std::string& dir, bool precise_ic = false,
     const char* scheme = "RK4")
      : n(n_) {
    const std::string path = dir + "/line_" + std::to_string(n) + "_" + scheme + ".txt";
    {
      std::ofstream o(path);
      char dts[64];
      std::snprintf(dts, sizeof dts, "%.17g", dtM);
      o << "--------------------- MoorDyn Input File ------------------------------------\n"
           "kelp benchmark line\n"
           "----------------------- LINE TYPES ------------------------------------------\n"
           "TypeName   Diam    Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    "
           "CaAx\n"
           "(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     "
           "(-)\n"
           "tether     0.008   0.07       1.0e5      0.0         0.0        1.2    1.0    0.008   "
           "0.0\n"
           "---------------------- POINT PROPERTIES --------------------------------\n"
           "ID    Type      X       Y       Z       Mass   Volume  CdA    Ca\n"
           "(#)   (-)       (m)     (m)     (m)     (kg)   (mˆ3)   (m^2)  (-)\n"
           "1     Fixed     0.0     0.0     0.0     0      0       0      0\n"
           "2     Coupled   10.0    0.0     -5.0    0      0       0      0\n"
           "---------------------- LINES ----------------------------------------\n"
           "ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs\n"
           "(#)   (name)     (#)      (#)       (m)       (-)     (-)\n"
           "1     tether     1        2         20.0      "
        << n
        << "      -\n"
           "---------------------- OPTIONS -----------------------------------------\n"
           "0             writeLog\n"
        << scheme << "           tScheme\n"
        << dts
        << "  dtM\n"
           "1025.0        WtrDnsty\n"
           "9.80665       g\n"
           "1000.0        WtrDpth\n"
           "3.0e6         kBot\n"
           "3.0e5         cBot\n"
        << (precise_ic ? "0.5 dtIC\n200.0 TmaxIC\n1e-9 threshIC\n"
                       : "0.5 dtIC\n20.0 TmaxIC\n1e-3 threshIC\n")
        << "1             disableOutput\n"
           "1             disableOutTime\n"
           "------------------------- need this line --------------------------------------\n";
    }
    // MoorDyn logs to stdout while it reads the file and initialises: silence it
    std::fflush(stdout);
    const int saved = dup(1), devnull = open("/dev/null", O_WRONLY);
    dup2(devnull, 1);
    sys = MoorDyn_Create(path.c_str());
    if (!sys) throw std::runtime_error("MoorDyn_Create failed");
    MoorDyn_SetVerbosity(sys, 0);  // MOORDYN_NO_OUTPUT
    unsigned int ndof = 0;
    MoorDyn_NCoupledDOF(sys, &ndof);
    if (ndof != 3) throw std::runtime_error("expected 3 coupled DOF");
    kin(0.0);
    if (MoorDyn_Init(sys, x, xd) != MOORDYN_SUCCESS)
      throw std::runtime_error("MoorDyn_Init failed");
    std::fflush(stdout);
    dup2(saved, 1);
    close(saved);
    close(devnull);
    line = MoorDyn_GetLine(sys, 1);
    double got = 0;
    MoorDyn_GetDt(sys, &got);
    if (got != dtM) std::fprintf(stderr, "warning: MoorDyn dt %.17g != %.17g\n", got, dtM);
  }
  ~Md() {
    if (sys) MoorDyn_Close(sys);
  }
  void kin(double tt) {
    x[0] = 10;
    x[1] = 0;
    x[2] = -heave_z(tt);
    xd[0] = xd[1] = 0;
    xd[2] = -heave_vz(tt);
  }
  // One coupling interval of length h (MoorDyn runs ceil(h / dtM) internal steps).
  void step(double h) {
    kin(t);
    double dt = h;
    if (MoorDyn_Step(sys, x, xd, f, &t, &dt) != MOORDYN_SUCCESS)
      throw std::runtime_error("MoorDyn_Step failed");
  }
  Vector3<double> node_vel_ned(int i) const {
    double p[3];
    MoorDyn_GetLineNodeVel(line, i, p);
    return {p[0], p[1], -p[2]};
  }
  Vector3<double> node_ned(int i) const {
    double p[3];
    MoorDyn_GetLineNodePos(line, i, p);
    return {p[0], p[1], -p[2]};
  }
};

double segment_tension(const Vector3<double>& p0, const Vector3<double>& p1, double l) {
  const double s = (p1 - p0).norm();
  return std::max(0.0, 1e5 * (s - l) / l);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}
double minv(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }
double maxv(const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); }

// Agreement check.
// (1) statics solved separately by each code (MoorDyn's stationary IC solver, 200 s, threshIC
//     1e-9; kelp's static_initial_state): max node distance, mid node, mid-segment tension.
// (2) dynamics from one initial state: kelp's nodes are set to MoorDyn's initial nodes, then both
//     run T seconds of heave, RK4 at the common dt (MoorDyn one Step per dtM), and kelp BDF2 at
//     K dt ~ 10 ms alongside. Compared: node distance, mid node, the axial force of segment N-2
//     (the last one between two free nodes; the kinematic end node is left out because MoorDyn
//     moves it linearly within a coupling step, kelp quadratically, and with EA/l = 5e3..1e6 N/m
//     the force of the end segment would mostly measure that).
void agreement(int n, double dt, const std::string& dir, double T) {
  Kelp k(n);
  Md m(n, dt, dir, true);
  const double l = 20.0 / n;
  auto ten = [&](const auto& pos, int s) { return segment_tension(pos(s), pos(s + 1), l); };
  auto kp = [&](const Kelp& kk) {
    return [&kk](int i) -> Vector3<double> { return kk.state.position.col(i); };
  };
  auto mp = [&](int i) { return m.node_ned(i); };
  auto compare = [&](const char* what, const Kelp& kk, int seg) {
    double dmax = 0;
    for (int i = 0; i <= n; ++i)
      dmax = std::max(dmax, (m.node_ned(i) - kk.state.position.col(i)).norm());
    const Vector3<double> km = kk.state.position.col(n / 2), mm = m.node_ned(n / 2);
    const double tk = ten(kp(kk), seg), tm = ten(mp, seg);
    std::printf(
        "  N=%3d %-24s max node distance %.2e m; mid node (x,z) kelp (%.6f, %.6f) MoorDyn "
        "(%.6f, %.6f); segment %d axial force kelp %.6f N MoorDyn %.6f N, rel diff %.2e\n",
        n, what, dmax, km.x(), km.z(), mm.x(), mm.z(), seg, tk, tm, (tm - tk) / tk);
  };
  compare("statics (own solvers)", k, n / 2);
  // same initial state for the dynamics
  for (int i = 0; i <= n; ++i) {
    k.state.position.col(i) = m.node_ned(i);
    k.state.velocity.col(i) = m.node_vel_ned(i);
  }
  k.state.clear_history();
  Kelp kb(n), k1(n), kx(n), km(n, 0.0, kt::LineModel::moordyn);
  for (Kelp* kk : {&kb, &k1, &kx, &km}) {
    kk->state.position = k.state.position;
    kk->state.velocity = k.state.velocity;
    kk->state.clear_history();
  }
  double se1 = 0, sex = 0, sbx = 0, sem = 0, dmax_m = 0;
  kt::StepReportd rb, rx;
  const long K = std::lround(0.01 / dt);
  const long steps = std::lround(T / (K * dt)) * K;
  const int seg = n - 2;
  double se = 0, sref = 0, se2 = 0, sref2 = 0, dmax_run = 0;
  for (long s = 1; s <= steps; ++s) {
    m.step(dt);
    k.step(dt, kt::Integrator::rk4);
    const double tk = ten(kp(k), seg), tm = ten(mp, seg);
    se += (tm - tk) * (tm - tk);
    sref += tm * tm;
    for (int i = 0; i <= n; ++i)
      dmax_run = std::max(dmax_run, (m.node_ned(i) - k.state.position.col(i)).norm());
    km.step_linear_end(dt, kt::Integrator::rk4);
    const double tkm = ten(kp(km), seg);
    sem += (tm - tkm) * (tm - tkm);
    for (int i = 0; i <= n; ++i)
      dmax_m = std::max(dmax_m, (m.node_ned(i) - km.state.position.col(i)).norm());
    if (s % K == 0) {
      rb += kb.step(K * dt, kt::Integrator::bdf2);
      rx += kx.step(K * dt, kt::Integrator::bdf2, exact_newton());
      k1.step(K * dt, kt::Integrator::bdf2, one_newton());
      const double tb = ten(kp(kb), seg), t1 = ten(kp(k1), seg), tx = ten(kp(kx), seg);
      se2 += (tm - tb) * (tm - tb);
      se1 += (tm - t1) * (tm - t1);
      sex += (tm - tx) * (tm - tx);
      sbx += (tx - tb) * (tx - tb);
      sref2 += tm * tm;
    }
  }
  char what[64];
  std::snprintf(what, sizeof what, "RK4 t=%.2fs", k.state.time);
  compare(what, k, seg);
  std::printf(
      "  N=%3d RK4 vs RK4 over %.2f s: RMS segment-%d force difference %.2e of RMS force; "
      "largest node distance %.2e m; clocks kelp %.9f MoorDyn %.9f\n",
      n, k.state.time, seg, std::sqrt(se / sref), dmax_run, k.state.time, m.t);
  std::printf(
      "  N=%3d RK4 vs RK4, kelp with LineModel::moordyn and MoorDyn's end motion (linear within "
      "a step): RMS segment-%d force difference %.2e of RMS force; largest node distance %.2e m\n",
      n, seg, std::sqrt(sem / sref), dmax_m);
  std::snprintf(what, sizeof what, "BDF2 %.2fms t=%.2fs", K * dt * 1e3, kb.state.time);
  compare(what, kb, seg);
  std::printf(
      "  N=%3d kelp BDF2 at %.3f ms vs MoorDyn RK4 at dt, sampled every %ld steps: RMS "
      "segment-%d force difference %.2e of RMS force\n",
      n, K * dt * 1e3, K, seg, std::sqrt(se2 / sref2));
  std::printf(
      "  N=%3d kelp BDF2 Newton's method (exact) at %.3f ms vs MoorDyn RK4 at dt: RMS segment-%d "
      "force difference %.2e of RMS force; simplified vs exact %.2e\n",
      n, K * dt * 1e3, seg, std::sqrt(sex / sref2), std::sqrt(sbx / sref2));
  const auto per_step = [](const kt::StepReportd& r) {
    const double st = r.substeps;
    char b[160];
    std::snprintf(b, sizeof b,
                  "%.3f Newton corrections, %.3f force evaluations, %.3f factorisations, %.3f "
                  "reuses per step",
                  r.newton_iterations / st, r.force_evaluations / st, r.factorisations / st,
                  r.reused_factorisations / st);
    return std::string(b);
  };
  std::printf("  N=%3d kelp BDF2 simplified: %s\n", n, per_step(rb).c_str());
  std::printf("  N=%3d kelp BDF2 exact:      %s\n", n, per_step(rx).c_str());
  std::printf(
      "  N=%3d kelp BDF2 one Newton correction at %.3f ms vs MoorDyn RK4 at dt: RMS segment-%d "
      "force difference %.2e of RMS force\n",
      n, K * dt * 1e3, seg, std::sqrt(se1 / sref2));
  // MoorDyn RK4 and kelp RK4 at kelp's own RK4 dt (estimate_stable_dt, 0.8 of the Gershgorin
  // bound), from the same start: is MoorDyn stable there, and do the two still agree?
  {
    Kelp k2(n);
    const double dtk =
        kt::estimate_stable_dt(k2.model, kt::Integrator::rk4, k2.env.water_density());
    const double q = std::ldexp(1.0, -24);
    const double dto = std::floor(dtk / q) * q;
    Md m3(n, dto, dir, true);
    for (int i = 0; i <= n; ++i) {
      k2.state.position.col(i) = m3.node_ned(i);
      k2.state.velocity.col(i) = m3.node_vel_ned(i);
    }
    k2.state.clear_history();
    bool ok = true;
    double e = 0, r = 0;
    const long st = std::lround(T / dto);
    for (long s = 0; s < st && ok; ++s) {
      try {
        m3.step(dto);
      } catch (const std::exception&) {
        ok = false;
        break;
      }
      k2.step(dto, kt::Integrator::rk4);
      const double tm = segment_tension(m3.node_ned(seg), m3.node_ned(seg + 1), l);
      const double tk =
          segment_tension(k2.state.position.col(seg), k2.state.position.col(seg + 1), l);
      if (!std::isfinite(tm) || tm > 1e6) ok = false;
      e += (tm - tk) * (tm - tk);
      r += tm * tm;
    }
    std::printf(
        "  N=%3d at kelp's RK4 dt %.3f us (MoorDyn CFL %.3f): MoorDyn RK4 %s over %.2f s; RMS "
        "segment-%d force difference %.2e\n",
        n, dto * 1e6, dto / dt * 0.1, ok ? "stable" : "FAILED", T, seg, std::sqrt(e / r));
  }
}

// ---------------------------------------------------------------------------------------------
// The validation cases of tests/tether/moordyn_cases.hpp: MoorDyn's run of a case and the table
// of kelp's two line models against it; `--write-reference` stores MoorDyn's results for the
// tests (tests/tether/moordyn_reference.hpp).
namespace mc = moordyn_cases;

// MoorDyn's run of a case: its initial nodes (NED), and either its samples (a dynamic case) or
// its nodes after 300 s with the ends held (the static case in a current: MoorDyn's stationary
// solver leaves the line metres short of its equilibrium in this current, and 300 s of dynamics
// settle it to 1e-12 m per 20 s).
struct MdRun {
  kelp::Matrix3X<double> x0, x_end;
  mc::Series series;
};

MdRun run_moordyn(const mc::Case& c, const std::string& dir) {
  const int n = c.segments;
  const std::string sub = dir + "/" + c.name;
  std::system(("mkdir -p " + sub).c_str());
  const std::string path = sub + "/line.txt";
  const double dt = c.dt();
  kelp_bench::LineInput input;
  input.title = std::string("kelp validation case ") + c.name;
  input.internal_damping = c.internal_damping;
  for (int i = 0; i < 3; ++i) {
    input.start[i] = c.start[i];
    input.end[i] = c.end[i];
  }
  input.segments = n;
  input.dt = dt;
  input.current = c.current;
  kelp_bench::write_moordyn_line(input, sub, path);
  std::fflush(stdout);
  const int saved = dup(1), devnull = open("/dev/null", O_WRONLY);
  dup2(devnull, 1);
  MoorDyn sys = MoorDyn_Create(path.c_str());
  if (!sys) throw std::runtime_error("MoorDyn_Create failed");
  MoorDyn_SetVerbosity(sys, 0);
  double x[3] = {c.end_x(0), c.end[1], -c.end[2]}, xd[3] = {c.end_vx(0), 0, 0}, f[3];
  if (MoorDyn_Init(sys, x, xd) != MOORDYN_SUCCESS) throw std::runtime_error("MoorDyn_Init failed");
  std::fflush(stdout);
  dup2(saved, 1);
  close(saved);
  close(devnull);
  MoorDynLine line = MoorDyn_GetLine(sys, 1);
  auto nodes = [&] {
    kelp::Matrix3X<double> m(3, n + 1);
    for (int i = 0; i <= n; ++i) {
      double p[3];
      MoorDyn_GetLineNodePos(line, i, p);
      m.col(i) = kelp::Vector3<double>(p[0], p[1], -p[2]);
    }
    return m;
  };
  auto velocities = [&] {
    kelp::Matrix3X<double> m(3, n + 1);
    for (int i = 0; i <= n; ++i) {
      double p[3];
      MoorDyn_GetLineNodeVel(line, i, p);
      m.col(i) = kelp::Vector3<double>(p[0], p[1], -p[2]);
    }
    return m;
  };
  MdRun r;
  r.x0 = nodes();
  double t = 0;
  const long steps = c.duration > 0 ? c.steps() : std::lround(300.0 / dt);
  kelp::tether::TetherStated st;
  for (long k = 1; k <= steps; ++k) {
    x[0] = c.end_x(t);
    xd[0] = c.end_vx(t);
    double h = dt;
    if (MoorDyn_Step(sys, x, xd, f, &t, &h) != MOORDYN_SUCCESS)
      throw std::runtime_error("MoorDyn_Step failed");
    if (c.duration > 0 && k % c.sample_every == 0) {
      st.position = nodes();
      st.velocity = velocities();
      st.time = t;
      mc::sample(c, st, true, r.series);
    }
  }
  r.x_end = nodes();
  MoorDyn_Close(sys);
  return r;
}

// kelp's static shape of the current case (its own solver) for a line model.
kelp::Matrix3X<double> kelp_static(const mc::Case& c, kt::LineModel lm) {
  const kt::TetherModeld model(mc::parameters(c, lm));
  kt::TetherWorkspaced ws(model);
  const auto env = mc::environment(c);
  kt::TetherStated st(model);
  kt::StaticOptionsd o;
  o.force_tolerance = 1e-8;  // N (the default is 1e-7 of the weight in air: 1.4e-6 N)
  o.max_iterations = 5000;   // the line in a current takes ~2000 pseudo steps to 1e-8 N
  const auto res =
      kt::static_initial_state(model, ws, env, Vector3<double>(c.start[0], c.start[1], c.start[2]),
                               Vector3<double>(c.end[0], c.end[1], c.end[2]), st, o);
  if (!res.converged)
    throw std::runtime_error("kelp static solve did not converge: residual " +
                             std::to_string(res.residual) + " N");
  return st.position;
}

void print_matrix(std::ofstream& o, const char* name, const kelp::Matrix3X<double>& m) {
  o << "inline constexpr double " << name << "[][3] = {\n";
  char b[128];
  for (int i = 0; i < m.cols(); ++i) {
    std::snprintf(b, sizeof b, "    {%.17g, %.17g, %.17g},\n", m(0, i), m(1, i), m(2, i));
    o << b;
  }
  o << "};\n";
}

void print_series(std::ofstream& o, const char* name, const mc::Series& s) {
  o << "// Every sample_every steps: end-segment axial force [N], mid node x, z (NED) [m]\n";
  o << "inline constexpr double " << name << "[][3] = {\n";
  char b[160];
  for (size_t i = 0; i < s.t.size(); ++i) {
    std::snprintf(b, sizeof b, "    {%.12g, %.12g, %.12g},\n", s.tension[i], s.mid_x[i],
                  s.mid_z[i]);
    o << b;
  }
  o << "};\n";
}

// Runs the cases in MoorDyn and in kelp (both line models), prints the table, and writes
// MoorDyn's results to `reference` when it is not empty.
void validation(const std::string& dir, const std::string& reference) {
  std::printf("== validation cases (tests/tether/moordyn_cases.hpp) vs MoorDyn v2 RK4 ==\n");
  std::printf(
      "case, kelp line model, end-segment force RMS diff / RMS, largest mid-node distance [m]\n");
  const MdRun surge = run_moordyn(mc::surge, dir), snap = run_moordyn(mc::snap, dir),
              cur = run_moordyn(mc::current, dir);
  for (const auto* cp : {&mc::surge, &mc::snap}) {
    const MdRun& m = cp == &mc::surge ? surge : snap;
    // kelp's default line, the same with MoorDyn's dashpot only, and LineModel::moordyn.
    for (int variant = 0; variant < 3; ++variant) {
      kt::TetherParametersd p =
          mc::parameters(*cp, variant == 2 ? kt::LineModel::moordyn : kt::LineModel::kelp);
      p.compressive_damping = variant == 1;
      const mc::Series k = mc::run_kelp(*cp, p, m.x0);
      const char* names[] = {"kelp", "kelp + compressive_damping", "moordyn"};
      std::printf("%s, %s, %.3e, %.3e\n", cp->name, names[variant],
                  mc::relative_rms(k.tension, m.series.tension),
                  mc::max_distance(k.mid_x, k.mid_z, m.series.mid_x, m.series.mid_z));
    }
  }
  for (kt::LineModel lm : {kt::LineModel::kelp, kt::LineModel::moordyn}) {
    const kelp::Matrix3X<double> xs = kelp_static(mc::current, lm);
    std::printf(
        "current (static), %s, largest node distance %.3e m, mid node %.3e m\n",
        lm == kt::LineModel::kelp ? "kelp" : "moordyn",
        (xs - cur.x_end).colwise().norm().maxCoeff(),
        (xs.col(mc::current.segments / 2) - cur.x_end.col(mc::current.segments / 2)).norm());
  }
  if (reference.empty()) return;
  std::ofstream o(reference);
  o << "// MoorDyn v2.7.1's results for the validation cases of tests/tether/moordyn_cases.hpp,\n"
       "// written by kelp-moordyn-side-by-side --write-reference (benchmarks/moordyn/). Do not\n"
       "// edit: regenerate. MoorDyn: https://github.com/FloatingArrayDesign/MoorDyn "
       "(BSD-3-Clause).\n"
       "// clang-format off\n"
       "#pragma once\n\nnamespace moordyn_reference {\n\n";
  o << "// Initial nodes (MoorDyn's stationary solution, NED [m]).\n";
  print_matrix(o, "surge_x0", surge.x0);
  print_series(o, "surge_series", surge.series);
  print_matrix(o, "snap_x0", snap.x0);
  print_series(o, "snap_series", snap.series);
  o << "// The line in the current: MoorDyn's nodes after its stationary solution and 300 s of\n"
       "// dynamics with the ends held (settled to 1e-12 m; NED [m]).\n";
  print_matrix(o, "current_nodes", cur.x_end);
  o << "\n}  // namespace moordyn_reference\n// clang-format on\n";
  std::printf("wrote %s\n", reference.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> sizes = {20, 50, 100, 200};
  int rounds = 5;
  double min_time = 0.2, check_T = 5.0;
  bool check = true, timing = true, validate = true;
  std::string dir = "/tmp/moordyn-bench", reference;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--rounds")
      rounds = std::atoi(argv[++i]);
    else if (a == "--min-time")
      min_time = std::atof(argv[++i]);
    else if (a == "--check-time")
      check_T = std::atof(argv[++i]);
    else if (a == "--no-check")
      check = false;
    else if (a == "--no-timing")
      timing = false;
    else if (a == "--no-validation")
      validate = false;
    else if (a == "--write-reference")
      reference = argv[++i];
    else if (a == "--sizes") {
      sizes.clear();
      std::string s = argv[++i];
      size_t p = 0;
      while (p < s.size()) {
        size_t q = s.find(',', p);
        if (q == std::string::npos) q = s.size();
        sizes.push_back(std::stoi(s.substr(p, q - p)));
        p = q + 1;
      }
    } else if (a == "--dir")
      dir = argv[++i];
  }
  std::system(("mkdir -p " + dir).c_str());

  auto common_dt = [](int n) {
    const double l = 20.0 / n, m = 0.07 * l, k = 1e5 / l;
    const double dt_cfl = 0.1 * 2 * M_PI * std::sqrt(m / k);
    const double q = std::ldexp(1.0, -24);
    return std::floor(dt_cfl / q) * q;
  };

  if (validate) validation(dir, reference);
  if (check) {
    std::printf("== agreement check (%.0f s of heave, common dt) ==\n", check_T);
    for (int n : sizes) agreement(n, common_dt(n), dir, check_T);
  }
  if (!timing) return 0;

  std::printf("\n== timing: %d rounds, >= %.2f s wall per measurement ==\n", rounds, min_time);
  std::printf(
      "case,N,round,dt_s,iters,wall_s,cpu_s,ns_per_node_eval_wall,ns_per_node_eval_cpu,"
      "rtf_wall,rtf_cpu\n");
  struct Row {
    std::vector<double> ns_w, ns_c, rtf_w, rtf_c;
  };
  struct Sum {
    int n;
    double dt, dt_kelp;
    Row md, mdc, krk4, kforce, kforcej, kbdf2, kbdf2x, kbdf21, krk4own, kforce_base, kbdf2_base,
        kbdf2_md;
  };
  std::vector<Sum> sums;
  for (int n : sizes) {
    const double dt = common_dt(n);
    const long K = std::lround(0.01 / dt);
    const double hc = K * dt;
    Sum S;
    S.n = n;
    S.dt = dt;
    Md md(n, dt, dir);
    Md mdc(n, dt, dir);
    Kelp krk(n), kf(n), kbd(n), kbdx(n), kbd1(n), kown(n), kbd_base(n);
    Kelp kbd_md(n, 0.0, kt::LineModel::moordyn);  // BDF2 on MoorDyn's line model
    const kt::ImplicitOptionsd once = one_newton(), exact = exact_newton();
    S.dt_kelp = kt::estimate_stable_dt(kown.model, kt::Integrator::rk4, kown.env.water_density());
    const double nodes = n + 1;
    auto record = [&](const char* name, Row& row, int r, const Timing& t, double evals_per_iter,
                      double sim_per_iter, double dtv) {
      const double ev = evals_per_iter * t.iters;
      const double nsw = t.wall * 1e9 / (ev * nodes), nsc = t.cpu * 1e9 / (ev * nodes);
      const double rw = sim_per_iter > 0 ? sim_per_iter * t.iters / t.wall : 0;
      const double rc = sim_per_iter > 0 ? sim_per_iter * t.iters / t.cpu : 0;
      row.ns_w.push_back(nsw);
      row.ns_c.push_back(nsc);
      row.rtf_w.push_back(rw);
      row.rtf_c.push_back(rc);
      std::printf("%s,%d,%d,%.6e,%ld,%.4f,%.4f,%.2f,%.2f,%.2f,%.2f\n", name, n, r, dtv, t.iters,
                  t.wall, t.cpu, nsw, nsc, rw, rc);
      std::fflush(stdout);
    };
    // kf's force evaluation (with the Jacobian terms when WithJacobian) and BDF2 steps of 10 ms of
    // line k (counting the force evaluations into `evals`), each timed by run_for.
    const auto time_forces = [&](auto with_jacobian) {
      return run_for(min_time, 256, [&] {
        kt::compute_forces<decltype(with_jacobian)::value>(kf.model, kf.ws, kf.env, 0.0,
                                                           kf.state.position, kf.state.velocity);
        asm volatile("" : : "r"(kf.ws.force.data()) : "memory");
      });
    };
    const auto time_bdf2 = [&](Kelp& k, const kt::ImplicitOptionsd& options, long& evals) {
      evals = 0;
      return run_for(min_time, 16, [&] {
        evals += kt::step(k.model, k.ws, k.env, k.state, k.boundary(k.state.time), 0.01,
                          {kt::Integrator::bdf2, options})
                     .force_evaluations;
      });
    };
    for (int r = 0; r < rounds; ++r) {
      // MoorDyn first, then kelp
      Timing t = run_for(min_time, 64, [&] { md.step(dt); });
      record("moordyn_rk4", S.md, r, t, 4, dt, dt);
      t = run_for(min_time, 1, [&] { mdc.step(hc); });
      record("moordyn_rk4_10ms_coupling", S.mdc, r, t, 4.0 * K, hc, dt);
      t = run_for(min_time, 64, [&] { krk.step(dt, kt::Integrator::rk4); });
      record("kelp_rk4", S.krk4, r, t, 4, dt, dt);
      t = time_forces(std::false_type{});
      record("kelp_forces", S.kforce, r, t, 1, 0, 0);
      t = time_forces(std::true_type{});
      record("kelp_forces_jacobian", S.kforcej, r, t, 1, 0, 0);
      long evb = 0;
      t = time_bdf2(kbd, {}, evb);
      record("kelp_bdf2_10ms", S.kbdf2, r, t, double(evb) / t.iters, 0.01, 0.01);
      t = time_bdf2(kbd_md, {}, evb);
      record("kelp_bdf2_10ms_moordyn_line", S.kbdf2_md, r, t, double(evb) / t.iters, 0.01, 0.01);
      t = time_bdf2(kbdx, exact, evb);
      record("kelp_bdf2_exact_10ms", S.kbdf2x, r, t, double(evb) / t.iters, 0.01, 0.01);
      t = run_for(min_time, 16, [&] { kbd1.step(0.01, kt::Integrator::bdf2, once); });
      record("kelp_bdf2_one_newton_10ms", S.kbdf21, r, t, 1, 0.01, 0.01);
      t = run_for(min_time, 64, [&] { kown.step(S.dt_kelp, kt::Integrator::rk4); });
      record("kelp_rk4_own_dt", S.krk4own, r, t, 4, S.dt_kelp, S.dt_kelp);
      // The same force evaluation and BDF2 step on the force passes' baseline build (the build's
      // own packets: SSE2 on x86-64) where kelp dispatches them to AVX2 (same bits).
      kt::detail::wide_force_passes() = false;
      t = time_forces(std::false_type{});
      record("kelp_forces_baseline", S.kforce_base, r, t, 1, 0, 0);
      t = time_bdf2(kbd_base, {}, evb);
      record("kelp_bdf2_10ms_baseline", S.kbdf2_base, r, t, double(evb) / t.iters, 0.01, 0.01);
      kt::detail::wide_force_passes() = true;
    }
    sums.push_back(S);
  }

  std::printf(
      "\n== summary: min / median over %d rounds (ns per node per force evaluation; "
      "real-time factor max / median), wall clock [thread CPU] ==\n",
      rounds);
  for (const Sum& S : sums) {
    auto ns = [](const Row& r) {
      char b[96];
      std::snprintf(b, sizeof b, "%.1f / %.1f [%.1f / %.1f]", minv(r.ns_w), median(r.ns_w),
                    minv(r.ns_c), median(r.ns_c));
      return std::string(b);
    };
    auto rtf = [](const Row& r) {
      char b[96];
      std::snprintf(b, sizeof b, "%.3g / %.3g [%.3g / %.3g]", maxv(r.rtf_w), median(r.rtf_w),
                    maxv(r.rtf_c), median(r.rtf_c));
      return std::string(b);
    };
    std::printf("N=%d dt=%.3f us (kelp RK4 own dt estimate_stable_dt = %.3f us)\n", S.n, S.dt * 1e6,
                S.dt_kelp * 1e6);
    std::printf("  MoorDyn RK4 (Step per dtM)  ns/node/eval %s  RTF %s\n", ns(S.md).c_str(),
                rtf(S.md).c_str());
    std::printf("  MoorDyn RK4 (10 ms coupling) ns/node/eval %s  RTF %s\n", ns(S.mdc).c_str(),
                rtf(S.mdc).c_str());
    std::printf("  kelp RK4 (same dt)          ns/node/eval %s  RTF %s\n", ns(S.krk4).c_str(),
                rtf(S.krk4).c_str());
    std::printf("  kelp compute_forces         ns/node      %s\n", ns(S.kforce).c_str());
    std::printf("  kelp compute_forces<true>   ns/node      %s\n", ns(S.kforcej).c_str());
    std::printf("  kelp BDF2 10 ms             ns/node/eval %s  RTF %s\n", ns(S.kbdf2).c_str(),
                rtf(S.kbdf2).c_str());
    std::printf("  kelp BDF2 10 ms, MoorDyn's line ns/node/eval %s  RTF %s\n",
                ns(S.kbdf2_md).c_str(), rtf(S.kbdf2_md).c_str());
    std::printf("  kelp BDF2 exact Newton 10 ms ns/node/eval %s  RTF %s\n", ns(S.kbdf2x).c_str(),
                rtf(S.kbdf2x).c_str());
    std::printf("  kelp BDF2 one Newton 10 ms  ns/node/eval %s  RTF %s\n", ns(S.kbdf21).c_str(),
                rtf(S.kbdf21).c_str());
    std::printf("  kelp RK4 (own dt)           ns/node/eval %s  RTF %s\n", ns(S.krk4own).c_str(),
                rtf(S.krk4own).c_str());
    std::printf("  kelp compute_forces, baseline build ns/node %s\n", ns(S.kforce_base).c_str());
    std::printf("  kelp BDF2 10 ms, baseline build ns/node/eval %s  RTF %s\n",
                ns(S.kbdf2_base).c_str(), rtf(S.kbdf2_base).c_str());
    std::printf(
        "  force passes' build taken: %s; baseline / it: force evaluation %.2f (min) %.2f "
        "(median), BDF2 real-time factor %.2f (max) %.2f (median)\n",
        kt::detail::force_passes_take_avx2() ? "AVX2" : "baseline",
        minv(S.kforce_base.ns_w) / minv(S.kforce.ns_w),
        median(S.kforce_base.ns_w) / median(S.kforce.ns_w),
        maxv(S.kbdf2.rtf_w) / maxv(S.kbdf2_base.rtf_w),
        median(S.kbdf2.rtf_w) / median(S.kbdf2_base.rtf_w));
    // Ratios of the minima (wall clock) and of the medians, measured in this run.
    std::printf(
        "  ratios MoorDyn/kelp: force evaluation %.2f (min) %.2f (median); RK4 real-time factor "
        "%.2f (max) %.2f (median)\n",
        minv(S.md.ns_w) / minv(S.kforce.ns_w), median(S.md.ns_w) / median(S.kforce.ns_w),
        maxv(S.krk4.rtf_w) / maxv(S.md.rtf_w), median(S.krk4.rtf_w) / median(S.md.rtf_w));
  }
  return 0;
}
