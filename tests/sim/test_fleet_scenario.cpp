// Fleet scenarios (`"fleet"`, kelp/sim/fleet_run.hpp): the shipped ones parse, write back the
// same and run to what they describe (a TMS hanging as its umbilical's weight says while its
// winch pays out the ROV's tether; a ROV returning to its dock; a boat holding station over two
// ROVs); bad fleets are refused naming the JSON path.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "kelp/sim/fleet_run.hpp"
#include "kelp/sim/scenario.hpp"
#include "kelp/sim/world.hpp"

namespace sim = kelp::sim;
namespace fs = std::filesystem;

namespace {

std::string scenario_path(const char* name) {
  return std::string(KELP_SCENARIO_DIR) + "/" + name + ".json";
}

// The rows of a CSV file: its header's column index and the numbers of each row.
struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  int column(const std::string& name) const {
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return int(i);
    FAIL("no column " << name);
    return -1;
  }
};
Csv read_csv(const fs::path& file) {
  std::ifstream in(file);
  Csv c;
  std::string line, cell;
  std::getline(in, line);
  std::stringstream h(line);
  while (std::getline(h, cell, ',')) c.header.push_back(cell);
  while (std::getline(in, line)) {
    std::stringstream r(line);
    std::vector<double> row;
    while (std::getline(r, cell, ',')) row.push_back(std::stod(cell));
    REQUIRE(row.size() == c.header.size());
    c.rows.push_back(row);
  }
  return c;
}

fs::path out_dir(const char* name) {
  const fs::path d = fs::temp_directory_path() / (std::string("kelp_test_fleet_") + name);
  fs::remove_all(d);
  return d;
}

}  // namespace

TEST_CASE("the shipped fleet scenarios parse and write back the same", "[sim][fleet]") {
  for (const char* name : {"ship_tms_rov", "boat_two_rovs", "rov_docking"}) {
    const sim::Scenario s = sim::load_scenario(scenario_path(name));
    REQUIRE(s.fleet);
    const std::string text = sim::scenario_json(s);
    const sim::Scenario back = sim::parse_scenario(text, name);
    CHECK(sim::scenario_json(back) == text);
    // The world builds: every vehicle loaded, every tether between its ends.
    const sim::FleetWorld w = sim::fleet_world(s, scenario_path(name));
    CHECK(w.parameters.vehicles.size() == s.fleet->vehicles.size());
    CHECK(w.parameters.tethers.size() == s.fleet->tethers.size());
  }
  // A pair scenario has no fleet and writes no "fleet" key.
  CHECK_FALSE(sim::Scenario{}.fleet);
  CHECK(sim::scenario_json(sim::Scenario{}).find("fleet") == std::string::npos);
}

TEST_CASE(
    "ship - umbilical - TMS - tether - ROV: the TMS hangs as its weight says and its "
    "winch pays out",
    "[sim][fleet]") {
  sim::Scenario s = sim::load_scenario(scenario_path("ship_tms_rov"));
  s.duration = 100;
  const fs::path out = out_dir("tms");
  const sim::FleetRunSummary r = sim::run_fleet(s, scenario_path("ship_tms_rov"), out.string());
  CHECK(r.simulated_s == Approx(100.0));
  CHECK(r.explicit_fallbacks == 0);
  const Csv c = read_csv(out / "timeseries.csv");
  const auto& last = c.rows.back();
  // The winch paid the ROV's tether out from 15 m to its 30 m limit (0.2 m/s for 75 s).
  CHECK(c.rows.front()[std::size_t(c.column("tether.length"))] == Approx(15.0));
  CHECK(last[std::size_t(c.column("tether.length"))] == Approx(30.0));
  // The sheave carries the TMS's and the umbilical's submerged weight (plus the little the
  // current and the ROV's tether add): (1200 − 1025·0.5) g + (1.5 − 1025·π·0.015²) g · 60.
  const double g = 9.80665;
  const double weight = (1200 - 1025 * 0.5) * g + (1.5 - 1025 * M_PI * 0.015 * 0.015) * g * 60;
  double mean = 0;
  int n = 0;
  for (const auto& row : c.rows)
    if (row[0] >= 60) {
      mean += row[std::size_t(c.column("umbilical.tension_start"))];
      ++n;
    }
  mean /= n;
  INFO("sheave load " << mean << " N, submerged weight " << weight << " N");
  CHECK(mean == Approx(weight).epsilon(0.03));
  // The TMS hangs 60 m (a little stretched) below the sheave at 8 m above the water, set off
  // by the 0.3 m/s current by about a metre.
  const double x = last[std::size_t(c.column("tms.x"))], y = last[std::size_t(c.column("tms.y"))];
  CHECK(std::hypot(x, y) < 3.0);
  CHECK(last[std::size_t(c.column("tms.z"))] == Approx(52.0).margin(0.2));
  // The ROV flies its survey at 54 m.
  CHECK(last[std::size_t(c.column("rov.z"))] == Approx(54.0).margin(0.5));
  // nodes.csv: every node of both lines at 1 Hz.
  std::ifstream nodes(out / "nodes.csv");
  std::string header;
  std::getline(nodes, header);
  CHECK(header == "t,tether,node,x,y,z");
  fs::remove_all(out);
}

