// libFuzzer target: kelp::sim's scenario reader (include/kelp/sim/scenario.hpp).
//
// Oracle: parse_scenario(input) either throws kelp::sim::scenario_error (the documented
// error, whose message names the file) or returns a scenario whose every number is finite and
// within the schema's ranges; scenario_json() of it parses back to the same scenario (the echo in
// the run's summary is a valid scenario file). Any other exception, crash or sanitizer report is a
// finding.
#include <string>

#include "fuzz_common.hpp"
#include "kelp/sim/scenario.hpp"

namespace {

void check_ranges(const kelp::sim::Scenario& s) {
  const auto in = [](double x, double lo, double hi) {
    return std::isfinite(x) && x >= lo && x <= hi;
  };
  KELP_FUZZ_REQUIRE(in(s.duration, 1e-3, 1e7), "duration");
  KELP_FUZZ_REQUIRE(s.seed <= 1000000000000000000ull, "seed");
  KELP_FUZZ_REQUIRE(s.wave_components >= 1 && s.wave_components <= 4096, "wave_components");
  KELP_FUZZ_REQUIRE(in(s.tether_length, 0.5, 1000), "tether length");
  KELP_FUZZ_REQUIRE(in(s.segment_length, 0.05, 10), "segment length");
  KELP_FUZZ_REQUIRE(in(s.asv_rate, 0.1, 1000) && in(s.auv_rate, 0.1, 1000), "rates");
  KELP_FUZZ_REQUIRE(in(s.log_rate, 0.01, 100) && in(s.node_rate, 0.001, 100), "output rates");
  KELP_FUZZ_REQUIRE(in(s.depth, 0.5, 1000) && in(s.square_side, 0.5, 1000), "mission");
  KELP_FUZZ_REQUIRE(s.asv_attachment.allFinite() && s.auv_attachment.allFinite(), "attachments");
  for (const auto& w : s.waypoints) KELP_FUZZ_REQUIRE(w.allFinite(), "waypoint");
  KELP_FUZZ_REQUIRE(!s.auv_start || s.auv_start->allFinite(), "auv_start");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  kelp::sim::Scenario s;
  try {
    s = kelp::sim::parse_scenario(text, "fuzz.json");
  } catch (const kelp::sim::scenario_error& e) {
    KELP_FUZZ_REQUIRE(std::string(e.what()).rfind("fuzz.json: ", 0) == 0,
                      "scenario_error does not name the file");
    return 0;
  }
  check_ranges(s);
  const std::string echo = kelp::sim::scenario_json(s);
  kelp::sim::Scenario again;
  try {
    again = kelp::sim::parse_scenario(echo, "echo.json");
  } catch (const kelp::sim::scenario_error& e) {
    kelp_fuzz::finding(std::string("scenario_json() of a valid scenario is refused: ") + e.what());
  }
  KELP_FUZZ_REQUIRE(kelp::sim::scenario_json(again) == kelp::sim::scenario_json(s),
                    "scenario_json() does not read back to the same scenario");
  return 0;
}
