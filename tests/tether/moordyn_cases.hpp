// The validation cases run side by side with MoorDyn v2.7.1 (benchmarks/moordyn/side_by_side.cpp,
// which also writes MoorDyn's results into tests/tether/moordyn_reference.hpp) and replayed
// against those stored results by tests/tether/test_moordyn_reference.cpp. kelp-only: this header
// needs no MoorDyn.
//
// Every case is kelp's benchmark line (TetherParameters defaults: 20 m, d 8 mm, 0.07 kg/m,
// EA 1e5 N, Cdn 1.2, Cdt 0.008, Can 1, Cat 0) in 20 segments, deep in still seawater
// (1025 kg/m³, g 9.80665; no seabed or surface in reach), node 0 fixed at `start`, node N moved
// along x as base + A (1 − cos ωt). NED here; MoorDyn works in z up: (x, y, z) <-> (x, y, −z).
//
// Both codes step classical RK4 at the same dt (MoorDyn's CFL-0.1 dt of this line, rounded down
// to a multiple of 2⁻²⁴ s), both starting from MoorDyn's initial nodes (its stationary solution).
// Within a step MoorDyn moves a coupled point linearly, r = x(t) + ẋ(t) τ: kelp is given the same
// end motion (TetherBoundary with zero acceleration), so after every step both end nodes sit at
// x(t) + ẋ(t) dt and the end segments' forces compare the lines alone.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "kelp/core/constants.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/tether/integrators.hpp"
#include "kelp/tether/lumped_mass.hpp"

namespace moordyn_cases {

/// One validation case.
struct Case {
  const char* name;
  int segments;
  double internal_damping;  // BA [N s]
  double start[3];          // node 0, NED [m]
  double end[3];            // node N at t = 0, NED [m]
  double amplitude;         // end surge A [m]: x = end[0] + A (1 - cos wt)
  double frequency;         // [Hz]
  double current;           // uniform current along +x [m/s]
  double duration;          // [s]
  int sample_every;         // steps between samples (38: ~20 ms)

