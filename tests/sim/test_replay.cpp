// The 3-D replay's data (kelp/sim/replay.hpp): a run's replay data holds what the run logged
// (vehicle poses, the tether's nodes and segment tensions; a fleet's every vehicle, point mass,
// anchor and tether), the sea exactly as kelp evaluates it, survives the trip through the page's
// script element, stays small for a long run, and a directory that is not a run is refused
// clearly.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "kelp/core/constants.hpp"
#include "kelp/sim/closed_loop.hpp"
#include "kelp/sim/fleet_run.hpp"
#include "kelp/sim/replay.hpp"
#include "kelp/sim/run_log.hpp"
#include "kelp/sim/scenario.hpp"
#include "kelp/tether/failure.hpp"
#include "sim_test_support.hpp"

namespace ks = kelp::sim;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// A fresh directory under the test's working directory.
fs::path fresh_dir(const std::string& name) {
  const fs::path dir = fs::current_path() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// What the run had at each node snapshot: time, node positions and segment tensions.
struct Snapshot {
  double t;
  kelp::Matrix3X<double> position;
  std::vector<double> tension;
};

// A short run in the moderate sea (waves ramped in over 4 s) logged into `dir`, with its summary,
// recording the vehicle samples and the tether's snapshots as the loop had them.
struct LoggedRun {
  ks::Scenario sc;
  std::vector<ks::LogRow> rows;
  std::vector<kelp::vehicle::VehicleStated> asv, auv;
  std::vector<Snapshot> snapshots;
};

LoggedRun logged_run(const fs::path& dir) {
  LoggedRun r;
  r.sc.sea = ks::Sea::moderate;
  r.sc.duration = 8.0;
  r.sc.segment_length = 1.0;
  r.sc.log_rate = 5.0;
  r.sc.node_rate = 2.0;
  r.sc.start_ramp = 4.0;
  ks::RunLog log(dir);
  ks::ClosedLoopOptions o;
  o.log = &log;
  o.on_sample = [&](const ks::LogRow& row) {
    r.rows.push_back(row);
    r.asv.push_back(*row.asv);
    r.auv.push_back(*row.auv);
  };
  ks::ClosedLoop loop(r.sc, o);
  const auto snap = [&] {
    Snapshot s{loop.time(), loop.state().tether.position, {}};
    const auto& line = loop.model().tether_of(loop.state());
    for (int i = 0; i + 1 < line.nodes(); ++i)
      s.tension.push_back(kelp::tether::segment_axial_force(line, loop.state().tether, i));
    r.snapshots.push_back(s);
  };
  snap();
  while (!loop.done()) {
    loop.step();
    if (loop.steps_taken() % 50 == 0) snap();  // 2 Hz: every 50 steps of 10 ms
  }
  log.close();
  std::ofstream(dir / "summary.json") << kelp_test::json_of(loop.summary()).dump(2) << '\n';
  return r;
}

// The replay data of the run in `dir` (kelp::sim gives it as JSON text).
json replay_data(const fs::path& dir, const ks::ReplayOptions& o = {}) {
  return json::parse(ks::replay_data_json(dir, o));
}

// The JSON inside the script a page gets.
json parse_script(const std::string& script) {
  const std::string prefix = "window.KELP_REPLAY_DATA = ";
  REQUIRE(script.rfind(prefix, 0) == 0);
  REQUIRE(script.back() == ';');
  return json::parse(script.substr(prefix.size(), script.size() - prefix.size() - 1));
}

// ζ evaluated as the page does, from the exported components and the stated formula.
double page_elevation(const json& waves, double x, double y, double t) {
  const json& c = waves["components"];
  double z = 0;
  for (std::size_t j = 0; j < c["amplitude"].size(); ++j) {
    const double b = c["direction"][j];
    z += c["amplitude"][j].get<double>() *
         std::cos(c["k"][j].get<double>() * (x * std::cos(b) + y * std::sin(b)) -
                  c["omega"][j].get<double>() * t + c["phase"][j].get<double>());
  }
  return ks::replay_ramp(t, waves["ramp"]) * z;
}

}  // namespace

