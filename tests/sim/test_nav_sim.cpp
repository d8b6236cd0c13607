// The scenario's navigation object (defaults, every key, errors naming the JSON path, the JSON
// echo) and the closed loop flown on the sensors' estimates: the filters converge and their
// error stays bounded in the moderate sea, the same seed gives the same run and another seed
// another, "perfect" is the run as before, and a step allocates nothing.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>

#include "../support/heap_counter.hpp"
#include "kelp/sim.hpp"
#include "sim_test_support.hpp"

namespace ks = kelp::sim;

namespace {

std::string sensors_run(double duration, int seed, const std::string& extra = "") {
  return R"({"duration": )" + std::to_string(duration) +
         R"(, "navigation": {"mode": "sensors", "seed": )" + std::to_string(seed) + extra + "}}";
}

}  // namespace

TEST_CASE("scenario navigation: perfect by default, every sensor's key read", "[nav][scenario]") {
  const ks::Scenario d = ks::parse_scenario("{}", "t.json");
  CHECK(d.navigation.mode == ks::NavigationMode::perfect);
  CHECK_FALSE(
      kelp_test::json_of(d).contains("navigation"));  // the default leaves the echo as it was
  const ks::Scenario s = ks::parse_scenario(R"({"navigation": {"mode": "sensors", "seed": 9,
      "imu": {"rate": 50, "gyro_noise_density": 1e-4, "gyro_bias_walk": 2e-5,
              "gyro_bias_initial": 0.01, "accel_noise_density": 2e-3, "accel_bias_walk": 1e-3,
              "accel_bias_initial": 0.02},
      "depth": {"rate": 10, "noise": 0.01, "bias": 0.2},
      "dvl": {"bottom_rate": 8, "water_rate": 1, "min_altitude": 0.3, "max_altitude": 30,
              "noise_floor": 0.002, "noise_fraction": 0.02, "water_track": false,
              "water_noise": 0.1, "water_track_distance": 2},
      "compass": {"rate": 10, "noise": 0.02, "bias": 0.05},
      "gps": {"rate": 10, "noise": 0.3, "bias_sigma": 1, "bias_time": 60, "vertical_factor": 1.5},
      "usbl": {"rate": 2, "noise_floor": 0.1, "noise_fraction": 0.02, "latency": 1,
               "dropout": 0.2, "max_range": 50}}})",
                                            "t.json");
  const auto& n = s.navigation;
  CHECK(n.mode == ks::NavigationMode::sensors);
  CHECK(n.seed == 9);
  CHECK(n.sensors.imu.rate == 50);
  CHECK(n.sensors.imu.accel_bias_initial == 0.02);
  CHECK(n.sensors.depth.bias == 0.2);
  CHECK(n.sensors.dvl.max_altitude == 30);
  CHECK_FALSE(n.sensors.dvl.water_track);
  CHECK(n.sensors.compass.bias == 0.05);
  CHECK(n.sensors.gps.vertical_factor == 1.5);
  CHECK(n.sensors.usbl.latency == 1);
  CHECK(n.sensors.usbl.max_range == 50);
  // The echo reads back to the same settings.
  const ks::Scenario back = ks::parse_scenario(kelp_test::json_of(s).dump(), "echo");
  CHECK(kelp_test::json_of(back) == kelp_test::json_of(s));
}

TEST_CASE("scenario navigation: bad values name their JSON path", "[nav][scenario][errors]") {
  const auto fails = [](const std::string& nav, const std::string& path) {
    CHECK_THROWS_WITH(ks::parse_scenario(R"({"navigation": )" + nav + "}", "t.json"),
                      Catch::Contains("t.json: " + path));
  };
  fails(R"({"mode": "dead_reckoning"})", "/navigation/mode");
  fails(R"({"seed": -1})", "/navigation/seed");
  fails(R"({"lidar": {}})", "/navigation/lidar");
  fails(R"({"imu": {"rate": 400}})", "/navigation/imu/rate");
  fails(R"({"imu": {"gyro_noise_density": -1}})", "/navigation/imu/gyro_noise_density");
  fails(R"({"depth": {"noise": "small"}})", "/navigation/depth/noise");
  fails(R"({"dvl": {"min_altitude": 10, "max_altitude": 5}})", "/navigation/dvl/max_altitude");
  fails(R"({"dvl": {"water_track": 1}})", "/navigation/dvl/water_track");
  fails(R"({"compass": {"bias": 4}})", "/navigation/compass/bias");
  fails(R"({"gps": {"bias_time": 0}})", "/navigation/gps/bias_time");
  fails(R"({"usbl": {"dropout": 1}})", "/navigation/usbl/dropout");
  fails(R"({"usbl": {"latency": 10, "rate": 10}})", "/navigation/usbl");
  fails(R"([])", "/navigation");
  CHECK_THROWS_AS(ks::parse_scenario(R"({"navigation": {"usbl": {"rate": 0}}})", "t"),
                  ks::scenario_error);
}

