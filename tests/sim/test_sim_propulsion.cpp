// kelp::sim with propulsion: the scenario's "thrusters" and "battery" keys (parsed, echoed,
// checked, reaching the system), the controllers' commands driving the thrusters, the log's
// battery columns and the summary's energy per vehicle.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "kelp/sim.hpp"
#include "sim_test_support.hpp"

namespace ks = kelp::sim;

namespace {
using kelp_test::short_calm_run;
}  // namespace

TEST_CASE("scenario: thrusters and battery keys are parsed, echoed, checked and applied",
          "[sim][propulsion]") {
  const ks::Scenario d;
  CHECK(d.propulsion);
  CHECK(d.thruster_lag);
  const auto p0 = ks::world_setup(d, "default").parameters;
  REQUIRE(p0.auv_propulsion.has_value());
  REQUIRE(p0.asv_propulsion.has_value());
  CHECK(p0.auv_propulsion->time_constant == 0.02);
  CHECK(p0.auv_propulsion->battery.capacity_ah == 15.6);
  CHECK(p0.asv_propulsion->battery.capacity_ah == 31.2);

  const ks::Scenario s = ks::parse_scenario(
      R"({"thrusters": {"lag": true, "time_constant": 0.05},
          "battery": {"auv": {"capacity_ah": 18, "initial_soc": 0.5, "hotel_current": 1.5},
                      "asv": {"internal_resistance": 0.03, "cells_in_series": 4}}})",
      "p.json");
  CHECK(s.thruster_time_constant == 0.05);
  CHECK(s.auv_battery.capacity_ah == 18);
  CHECK(s.auv_battery.initial_soc == 0.5);
  CHECK(s.asv_battery.internal_resistance == 0.03);
  const auto p = ks::world_setup(s, "p.json").parameters;
  CHECK(p.auv_propulsion->time_constant == 0.05);
  CHECK(p.auv_propulsion->battery.capacity_ah == 18);
  CHECK(p.auv_propulsion->battery.hotel_current == 1.5);
  CHECK(p.asv_propulsion->battery.internal_resistance == 0.03);
  // The echo reads back to the same scenario.
  const ks::Scenario e = ks::parse_scenario(kelp_test::json_of(s).dump(), "echo");
  CHECK(e.thruster_time_constant == 0.05);
  CHECK(e.auv_battery.hotel_current == 1.5);
  CHECK(e.asv_battery.internal_resistance == 0.03);
  // Lag off: time constant 0; propulsion off: no propulsion model.
  const ks::Scenario nolag = ks::parse_scenario(R"({"thrusters": {"lag": false}})", "n.json");
  CHECK(ks::world_setup(nolag, "n.json").parameters.auv_propulsion->time_constant == 0.0);
  const ks::Scenario off = ks::parse_scenario(R"({"thrusters": {"propulsion": false}})", "o.json");
  CHECK_FALSE(ks::world_setup(off, "o.json").parameters.auv_propulsion.has_value());
  // Errors name the path.
  CHECK_THROWS_WITH(ks::parse_scenario(R"({"thrusters": {"time_constant": -1}})", "b.json"),
                    Catch::Contains("b.json: /thrusters/time_constant"));
  CHECK_THROWS_WITH(ks::parse_scenario(R"({"battery": {"auv": {"initial_soc": 2}}})", "b.json"),
                    Catch::Contains("/battery/auv/initial_soc"));
  CHECK_THROWS_WITH(ks::parse_scenario(R"({"battery": {"rov": {}}})", "b.json"),
                    Catch::Contains("/battery/rov"));
  CHECK_THROWS_WITH(ks::parse_scenario(R"({"battery": {"asv": {"volts": 12}}})", "b.json"),
                    Catch::Contains("/battery/asv/volts"));
  CHECK_THROWS_AS(ks::parse_scenario(R"({"thrusters": {"lag": 1}})", "b.json"), ks::scenario_error);
}

TEST_CASE(
    "closed loop with propulsion: the commands drive the thrusters, the log and the "
    "summary report the batteries",
    "[sim][propulsion]") {
  const std::filesystem::path dir = "sim_propulsion_log";
  std::filesystem::remove_all(dir);
  ks::SimulateOptions o;
  o.log_dir = dir.string();
  const nlohmann::json s = kelp_test::json_of(ks::simulate(short_calm_run(), o));
  CHECK(s.at("auv").at("energy_wh").get<double>() > 0.0);
  CHECK(s.at("asv").at("energy_wh").get<double>() > 0.0);
  const double soc = s.at("auv").at("final_soc").get<double>();
  CHECK(soc < 1.0);
  CHECK(soc > 0.9);
  // The energy is the charge drawn at ~15-17 V: SoC × capacity.
  const double charge_ah = (1.0 - soc) * 15.6;
  CHECK(s.at("auv").at("energy_wh").get<double>() / charge_ah > 14.0);
  CHECK(s.at("auv").at("energy_wh").get<double>() / charge_ah < 17.0);
  // The log's battery columns.
  std::ifstream in(dir / "timeseries.csv");
  std::string header, row, last;
  std::getline(in, header);
  for (const char* c : {"asv_voltage", "asv_soc", "asv_current_port", "asv_current_starboard",
                        "auv_voltage", "auv_soc", "auv_current_1", "auv_current_8"})
    CHECK(header.find(c) != std::string::npos);
  while (std::getline(in, row)) last = row;
  // Every propulsion column of the last row holds a number (the winch's columns are nan without
  // a winch, so the row as a whole may hold some).
  const auto field = [](const std::string& line, std::size_t k) {
    std::size_t b = 0;
    for (std::size_t i = 0; i < k; ++i) b = line.find(',', b) + 1;
    return line.substr(b, line.find(',', b) - b);
  };
  const auto& columns = ks::timeseries_columns();
  for (std::size_t k = 0; k < columns.size(); ++k)
    if (columns[k].find("_voltage") != std::string::npos ||
        columns[k].find("_soc") != std::string::npos ||
        columns[k].find("_current_") != std::string::npos)
      CHECK(field(last, k).find("nan") == std::string::npos);

  // Without propulsion, the summary has no battery and the run differs.
  ks::Scenario off = short_calm_run();
  off.propulsion = false;
  const nlohmann::json s_off = kelp_test::json_of(ks::simulate(off));
  CHECK_FALSE(s_off.at("auv").contains("energy_wh"));
  CHECK(s_off.at("auv").at("rms_path_error_m") != s.at("auv").at("rms_path_error_m"));

  // Stepped by hand: after the first controller update, the ROV's thrusters carry the commands'
  // thrust (with the lag) and draw current.
  ks::ClosedLoop loop(short_calm_run());
  loop.run_for(1.0);
  const auto& x = loop.state().auv_propulsion;
  CHECK(x.current.sum() > 0.0);
  CHECK(x.thrust.cwiseAbs().sum() > 0.0);
  CHECK(loop.sample().auv_voltage == x.battery.voltage);
}