TEST_CASE("a ROV returns along its tether to its dock on the seabed", "[sim][fleet]") {
  const sim::Scenario s = sim::load_scenario(scenario_path("rov_docking"));
  const fs::path out = out_dir("dock");
  sim::run_fleet(s, scenario_path("rov_docking"), out.string());
  const Csv c = read_csv(out / "timeseries.csv");
  const auto& last = c.rows.back();
  INFO("ROV at " << last[std::size_t(c.column("rov.x"))] << ", "
                 << last[std::size_t(c.column("rov.y"))] << ", "
                 << last[std::size_t(c.column("rov.z"))]);
  CHECK(last[std::size_t(c.column("rov.x"))] == Approx(1.0).margin(0.2));
  CHECK(last[std::size_t(c.column("rov.y"))] == Approx(0.0).margin(0.2));
  CHECK(last[std::size_t(c.column("rov.z"))] == Approx(28.5).margin(0.2));
  // The summary says so.
  std::ifstream in(out / "summary.json");
  const std::string summary((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(summary.find("\"completed\": true") != std::string::npos);
  CHECK(summary.find("\"rov\"") != std::string::npos);
  fs::remove_all(out);
}

TEST_CASE("one boat holds station over two ROVs heading for their piles", "[sim][fleet]") {
  sim::Scenario s = sim::load_scenario(scenario_path("boat_two_rovs"));
  s.duration = 20;
  const fs::path out = out_dir("two");
  sim::run_fleet(s, scenario_path("boat_two_rovs"), out.string());
  const Csv c = read_csv(out / "timeseries.csv");
  const auto& first = c.rows.front();
  const auto& last = c.rows.back();
  const auto at = [&](const std::vector<double>& row, const char* col) {
    return row[std::size_t(c.column(col))];
  };
  // Both ROVs went down towards 8 m and east towards their piles; the boat kept its station.
  for (const char* rov : {"rov_a", "rov_b"}) {
    const std::string r(rov);
    CHECK(at(last, (r + ".x").c_str()) > at(first, (r + ".x").c_str()) + 2.0);
    CHECK(at(last, (r + ".z").c_str()) > 6.5);
  }
  CHECK(std::hypot(at(last, "boat.x"), at(last, "boat.y")) < 3.0);
  CHECK(at(last, "tether_a.tension_end") >= 0.0);
  fs::remove_all(out);
}

TEST_CASE("a Gazebo model flies in a fleet, in the scenario's sea", "[sim][fleet]") {
  // The test's BlueROV2 Heavy SDF (13 kg, 0.01314 m³ of collision box) in still seawater, no
  // controller: ρ V = 13.47 kg > 13 kg, so it rises.
  const std::string text = R"({"duration": 5, "sea": "calm", "fleet": {"vehicles": [
      {"name": "gz", "vehicle": "bluerov2_heavy.sdf", "start": [0, 0, 10]}]}})";
  const std::string file = std::string(KELP_TEST_DATA_DIR) + "/fleet.json";
  const sim::Scenario s = sim::parse_scenario(text, file);
  const sim::FleetWorld w = sim::fleet_world(s, file);
  REQUIRE(w.parameters.vehicles.size() == 1);
  CHECK(w.parameters.vehicles[0].parameters.density == w.environment.water_density());
  // (The file states Gazebo's fresh water; the run says it was replaced.)
  REQUIRE(w.notes.size() == 1);
  CHECK_THAT(w.notes[0], Catch::Contains("/fleet/vehicles/0/vehicle") && Catch::Contains("1000"));
  const fs::path out = out_dir("sdf");
  sim::run_fleet(s, file, out.string());
  const Csv c = read_csv(out / "timeseries.csv");
  const double rise =
      c.rows.front()[std::size_t(c.column("gz.z"))] - c.rows.back()[std::size_t(c.column("gz.z"))];
  INFO("rose " << rise << " m in 5 s");
  CHECK(rise > 0.05);
  CHECK(rise < 2.0);
  fs::remove_all(out);
}