  double omega() const { return 2 * kelp::pi * frequency; }
  double end_x(double t) const { return end[0] + amplitude * (1 - std::cos(omega() * t)); }
  double end_vx(double t) const { return amplitude * omega() * std::sin(omega() * t); }
  /// The common dt: MoorDyn's CFL 0.1 dt, 0.1 · 2π √(m l / EA), rounded down to 2⁻²⁴ s.
  double dt() const {
    const double l = 20.0 / segments, m = 0.07 * l, k = 1e5 / l;
    const double q = std::ldexp(1.0, -24);
    return std::floor(0.1 * 2 * kelp::pi * std::sqrt(m / k) / q) * q;
  }
  long steps() const { return std::lround(duration / dt()); }
};

/// Surge: the slack benchmark line (ends 10 m apart, 5 m down), far end surging 0.5 m at 0.2 Hz.
inline constexpr Case surge{"surge", 20, 0.0, {0, 0, 50}, {10, 0, 55}, 0.5, 0.2, 0.0, 10.0, 38};
/// Snap loads: the line nearly straight (chord 19.4 m of 20 m), far end surging 0.4 m at 0.5 Hz,
/// so that it goes slack and snaps taut (peaks ~1 kN) twice a second; BA 20 N s.
inline constexpr Case snap{"snap", 20, 20.0, {0, 0, 50}, {19, 0, 54}, 0.4, 0.5, 0.0, 10.0, 38};
/// Static shape in a 0.5 m/s current along +x (the slack line of `surge`, ends fixed).
inline constexpr Case current{"current", 20, 0.0, {0, 0, 50}, {10, 0, 55}, 0.0, 0.2, 0.5, 0.0, 1};

inline kelp::tether::TetherParametersd parameters(const Case& c,
                                                  kelp::tether::LineModel line_model) {
  kelp::tether::TetherParametersd p;
  p.segments = c.segments;
  p.internal_damping = c.internal_damping;
  p.line_model = line_model;
  return p;
}

inline kelp::environment::Environmentd environment(const Case& c) {
  kelp::environment::Environmentd env;
  if (c.current != 0) env.set_current(kelp::Vector3<double>(c.current, 0, 0));
  return env;
}

/// Fixed start; the far end at x(t) with velocity ẋ(t) and no acceleration (MoorDyn's linear
/// motion of a coupled point within a step).
inline kelp::tether::TetherBoundaryd boundary(const Case& c, double t) {
  const kelp::Vector3<double> a(c.start[0], c.start[1], c.start[2]);
  const kelp::Vector3<double> b(c.end_x(t), c.end[1], c.end[2]);
  kelp::tether::TetherBoundaryd bnd = kelp::tether::TetherBoundaryd::fixed(a, b);
  bnd.end.velocity.x() = c.end_vx(t);
  return bnd;
}

/// The axial force [N] of the segment between nodes p0 and p1 (velocities v0, v1) of a line of
/// unstretched segment length l: EA·max(0, ε) + BA·ε̇, not clamped when `pushes` (MoorDyn's line),
/// clamped at zero otherwise (kelp's).
inline double axial_force(const kelp::Vector3<double>& p0, const kelp::Vector3<double>& p1,
                          const kelp::Vector3<double>& v0, const kelp::Vector3<double>& v1,
                          double l, double ba, bool pushes) {
  const kelp::Vector3<double> d = p1 - p0;
  const double ls = d.norm();
  const double f = 1e5 * std::max(0.0, ls - l) / l + ba * d.dot(v1 - v0) / (ls * l);
  return pushes ? f : std::max(0.0, f);
}

/// The samples of one run: time, end-segment axial force, mid node x and z (NED).
struct Series {
  std::vector<double> t, tension, mid_x, mid_z;
};

/// The end segment's force and the mid node of a state into `s`.
inline void sample(const Case& c, const kelp::tether::TetherStated& st, bool pushes, Series& s) {
  const int n = c.segments;
  s.t.push_back(st.time);
  s.tension.push_back(axial_force(st.position.col(n - 1), st.position.col(n),
                                  st.velocity.col(n - 1), st.velocity.col(n), 20.0 / n,
                                  c.internal_damping, pushes));
  s.mid_x.push_back(st.position(0, n / 2));
  s.mid_z.push_back(st.position(2, n / 2));
}

/// kelp's RK4 run of a dynamic case with the tether parameters `p` (parameters(c, ...) or a
/// variant of them) from the initial nodes `x0` (NED, 3 × (N+1), at rest).
inline Series run_kelp(const Case& c, const kelp::tether::TetherParametersd& p,
                       const kelp::Matrix3X<double>& x0) {
  namespace kt = kelp::tether;
  const kt::TetherModeld model(p);
  kt::TetherWorkspaced ws(model);
  const auto env = environment(c);
  kt::TetherStated st(model);
  st.position = x0;
  st.velocity.setZero();
  st.time = 0;
  const bool pushes = model.parameters().compressive_damping;
  Series s;
  const double dt = c.dt();
  for (long k = 1; k <= c.steps(); ++k) {
    kt::step(model, ws, env, st, boundary(c, st.time), dt, {kt::Integrator::rk4});
    if (k % c.sample_every == 0) sample(c, st, pushes, s);
  }
  return s;
}

/// Relative RMS difference sqrt(Σ(a − b)²/Σ b²) of two series of equal length.
inline double relative_rms(const std::vector<double>& a, const std::vector<double>& b) {
  double e = 0, r = 0;
  for (size_t i = 0; i < b.size(); ++i) {
    e += (a[i] - b[i]) * (a[i] - b[i]);
    r += b[i] * b[i];
  }
  return std::sqrt(e / r);
}

/// Largest distance [m] between the points (x[i], z[i]) of two series.
inline double max_distance(const std::vector<double>& ax, const std::vector<double>& az,
                           const std::vector<double>& bx, const std::vector<double>& bz) {
  double d = 0;
  for (size_t i = 0; i < bx.size(); ++i) d = std::max(d, std::hypot(ax[i] - bx[i], az[i] - bz[i]));
  return d;
}

}  // namespace moordyn_cases