TEST_CASE("closed loop on sensors: the estimates converge and stay bounded in the moderate sea",
          "[nav][sim]") {
  // 60 s of the default run (moderate sea, 0.5 m/s current, no seabed: the DVL water-tracks)
  // with the GPS's slow error off, so that what is measured is the filters' own error.
  ks::Scenario sc = ks::parse_scenario(sensors_run(60, 1, R"(, "gps": {"bias_sigma": 0})"), "t");
  ks::ClosedLoop loop(sc);
  double late_auv = 0, late_asv = 0;
  while (!loop.done()) {
    loop.step();
    if (loop.time() > 30) {
      const auto* n = loop.navigation();
      late_auv = std::max(late_auv, (n->auv().position - loop.state().auv.position).norm());
      late_asv =
          std::max(late_asv, (n->asv().position - loop.state().asv.position).head<2>().norm());
    }
  }
  const nlohmann::json s = kelp_test::json_of(loop.summary())["navigation"];
  INFO(s.dump(1));
  CHECK(s["mode"] == "sensors");
  CHECK(s["dvl_pings"]["water"].get<long>() > 100);
  CHECK(s["dvl_pings"]["bottom"].get<long>() == 0);
  CHECK(s["usbl"]["pings"].get<long>() == 60);
  // Measured (seed 1): ROV 0.38 m RMS, boat 0.26 m RMS horizontally; the bounds leave 2x.
  CHECK(s["auv_rms_position_error_m"].get<double>() < 0.75);
  CHECK(s["asv_rms_horizontal_error_m"].get<double>() < 0.6);
  CHECK(s["auv_rms_heading_error_deg"].get<double>() < 1.0);
  CHECK(s["auv_rms_velocity_error_m_s"].get<double>() < 0.5);
  CHECK(late_auv < 1.5);
  CHECK(late_asv < 1.5);
}

TEST_CASE("closed loop on sensors: the same seed gives the same run, another seed another",
          "[nav][sim]") {
  const auto run = [](int seed) {
    ks::ClosedLoop loop(ks::parse_scenario(sensors_run(5, seed), "t"));
    loop.run();
    return std::make_pair(kelp_test::json_of(loop.summary())["navigation"],
                          loop.state().auv.position);
  };
  const auto a = run(3), b = run(3), c = run(4);
  CHECK(a.first == b.first);
  CHECK(a.second == b.second);
  CHECK(a.first != c.first);
  CHECK(a.second != c.second);
}

TEST_CASE("closed loop, perfect navigation: no sensors, the summary says so", "[nav][sim]") {
  ks::ClosedLoop loop(ks::parse_scenario(R"({"duration": 1})", "t"));
  CHECK(loop.navigation() == nullptr);
  loop.run();
  CHECK(kelp_test::json_of(loop.summary())["navigation"] == nlohmann::json{{"mode", "perfect"}});
}

TEST_CASE("closed loop on sensors: a step allocates nothing", "[nav][sim][malloc]") {
  ks::ClosedLoop loop(ks::parse_scenario(sensors_run(3, 1), "t"));
  loop.run_for(1.0);
  const long before = kelp_test::heap_allocations();  // the whole program's, the library's too
  Eigen::internal::set_is_malloc_allowed(false);
  loop.run_for(1.5);  // USBL fixes, DVL pings and GPS fixes all fall in here
  Eigen::internal::set_is_malloc_allowed(true);
  CHECK(kelp_test::heap_allocations() == before);
  CHECK(loop.navigation()->usbl_fixes() >= 1);
}