TEST_CASE("bad fleets are refused naming the JSON path", "[sim][fleet][bad_input]") {
  const auto refused = [](const std::string& fleet, const std::string& path) {
    const std::string text = "{\"fleet\": " + fleet + "}";
    INFO(text);
    CHECK_THROWS_WITH(
        [&] {
          const sim::Scenario s = sim::parse_scenario(text, "f.json");
          sim::fleet_world(s, "f.json");
        }(),
        Catch::Contains("f.json: " + path));
  };
  const std::string rov = R"({"name": "rov", "vehicle": "bluerov2_heavy"})";
  refused(R"({"vehicles": []})", "/fleet/vehicles");
  refused(R"({"vehicles": [{"vehicle": "bluerov2_heavy"}]})", "/fleet/vehicles/0");
  refused(R"({"vehicles": [)" + rov + "," + rov + "]}", "/fleet/vehicles/1/name");
  refused(R"({"vehicles": [{"name": "r", "vehicle": "deep_trekker"}]})",
          "/fleet/vehicles/0/vehicle");
  refused(R"({"vehicles": [{"name": "r", "vehicle": "no_such_file.json"}]})",
          "/fleet/vehicles/0/vehicle");
  refused(R"({"vehicles": [{"name": "r", "vehicle": "bluerov2_heavy",
              "controller": {"type": "waypoints"}}]})",
          "/fleet/vehicles/0/controller/waypoints");
  refused(R"({"vehicles": [{"name": "r", "vehicle": "bluerov2_heavy",
              "controller": {"type": "follow", "target": "boat"}}]})",
          "/fleet/vehicles/0/controller/target");
  refused(R"({"vehicles": [)" + rov + R"(], "tethers": [{"name": "t", "from": "rov",
              "to": "dock", "length": 10}]})",
          "/fleet/tethers/0/to");
  refused(R"({"vehicles": [)" + rov + R"(], "anchors": [{"name": "dock",
              "position": [50, 0, 0]}], "tethers": [{"name": "t", "from": "dock",
              "to": "rov", "length": 10}]})",
          "/fleet/tethers/0/length");
  refused(R"({"vehicles": [)" + rov + R"(], "tethers": [{"name": "t", "from": "free",
              "to": "rov", "length": 10, "winch": {}}]})",
          "/fleet/tethers/0/winch");
  refused(R"({"vehicles": [)" + rov + R"(], "colour": 1})", "/fleet/colour");
  // The pair's world refuses a fleet scenario instead of running the pair.
  const sim::Scenario s =
      sim::parse_scenario(R"({"fleet": {"vehicles": [)" + rov + "]}}", "f.json");
  CHECK_THROWS_WITH(sim::world_setup(s, "f.json"), Catch::Contains("f.json: /fleet"));
}
