// Scenarios shared by the kelp::sim tests, and the JSON kelp::sim writes as values to compare.
#pragma once

#include <nlohmann/json.hpp>

#include "kelp/sim/scenario.hpp"
#include "kelp/sim/summary.hpp"

namespace kelp_test {

/// The scenario as the JSON value scenario_json() writes.
inline nlohmann::json json_of(const kelp::sim::Scenario& s) {
  return nlohmann::json::parse(kelp::sim::scenario_json(s));
}

/// The summary as the JSON value summary_json() writes (summary.json's).
inline nlohmann::json json_of(const kelp::sim::RunSummary& s) {
  return nlohmann::json::parse(kelp::sim::summary_json(s));
}

/// A short calm run on a coarse tether: 5 s, samples at 5 Hz, tether snapshots at 2 Hz.
inline kelp::sim::Scenario short_calm_run() {
  kelp::sim::Scenario sc;
  sc.sea = kelp::sim::Sea::calm;
  sc.duration = 5.0;
  sc.segment_length = 1.0;
  sc.log_rate = 5.0;
  sc.node_rate = 2.0;
  return sc;
}

}  // namespace kelp_test
