// docs/getting-started.md's "hello tether": a 20 m lumped-mass tether between a fixed ASV and
// an AUV that drives away at 0.5 m/s, stepped with the implicit BDF2 integrator at 10 ms.
#include <cstdio>

#include "kelp/environment/environment.hpp"
#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/integrators.hpp"

int main() {
  namespace kt = kelp::tether;
  const kelp::environment::Environmentd sea;  // still seawater, no seabed
  kt::TetherParametersd p;                    // the benchmark line: 20 m, d 8 mm, EA 1e5 N
  p.segments = 100;
  p.internal_damping = 100.0;  // N s
  const kt::TetherModeld tether(p);
  kt::TetherWorkspaced ws(tether);
  const kelp::Vector3<double> asv(0, 0, 0), auv(10, 0, 5);  // NED [m]
  kt::TetherStated s;                                       // catenary, then static equilibrium:
  if (!kt::static_initial_state(tether, ws, sea, asv, auv, s).converged) return 1;
  auto ends = kt::TetherBoundaryd::fixed(asv, auv);
  ends.end.velocity = {0.5, 0, 0};
  for (int k = 0; k < 1000; ++k) {  // 10 s at 10 ms
    ends.end.position = auv + s.time * ends.end.velocity;
    kt::step(tether, ws, sea, s, ends, 0.01, {kt::Integrator::bdf2});
  }
  const kelp::Vector3<double> pull = ws.end_forces.on_end;  // force on the AUV [N, NED]
  std::printf("pull on the AUV after 10 s: %.2f N (%.2f, %.2f, %.2f) NED\n", pull.norm(), pull.x(),
              pull.y(), pull.z());
  return pull.norm() > 0.0 ? 0 : 1;
}