TEST_CASE("a run's replay data holds the logged poses, nodes and segment tensions", "[replay]") {
  const fs::path dir = fresh_dir("test_replay_run");
  const LoggedRun run = logged_run(dir);
  const json d = replay_data(dir);
  CHECK(d["format"] == "kelp-replay");
  CHECK(d["version"] == 1);
  CHECK(d["source"] == "kelp-tethered-pair");
  CHECK(d["frame"] == "NED");
  CHECK(d["duration"].get<double>() == Approx(8.0));

  // Vehicles at the log rate (8 s at 5 Hz and t = 0): positions to 1 mm, angles to 1e-4 rad.
  const json& s = d["series"];
  REQUIRE(run.rows.size() == 41);
  REQUIRE(s["t"].size() == run.rows.size());
  for (std::size_t i = 0; i < run.rows.size(); ++i) {
    CHECK(s["t"][i].get<double>() == Approx(run.rows[i].t).margin(1e-6));
    for (int k = 0; k < 3; ++k) {
      const char* axis = k == 0 ? "n" : k == 1 ? "e" : "d";
      CHECK(s["boat"][axis][i].get<double>() == Approx(run.asv[i].position(k)).margin(6e-4));
      CHECK(s["rov"][axis][i].get<double>() == Approx(run.auv[i].position(k)).margin(6e-4));
      CHECK(s["rov_target"][axis][i].get<double>() ==
            Approx(run.rows[i].auv_target(k)).margin(6e-4));
    }
    const Eigen::Vector3d e = kelp::euler_from_quaternion(run.auv[i].attitude);
    CHECK(s["rov"]["yaw"][i].get<double>() == Approx(e.z()).margin(6e-5));
    CHECK(s["tension_rov"][i].get<double>() == Approx(run.rows[i].tension_auv).margin(6e-3));
    REQUIRE(s["rov_thrust"][i].size() == 8);
    CHECK(s["rov_thrust"][i][3].get<double>() == Approx(run.rows[i].auv_thrust(3)).margin(6e-3));
    REQUIRE(s["boat_command"][i].size() == 2);
  }

  // The tether at the node rate: every node's position, every segment's axial tension.
  const json& n = d["nodes"];
  REQUIRE(n["t"].size() == run.snapshots.size());
  REQUIRE(run.snapshots.size() == 17);
  double peak = 0;
  for (std::size_t k = 0; k < run.snapshots.size(); ++k) {
    const Snapshot& snap = run.snapshots[k];
    CHECK(n["t"][k].get<double>() == Approx(snap.t).margin(1e-6));
    REQUIRE(n["position"][k].size() == 3 * static_cast<std::size_t>(snap.position.cols()));
    REQUIRE(n["tension"][k].size() == snap.tension.size());
    for (Eigen::Index i = 0; i < snap.position.cols(); ++i)
      for (int c = 0; c < 3; ++c)
        CHECK(n["position"][k][3 * static_cast<std::size_t>(i) + c].get<double>() ==
              Approx(snap.position(c, i)).margin(6e-4));
    for (std::size_t i = 0; i < snap.tension.size(); ++i) {
      CHECK(n["tension"][k][i].get<double>() ==
            Approx(std::max(0.0, snap.tension[i])).margin(6e-3 + 1e-5 * snap.tension[i]));
      peak = std::max(peak, snap.tension[i]);
    }
  }
  // The tether pulls in a moderate sea, and the legend's top is the run's largest tension.
  CHECK(peak > 1.0);
  CHECK(d["tension_scale"]["min"] == 0.0);
  CHECK(d["tension_scale"]["max"].get<double>() == Approx(peak).margin(0.011));

  // The default survey: a square at the mission depth from the ROV's start.
  REQUIRE(d["waypoints"].size() == 4);
  CHECK(d["waypoints"][0][2].get<double>() == run.sc.depth);
  CHECK(d["seabed"].is_null());
  CHECK(d["obstacles"].empty());
}

