// Scenarios shared by the kelp::sim tests.
#pragma once

#include "kelp/sim/scenario.hpp"

namespace kelp_test {

/// A short calm run on a coarse tether: 5 s, samples at 5 Hz, tether snapshots at 2 Hz.
inline kelp::sim::Scenario short_calm_run() {
  kelp::sim::Scenario sc;
  sc.sea = "calm";
  sc.duration = 5.0;
  sc.segment_length = 1.0;
  sc.log_rate = 5.0;
  sc.node_rate = 2.0;
  return sc;
}

}  // namespace kelp_test
