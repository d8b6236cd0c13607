// docs/custom-environment.md's example: a 20 m tether hangs in WaveTank (wave_tank.hpp), a
// custom environment, and in kelp's own Environment given the same regular wave; the two runs
// agree. Exit status 0 when they do (and the wave moved the line).
#include <cstdio>

#include "kelp/environment/sea_state.hpp"
#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/integrators.hpp"
#include "wave_tank.hpp"

// The tether asks WaveTank for the elevation in the same batch query as the kinematics (a
// signature that missed would not compile: kelp/tether/forces.hpp's static_assert).
static_assert(kelp::tether::detail::has_batch_surface<WaveTank<double>, double>::value);

namespace kt = kelp::tether;

// The middle node of a 20 m line from (0, 0, −0.5) to (12, 0, 8) m (NED; the top end out of the
// water) laid as a catenary, at the start (`start`) and after 5 s of 10 ms steps in `env`.
template <typename Env>
kelp::Vector3<double> hang(const Env& env, kelp::Vector3<double>& start) {
  kt::TetherParametersd p;  // the benchmark line: 20 m, d 8 mm, EA 1e5 N
  p.segments = 40;
  p.internal_damping = 100.0;  // N s
  const kt::TetherModeld tether(p);
  kt::TetherWorkspaced ws(tether);
  const kelp::Vector3<double> a(0, 0, -0.5), b(12, 0, 8);
  kt::TetherStated s = kt::catenary_initial_state(tether, env, a, b);
  start = s.position.col(20);
  const auto ends = kt::TetherBoundaryd::fixed(a, b);
  for (int k = 0; k < 500; ++k) kt::step(tether, ws, env, s, ends, 0.01, {kt::Integrator::bdf2});
  return s.position.col(20);
}

int main() {
  const WaveTank<double> tank;
  kelp::environment::SeaState sea;  // no JONSWAP sea: the regular wave alone
  kelp::environment::RegularWave w;
  w.height = 2.0 * tank.amplitude;
  w.period = tank.period;
  sea.regular_waves = {w};
  const auto kelps = kelp::environment::make_environment<double>(sea);
  kelp::Vector3<double> start;
  const kelp::Vector3<double> mid_tank = hang(tank, start), mid_kelp = hang(kelps, start);
  const double gap = (mid_tank - mid_kelp).norm(), moved = (mid_tank - start).norm();
  std::printf(
      "middle node after 5 s: WaveTank (%.6f, %.6f, %.6f) m, kelp (%.6f, %.6f, %.6f) m, "
      "%.2e m apart; it moved %.3f m\n",
      mid_tank.x(), mid_tank.y(), mid_tank.z(), mid_kelp.x(), mid_kelp.y(), mid_kelp.z(), gap,
      moved);
  return gap < 1e-6 && moved > 0.01 && kelp::all_finite(mid_tank) ? 0 : 1;
}