TEST_CASE("the replay's sea is kelp's: elevation_check and the exported formula", "[replay]") {
  const fs::path dir = fresh_dir("test_replay_sea");
  const LoggedRun run = logged_run(dir);
  const json d = replay_data(dir);
  const ks::WorldSetup world = ks::world_setup(run.sc, "test");
  const auto& env = world.environment;
  const json& w = d["waves"];
  REQUIRE(w["components"]["amplitude"].size() == env.waves().size());
  REQUIRE(env.waves().size() == 64);
  CHECK(w["ramp"].get<double>() == 4.0);
  const json& check = d["elevation_check"];
  REQUIRE(check.size() == 50);
  int in_ramp = 0;
  double largest = 0;
  for (const auto& c : check) {
    const double x = c[0], y = c[1], t = c[2], z = c[3];
    // kelp's own value, bit for bit, and the page's formula from the exported components.
    CHECK(z == env.surface_elevation(x, y, t));
    CHECK(page_elevation(w, x, y, t) == Approx(z).margin(1e-9));
    in_ramp += t < 4.0;
    largest = std::max(largest, std::abs(z));
  }
  CHECK(in_ramp >= 5);    // the ramp is checked too
  CHECK(largest > 0.05);  // a real sea (Hs 1.2 m), not zeros
  // The ramp as kelp has it.
  double rate = 0;
  for (double t : {-1.0, 0.0, 1.0, 2.0, 3.999, 4.0, 9.0})
    CHECK(ks::replay_ramp(t, 4.0) == env.ramp_factor(t, rate));

  // Through the page's script, every wave number and check value comes back bit for bit.
  const json back = parse_script(ks::replay_script(d.dump()));
  CHECK(back["waves"] == d["waves"]);
  CHECK(back["elevation_check"] == d["elevation_check"]);
  CHECK(back["nodes"] == d["nodes"]);
  // A NaN (the ROV's target when an autopilot flies it) is written as null.
  json nan = {{"x", std::numeric_limits<double>::quiet_NaN()}};
  CHECK(parse_script(ks::replay_script(nan.dump()))["x"].is_null());
}

TEST_CASE("no string of the data can end the page's script element", "[replay]") {
  const std::string evil = "</script><script>alert(1)</script><!-- </SCRIPT ";
  json d = {{"title", evil}, {"obstacles", {{{"type", "box"}, {"name", evil}}}}};
  const std::string tmpl = "<html><script>/*@KELP_DATA@*/</script></html>";
  const std::string html = ks::replay_html(tmpl, d.dump());
  // Exactly the template's one closing tag, and no comment opener.
  std::size_t closes = 0;
  for (std::size_t at = html.find("</"); at != std::string::npos; at = html.find("</", at + 1))
    ++closes;
  CHECK(closes == 2);  // </script> and </html> of the template
  CHECK(html.find("<!--") == std::string::npos);
  const std::string script = html.substr(14, html.size() - 14 - 16);
  CHECK(parse_script(script)["title"] == evil);
  CHECK(parse_script(script)["obstacles"][0]["name"] == evil);

  // A template without the marker, or with two, is refused.
  CHECK_THROWS_AS(ks::replay_html("<html></html>", d.dump()), ks::replay_error);
  CHECK_THROWS_AS(ks::replay_html(tmpl + tmpl, d.dump()), ks::replay_error);
}

