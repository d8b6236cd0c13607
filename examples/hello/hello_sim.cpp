// Hello sim: 30 s of kelp-tethered-pair's closed loop (a scenario file, or the embedded default)
// through kelp::sim, with its CSV log (checked against docs/getting-started.md by CTest).
#include <cstdio>

#include "kelp/sim.hpp"

int main(int argc, char** argv) {
  namespace sim = kelp::sim;
  // A scenario file (schema: apps/tethered_pair/README.md), or the embedded default run.
  sim::Scenario sc = argc > 1 ? sim::load_scenario(argv[1]) : sim::Scenario{};
  sc.duration = 30.0;                // [s]
  sim::RunLog log("hello-sim-run");  // timeseries.csv and nodes.csv, at the scenario's rates
  sim::ClosedLoopOptions options;
  options.log = &log;
  sim::ClosedLoop loop(sc, options);  // the world, the ROV's survey, the boat following it
  while (!loop.done()) loop.step();   // 10 ms a step
  std::printf("after %.0f s: ROV %.2f m from its path (RMS), next waypoint %zu, pull %.2f N\n",
              loop.time(), loop.metrics().auv_rms_error(), loop.auv_controller().next_waypoint(),
              loop.sample().tension_auv);
  return 0;
}
