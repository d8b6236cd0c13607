// A downstream program on kelp::sim, built against the installed package: it writes a scenario
// file, loads it, runs 10 s of the closed loop with a CSV log through the public API and checks
// what the run must show. Exit status 0 when every check holds.
// kelp/sim.hpp first: this file is where the packaging test compiles it on its own.
#include "kelp/sim.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

int failures = 0;

void check(bool ok, const std::string& what) {
  if (!ok) {
    std::fprintf(stderr, "hello_sim: FAILED: %s\n", what.c_str());
    ++failures;
  }
}

std::size_t lines_of(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);) ++n;
  return n;
}

}  // namespace

int main() {
  namespace fs = std::filesystem;
  const fs::path dir = fs::current_path() / "hello_sim_run";
  fs::create_directories(dir);
  const std::string file = (dir / "scenario.json").string();
  // A calm sea, a 10 m tether in 1 m segments, the default square survey (its first corner 10 m
  // ahead of the ROV's start at 5 m depth), samples at 5 Hz.
  std::ofstream(file) << R"({"duration": 10, "seed": 3, "sea": "calm",
    "tether": {"length": 10, "segment_length": 1.0},
    "output": {"log_rate": 5, "node_rate": 1}})";

  const kelp::sim::Scenario sc = kelp::sim::load_scenario(file);
  check(sc.duration == 10.0 && sc.sea == kelp::sim::Sea::calm && sc.segment_length == 1.0,
        "the scenario file was not read as written");

  kelp::sim::RunLog log(dir);
  kelp::sim::ClosedLoopOptions options;
  options.scenario_file = file;
  options.log = &log;
  kelp::sim::ClosedLoop loop(sc, options);
  const kelp::Vector3<double> first_corner = loop.waypoints().front();
  const double d0 = (loop.state().auv.position - first_corner).norm();
  long observed = 0;
  while (!loop.done()) {
    const kelp::system::SystemReportd& r = loop.step();
    observed += std::isfinite(r.force_on_auv.norm()) ? 1 : 0;
  }
  log.close();
  const double d1 = (loop.state().auv.position - first_corner).norm();

  check(loop.total_steps() == 1000 && loop.steps_taken() == 1000 && observed == 1000,
        "10 s is not 1000 steps of 10 ms with a finite report each");
  check(std::abs(loop.time() - 10.0) < 1e-9, "the clock does not read 10 s");
  // The ROV flies towards its first corner (at up to ~1 m/s; 10 m away at the start).
  check(d1 < d0 - 2.0, "the ROV did not make progress towards its first waypoint (" +
                           std::to_string(d0) + " m -> " + std::to_string(d1) + " m)");
  // A 10 m tether between vehicles a few metres apart hangs in the water: it pulls on both.
  check(loop.sample().tension_auv > 0.0 && loop.sample().tension_asv > 0.0,
        "no tether tension at the end of the run");
  const kelp::sim::RunSummary s = loop.summary();
  check(std::isfinite(s.auv.rms_path_error_m) && std::isfinite(s.auv.max_path_error_m) &&
            s.auv.max_path_error_m >= s.auv.rms_path_error_m,
        "summary auv: path errors not finite or the largest below the RMS");
  check(std::isfinite(s.energy_j), "summary energy_j not finite");
  check(s.tether.max_tension_n > 0.0, "summary: no tension");
  check(kelp::sim::scenario_json(s.scenario) == kelp::sim::scenario_json(sc),
        "summary does not echo the scenario");
  const std::string text = kelp::sim::summary_json(s);
  check(text.find("\"max_tension_n\":") != std::string::npos &&
            text.find(kelp::sim::scenario_json(sc)) != std::string::npos,
        "summary_json() lacks the tension or the scenario's echo");
  // timeseries.csv: the header and one row every 0.2 s from 0 to 10 s; nodes.csv: the header and
  // 11 nodes every second from 0 to 10 s.
  check(lines_of(dir / "timeseries.csv") == 1 + 51, "timeseries.csv does not have 51 rows");
  check(lines_of(dir / "nodes.csv") == 1 + 11 * 11, "nodes.csv does not have 11 snapshots");
  check(loop.metrics().samples == 50, "the metrics did not take 50 samples");

  // A bad scenario is refused with kelp::sim::scenario_error (a kelp::error) naming the path.
  try {
    (void)kelp::sim::parse_scenario(R"({"tether": {"length": -3}})", "bad.json");
    check(false, "a negative tether length was accepted");
  } catch (const kelp::error& e) {
    check(dynamic_cast<const kelp::sim::scenario_error*>(&e) != nullptr &&
              std::string(e.what()).find("bad.json: /tether/length") == 0,
          std::string("unexpected error for a bad scenario: ") + e.what());
  }

  if (failures > 0) return 1;
  std::printf(
      "hello_sim: 10 s of %s in %ld steps; ROV %.2f m -> %.2f m from its first waypoint, end "
      "tension %.2f N at the ROV\n",
      file.c_str(), loop.steps_taken(), d0, d1, loop.sample().tension_auv);
  return 0;
}