TEST_CASE("a directory that is not a run is refused, naming what it lacks", "[replay]") {
  const fs::path dir = fresh_dir("test_replay_not_a_run");
  CHECK_THROWS_WITH(replay_data(dir / "missing"), Catch::Contains("is not a directory"));
  std::ofstream(dir / "notes.txt") << "hello\n";
  CHECK_THROWS_WITH(replay_data(dir),
                    Catch::Contains("is not a kelp run directory: it has no timeseries.csv"));
  // The CSV files without a summary, then a summary without the scenario, then bad CSV.
  const fs::path run = fresh_dir("test_replay_partial");
  std::ofstream(run / "timeseries.csv") << "t\n0\n";
  std::ofstream(run / "nodes.csv") << "t,node,x,y,z\n0,0,0,0,0\n";
  CHECK_THROWS_WITH(replay_data(run), Catch::Contains("it has no summary.json"));
  std::ofstream(run / "summary.json") << "{\"wall_s\": 1}";
  CHECK_THROWS_WITH(replay_data(run), Catch::Contains("no \"scenario\""));
  std::ofstream(run / "summary.json") << "{\"scenario\": {\"sea\": \"calm\"}}";
  CHECK_THROWS_WITH(replay_data(run), Catch::Contains("no column asv_x"));
  std::ofstream(run / "timeseries.csv") << "t,a\n0,zz\n";
  CHECK_THROWS_WITH(replay_data(run), Catch::Contains("timeseries.csv:2: expected a number"));
  // Every refusal is a kelp::error.
  CHECK_THROWS_AS(replay_data(dir), kelp::error);
  CHECK_THROWS_AS(ks::write_replay(dir, "/no/such/template.html"), ks::replay_error);
}

TEST_CASE("a 10-minute run with 40 nodes at the default rates makes under 10 MB", "[replay]") {
  // A synthetic log of the size of such a run: 600 s at 10 Hz, 40 nodes at 1 Hz, every value
  // moving (no short repeated numbers), written by RunLog as a run writes it.
  const fs::path dir = fresh_dir("test_replay_size");
  ks::Scenario sc;  // moderate sea, the default rates (10 Hz log, 1 Hz nodes)
  sc.duration = 600;
  sc.tether_length = 19.5;  // 39 segments of 0.5 m: 40 nodes
  REQUIRE(sc.log_rate == 10.0);
  REQUIRE(sc.node_rate == 1.0);
  const ks::WorldSetup world = ks::world_setup(sc, "test");
  const kelp::system::SystemModeld model(world.parameters, world.environment);
  kelp::system::SystemWorkspaced ws(model);
  kelp::system::SystemStated state = ks::start_state(model, ws, world, sc);
  const auto& line = model.tether_of(state);
  REQUIRE(line.nodes() == 40);
  {
    ks::RunLog log(dir);
    for (int i = 0; i <= 6000; ++i) {
      const double t = 0.1 * i;
      state.asv.position << 3.1 * std::sin(0.011 * t), 2.7 * std::cos(0.013 * t),
          0.05 * std::sin(1.3 * t);
      state.auv.position << 4.1 * std::cos(0.017 * t), 5.3 * std::sin(0.019 * t),
          5 + 0.2 * std::sin(0.3 * t);
      ks::LogRow row;
      row.t = t;
      row.asv = &state.asv;
      row.auv = &state.auv;
      row.auv_target << 8.123456, 0.5 * t / 600, 5.0;
      row.auv_error = 0.3 + 0.1 * std::sin(t);
      row.asv_error = 1.1 + 0.2 * std::cos(t);
      row.asv_thrust << 10 * std::sin(t), 10 * std::cos(t);
      row.asv_command << 0.3 * std::sin(t), 0.3 * std::cos(t);
      for (int k = 0; k < 8; ++k) {
        row.auv_thrust(k) = 20 * std::sin(t + k);
        row.auv_command(k) = 0.5 * std::sin(t + k);
      }
      row.tension_asv = 5 + std::sin(t);
      row.tension_auv = 6 + std::cos(t);
      log.row(row);
      if (i % 10 == 0) {
        kelp::tether::TetherStated tether = state.tether;
        for (Eigen::Index k = 0; k < tether.position.cols(); ++k)
          tether.position.col(k) +=
              0.37 * kelp::Vector3<double>(std::sin(t + k), std::cos(t * k), std::sin(0.5 * t * k));
        log.nodes(t, line, tether);
      }
    }
  }
  json summary = {{"scenario", kelp_test::json_of(sc)}, {"scenario_file", "synthetic"}};
  std::ofstream(dir / "summary.json") << summary.dump(2);
  const std::string script = ks::replay_script(ks::replay_data_json(dir));
  const double mb = static_cast<double>(script.size()) / 1e6;
  // The page's template (three.js ~2.1 MB, the page's own code) comes on top: the data must
  // leave it room under 10 MB.
  WARN("replay data of a synthetic 600 s, 40-node run: " << mb << " MB");
  CHECK(mb < 7.0);
  // And it has all the samples.
  const json d = parse_script(script);
  CHECK(d["series"]["t"].size() == 6001);
  CHECK(d["nodes"]["t"].size() == 601);
  CHECK(d["nodes"]["position"][600].size() == 120);
  CHECK(d["nodes"]["tension"][600].size() == 39);
}

