// Obstacles and the seabed in scenario files (kelp/sim/scenario.hpp): parsing, errors naming the
// JSON path, to_json reading back to the same obstacles, and world_setup handing them to the
// environment the tether steps in.
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <string>

#include "kelp/sim/scenario.hpp"
#include "kelp/sim/world.hpp"
#include "sim_test_support.hpp"

namespace ks = kelp::sim;

namespace {
const char* const kScenario = R"({
  "obstacles": [
    {"type": "cylinder", "name": "pile", "from": [4, 2, 0], "to": [4, 2, 30], "radius": 0.4,
     "friction": 0.3},
    {"type": "box", "name": "frame", "center": [10, -3, 28], "half_extents": [2, 1, 1],
     "yaw": 0.5, "stiffness": 1e6, "damping": 1e4},
    {"type": "cylinder", "from": [0, 0, 20], "to": [20, 0, 30], "radius": 0.05}
  ],
  "seabed": {"heightfield": {"origin": [-50, -50], "spacing": [50, 50], "size": [3, 3],
                             "depth": [30, 30, 31, 30, 30, 31, 29, 30, 32]},
             "friction": 0.4}
})";
}  // namespace

TEST_CASE("scenario obstacles and seabed: parsed, echoed and handed to the environment",
          "[sim][obstacles]") {
  const ks::Scenario s = ks::parse_scenario(kScenario, "obstacles.json");
  REQUIRE(s.cylinders.size() == 2);
  REQUIRE(s.boxes.size() == 1);
  CHECK(s.cylinders[0].name == "pile");
  CHECK(s.cylinders[0].contact.friction == 0.3);
  CHECK(s.cylinders[1].name == "cylinder 2");
  CHECK(s.boxes[0].yaw == 0.5);
  CHECK(s.boxes[0].contact.stiffness == 1e6);
  REQUIRE(s.heightfield.has_value());
  CHECK(s.heightfield->at(2, 2) == 32);
  CHECK(s.seabed_friction.value_or(-1) == 0.4);
  // to_json reads back to the same scenario.
  const nlohmann::json j = kelp_test::json_of(s);
  const ks::Scenario back = ks::parse_scenario(j.dump(), "echo.json");
  CHECK(kelp_test::json_of(back) == j);
  CHECK(back.cylinders[1].to == s.cylinders[1].to);
  REQUIRE(back.heightfield.has_value());
  CHECK(back.heightfield->depth == s.heightfield->depth);
  // The world's environment carries them; the tether's seabed friction is the scenario's.
  const ks::WorldSetup w = ks::world_setup(s, "obstacles.json");
  REQUIRE(w.environment.obstacles() != nullptr);
  CHECK(w.environment.obstacles()->size() == 3);
  CHECK(w.environment.obstacles()->seabed() != nullptr);
  CHECK(w.parameters.tether.seabed_friction == 0.4);
  // Without obstacles: none in the environment, none in the echo.
  const ks::Scenario plain = ks::parse_scenario("{}", "plain.json");
  CHECK(ks::world_setup(plain, "plain.json").environment.obstacles() == nullptr);
  CHECK(!kelp_test::json_of(plain).contains("obstacles"));
  CHECK(!kelp_test::json_of(plain).contains("seabed"));
  const ks::Scenario flat = ks::parse_scenario(R"({"seabed": {"depth": 40}})", "flat.json");
  CHECK(ks::world_setup(flat, "flat.json").environment.seabed_depth() == 40);
}

TEST_CASE("scenario seabed from a grid file beside the scenario", "[sim][obstacles]") {
  std::ofstream("kelp_test_bathymetry.txt")
      << "2 2\n0 10\n0 10\n0 0 20\n0 10 21\n10 0 22\n10 10 23\n";
  std::ofstream("kelp_test_scenario_hf.json")
      << R"({"seabed": {"heightfield": "kelp_test_bathymetry.txt"}})";
  const ks::Scenario s = ks::load_scenario("kelp_test_scenario_hf.json");
  REQUIRE(s.heightfield.has_value());
  CHECK(s.heightfield->at(1, 1) == 23);
  CHECK(kelp_test::json_of(s)["seabed"]["heightfield"] == "kelp_test_bathymetry.txt");
}

TEST_CASE("scenario obstacles: errors name the JSON path", "[sim][obstacles]") {
  const auto fails = [](const std::string& text, const std::string& what) {
    CHECK_THROWS_AS(ks::parse_scenario(text, "bad.json"), ks::scenario_error);
    CHECK_THROWS_WITH(ks::parse_scenario(text, "bad.json"), Catch::Matchers::Contains(what));
  };
  fails(R"({"obstacles": {}})", "/obstacles: expected an array");
  fails(R"({"obstacles": [{"type": "cone"}]})", "/obstacles/0/type");
  fails(R"({"obstacles": [{"type": "cylinder", "from": [0,0,0], "radius": 1}]})", "missing \"to\"");
  fails(R"({"obstacles": [{"type": "cylinder", "from": [0,0,0], "to": [0,0,0], "radius": 1}]})",
        "/obstacles/0: cylinder 'cylinder 0': from and to must differ");
  fails(R"({"obstacles": [{"type": "cylinder", "from": [0,0,0], "to": [0,0,1], "radius": -1}]})",
        "/obstacles/0/radius");
  fails(R"({"obstacles": [{"type": "box", "center": [0,0,0], "half_extents": [1,0,1]}]})",
        "half_extents");
  fails(R"({"obstacles": [{"type": "box", "name": "a", "center": [0,0,0], "half_extents": [1,1,1]},
                          {"type": "box", "name": "a", "center": [5,0,0], "half_extents": [1,1,1]}]})",
        "/obstacles/1/name");
  fails(
      R"({"obstacles": [{"type": "box", "center": [0,0,0], "half_extents": [1,1,1], "friction": -1}]})",
      "/obstacles/0/friction");
  fails(R"({"seabed": {"depth": 30, "heightfield": "x.txt"}})", "not both");
  fails(R"({"seabed": {"heightfield": "kelp_test_no_such_grid.txt"}})",
        "/seabed/heightfield: heightfield file 'kelp_test_no_such_grid.txt': cannot open");
  fails(
      R"({"seabed": {"heightfield": {"origin": [0,0], "spacing": [1,1], "size": [2,2], "depth": [1,2,3]}}})",
      "/seabed/heightfield/depth");
}
