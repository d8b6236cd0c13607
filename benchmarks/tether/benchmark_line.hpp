// kelp's tether benchmark line, shared by bench_tether and the MoorDyn side-by-side
// (benchmarks/moordyn/): TetherParameters defaults (20 m, d 8 mm, 0.07 kg/m, EA 1e5 N, Cdn 1.2,
// Cdt 0.008, Can 1, no internal damping) with N segments, ends 10 m apart horizontally and 5 m
// vertically in still seawater, started from static equilibrium, the far end heaving
// 0.1 m (1 − cos ωt) with ω = 2π · 0.2 Hz.
#pragma once

#include <cmath>
#include <stdexcept>

#include "kelp/core/constants.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/lumped_mass.hpp"
#include "kelp/tether/stable_dt.hpp"

namespace kelp_bench {

/// The far end's heave, NED: depth z(t) [m], its velocity and acceleration.
struct Heave {
  static constexpr double amplitude = 0.1, base_depth = 5.0;
  static constexpr double omega = 2 * kelp::pi * 0.2;
  static double z(double t) { return base_depth + amplitude * (1 - std::cos(omega * t)); }
  static double vz(double t) { return amplitude * omega * std::sin(omega * t); }
  static double az(double t) { return amplitude * omega * omega * std::cos(omega * t); }
};

struct BenchmarkLine {
  kelp::environment::Environmentd env;
  kelp::tether::TetherModeld model;
  kelp::tether::TetherWorkspaced ws;
  kelp::tether::TetherStated state;
  kelp::Vector3<double> a{0, 0, 0}, b{10, 0, Heave::base_depth};

  /// N segments; `damping_ratio` ζ > 0 gives the line internal damping BA = 2ζ EA/ω_max, the
  /// damping ratio ζ at its highest axial frequency (MoorDyn's negative-BA convention);
  /// `line_model` kelp's line or MoorDyn's (kelp::tether::LineModel).
  explicit BenchmarkLine(int n, double damping_ratio = 0.0,
                         kelp::tether::LineModel line_model = kelp::tether::LineModel::kelp)
      : model(params(n, damping_ratio, line_model)), ws(model) {
    if (!kelp::tether::static_initial_state(model, ws, env, a, b, state).converged)
      throw std::runtime_error("benchmark line: static equilibrium did not converge");
  }
  static kelp::tether::TetherParametersd params(
      int n, double damping_ratio = 0.0,
      kelp::tether::LineModel line_model = kelp::tether::LineModel::kelp) {
    kelp::tether::TetherParametersd p;
    p.segments = n;
    p.line_model = line_model;
    if (damping_ratio > 0)
      p.internal_damping =
          2 * damping_ratio * p.axial_stiffness /
          kelp::tether::highest_axial_frequency(kelp::tether::TetherModeld(p), 0.0);
    return p;
  }
  /// Fixed start at a, the far end heaving about b.
  kelp::tether::TetherBoundaryd boundary(double t) const {
    kelp::tether::TetherBoundaryd bnd = kelp::tether::TetherBoundaryd::fixed(a, b);
    bnd.end.position.z() = Heave::z(t);
    bnd.end.velocity.z() = Heave::vz(t);
    bnd.end.acceleration.z() = Heave::az(t);
    return bnd;
  }
};

}  // namespace kelp_bench