TEST_CASE("a run kept by kelp-sweep is told from its place in the sweep", "[replay]") {
  const fs::path src = fresh_dir("test_replay_sweep_src");
  logged_run(src);
  const fs::path sweep = fresh_dir("test_replay_sweep");
  std::ofstream(sweep / "sweep.json") << "{}";
  fs::create_directories(sweep / "runs");
  fs::copy(src, sweep / "runs" / "0123456789abcdef");
  CHECK(replay_data(sweep / "runs" / "0123456789abcdef")["source"] == "kelp-sweep");
  ks::ReplayOptions o;
  o.source = "kelp-sitl";
  o.title = "given";
  const json d = replay_data(src, o);
  CHECK(d["source"] == "kelp-sitl");
  CHECK(d["title"] == "given");
  CHECK(d["waypoints"].empty());  // ArduPilot flies its own mission

  // write_replay: replay.html in the run directory, the template with the same data.
  const std::string tmpl = "<html><script>/*@KELP_DATA@*/</script></html>";
  std::ofstream(src / "template.html") << tmpl;
  const fs::path page = ks::write_replay(src, (src / "template.html").string(), o);
  CHECK(page == src / "replay.html");
  std::ifstream in(page, std::ios::binary);
  const std::string html((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(html == ks::replay_html(tmpl, ks::replay_data_json(src, o)));
  CHECK(parse_script(html.substr(14, html.size() - 14 - 16))["title"] == "given");
}

namespace {

// A CSV file as text cells (the fleet's nodes.csv has the tether's name in a column).
std::vector<std::vector<std::string>> csv_cells(const fs::path& file) {
  std::ifstream in(file);
  REQUIRE(in);
  std::vector<std::vector<std::string>> rows;
  std::string line, cell;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::vector<std::string> row;
    while (std::getline(ss, cell, ',')) row.push_back(cell);
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

TEST_CASE("a fleet run's replay data holds every vehicle, point mass, anchor and tether as logged",
          "[replay][fleet]") {
  // The shipped ship - umbilical - TMS - tether - ROV (an anchor, a point mass, a winch that
  // re-meshes its line) for 10 s, with a second ROV from a vehicle file (no model of its own on
  // the page: its hull box) hanging free on no line.
  const std::string file = std::string(KELP_SCENARIO_DIR) + "/ship_tms_rov.json";
  ks::Scenario sc = ks::load_scenario(file);
  sc.duration = 10;
  ks::FleetVehicleScenario extra;
  extra.name = "rov_file";
  extra.vehicle = std::string(KELP_VEHICLE_DIR) + "/bluerov2_heavy.json";
  extra.start = kelp::Vector3<double>(-6, 4, 30);
  sc.fleet->vehicles.push_back(extra);
  const fs::path dir = fresh_dir("test_replay_fleet");
  ks::run_fleet(sc, file, dir.string());
  const json d = replay_data(dir);
  CHECK(d["format"] == "kelp-replay");
  CHECK(d["version"] == 2);  // not the pair's version 1: no boat, no ROV, no single tether
  CHECK(d["source"] == "kelp-tethered-pair");
  CHECK(d["frame"] == "NED");
  CHECK(d["duration"].get<double>() == Approx(10.0));
  CHECK_THAT(d["title"].get<std::string>(), Catch::Contains("ship_tms_rov.json"));

  // The time series against timeseries.csv, column by column.
  const auto ts = csv_cells(dir / "timeseries.csv");
  REQUIRE(ts.size() == 102);  // the header, 10 s at 10 Hz and t = 0
  const auto column = [&](const std::string& name) {
    const auto& h = ts.front();
    const auto it = std::find(h.begin(), h.end(), name);
    REQUIRE(it != h.end());
    std::vector<double> v;
    for (std::size_t r = 1; r < ts.size(); ++r)
      v.push_back(std::stod(ts[r][static_cast<std::size_t>(it - h.begin())]));
    return v;
  };
  const auto same = [&](const json& a, const std::vector<double>& logged, double margin,
                        const std::string& what) {
    INFO(what);
    REQUIRE(a.size() == logged.size());
    for (std::size_t i = 0; i < logged.size(); ++i)
      CHECK(a[i].get<double>() == Approx(logged[i]).margin(margin));
  };
  same(d["series"]["t"], column("t"), 1e-6, "t");

  // Every vehicle: name, model, hull box and pose (positions to 1 mm, angles to 1e-4 rad).
  REQUIRE(d["vehicles"].size() == 2);
  const auto hull = kelp::system::bluerov2_heavy_hull<double>();
  for (const json& v : d["vehicles"]) {
    const std::string name = v["name"];
    CHECK(v["model"] == (name == "rov" ? "bluerov2_heavy" : "box"));
    REQUIRE(v["hull"].is_object());  // the preset's, and the vehicle file's from the summary
    for (int k = 0; k < 3; ++k)
      CHECK(v["hull"]["half_extents"][k].get<double>() == hull.half_extents(k));
    const char* ned[] = {"n", "e", "d"};
    const char* xyz[] = {".x", ".y", ".z"};
    for (int k = 0; k < 3; ++k) same(v[ned[k]], column(name + xyz[k]), 6e-4, name + xyz[k]);
    for (const char* a : {"roll", "pitch", "yaw"}) same(v[a], column(name + "." + a), 6e-5, a);
  }
  CHECK(d["vehicles"][0]["waypoints"].size() == 6);  // the survey's
  CHECK(d["vehicles"][1]["waypoints"].empty());      // no controller

  // The point mass: a sphere of its 0.5 m³, where it was.
  REQUIRE(d["point_masses"].size() == 1);
  const json& tms = d["point_masses"][0];
  CHECK(tms["name"] == "tms");
  CHECK(tms["diameter"].get<double>() == Approx(std::cbrt(6 * 0.5 / kelp::pi)).margin(6e-4));
  same(tms["n"], column("tms.x"), 6e-4, "tms.x");
  same(tms["e"], column("tms.y"), 6e-4, "tms.y");
  same(tms["d"], column("tms.z"), 6e-4, "tms.z");

  // The anchor: the ship's sheave.
  REQUIRE(d["anchors"].size() == 1);
  CHECK(d["anchors"][0]["name"] == "ship");
  CHECK(d["anchors"][0]["position"] == json::array({0.0, 0.0, -8.0}));

  // Every tether: its ends, end forces, length, and every node of every snapshot of nodes.csv.
  REQUIRE(d["tethers"].size() == 2);
  const auto nodes = csv_cells(dir / "nodes.csv");
  REQUIRE(nodes.front() == std::vector<std::string>{"t", "tether", "node", "x", "y", "z"});
  double largest = 0;
  for (const json& l : d["tethers"]) {
    const std::string name = l["name"];
    CHECK(l["from"] == (name == "umbilical" ? "ship" : "tms"));
    CHECK(l["to"] == (name == "umbilical" ? "tms" : "rov"));
    for (const std::string c : {"tension_start", "tension_end"}) {
      same(l[c], column(name + "." + c), 6e-3, name + "." + c);
      for (double v : column(name + "." + c)) largest = std::max(largest, v);
    }
    same(l["length"], column(name + ".length"), 6e-4, name + ".length");
    // nodes.csv's rows of this line, snapshot by snapshot
    std::vector<double> times;
    std::vector<std::vector<double>> snapshots;
    for (std::size_t r = 1; r < nodes.size(); ++r) {
      if (nodes[r][1] != name) continue;
      if (nodes[r][2] == "0") {
        times.push_back(std::stod(nodes[r][0]));
        snapshots.emplace_back();
      }
      for (int k = 3; k < 6; ++k) snapshots.back().push_back(std::stod(nodes[r][std::size_t(k)]));
    }
    REQUIRE(times.size() == 11);  // 1 Hz
    same(l["nodes"]["t"], times, 1e-6, name + " snapshot times");
    REQUIRE(l["nodes"]["position"].size() == snapshots.size());
    for (std::size_t k = 0; k < snapshots.size(); ++k)
      same(l["nodes"]["position"][k], snapshots[k], 6e-4, name + " nodes");
    // The umbilical hangs from the anchor to the TMS: its first node at the sheave, its last at
    // the TMS's logged position (a snapshot every tenth log row).
    if (name == "umbilical") {
      const json& last = l["nodes"]["position"].back();
      const std::size_t n = last.size();
      CHECK(last[0].get<double>() == Approx(0.0).margin(1e-3));
      CHECK(last[2].get<double>() == Approx(-8.0).margin(1e-3));
      CHECK(last[n - 1].get<double>() == Approx(column("tms.z").back()).margin(1e-3));
    } else {  // the winch paid out 2 m: 4 more nodes of 0.5 m
      CHECK(l["nodes"]["position"].back().size() > l["nodes"]["position"].front().size());
    }
  }
  CHECK(d["tension_scale"]["max"].get<double>() >= largest);
  CHECK(d["tension_scale"]["max"].get<double>() <= largest + 0.01 + 1e-9);

  // The sea: the rough sea's components, kelp's own elevation samples match the formula; no
  // seabed, no obstacles in this scenario.
  CHECK(d["waves"]["components"]["amplitude"].size() > 10);
  REQUIRE(d["elevation_check"].size() == 50);
  for (const json& e : d["elevation_check"])
    CHECK(page_elevation(d["waves"], e[0], e[1], e[2]) == Approx(e[3].get<double>()).margin(1e-9));
  CHECK(d["seabed"].is_null());
  CHECK(d["obstacles"].empty());

  // An older fleet summary without the echoed scenario reads the scenario file it names, and
  // says what is missing when that file is gone.
  json summary;
  std::ifstream(dir / "summary.json") >> summary;
  summary.erase("scenario_echo");
  summary["scenario"] = (dir / "gone.json").string();
  std::ofstream(dir / "summary.json") << summary.dump(2);
  CHECK_THROWS_AS(replay_data(dir), ks::replay_error);
  CHECK_THROWS_WITH(replay_data(dir), Catch::Contains("scenario_echo") &&
                                          Catch::Contains("gone.json cannot be read"));
}

TEST_CASE("a fleet's seabed and obstacles are the scenario's", "[replay][fleet]") {
  const std::string file = std::string(KELP_SCENARIO_DIR) + "/boat_two_rovs.json";
  ks::Scenario sc = ks::load_scenario(file);
  sc.duration = 2;
  const fs::path dir = fresh_dir("test_replay_fleet_piles");
  ks::run_fleet(sc, file, dir.string());
  const json d = replay_data(dir);
  REQUIRE(d["vehicles"].size() == 3);
  CHECK(d["vehicles"][0]["model"] == "blueboat");
  CHECK(d["vehicles"][0]["hull"]["half_extents"][0].get<double>() == 0.6);
  CHECK(d["point_masses"].empty());
  CHECK(d["anchors"].empty());
  CHECK(d["tethers"].size() == 2);
  CHECK(d["seabed"]["depth"].get<double>() == 20.0);
  REQUIRE(d["obstacles"].size() == 2);
  CHECK(d["obstacles"][0]["type"] == "cylinder");
  CHECK(d["obstacles"][0]["name"] == "pile_a");
}
