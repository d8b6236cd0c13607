// The 3-D replay of a run (kelp/sim/replay.hpp): the run directory's data as the page's JSON
// (built with nlohmann-json, private to kelp::sim: callers get its text) and replay.html.
#include "kelp/sim/replay.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <unordered_map>
#include <utility>
#include <vector>

#include "kelp/core/constants.hpp"
#include "kelp/sim/scenario.hpp"
#include "kelp/sim/vehicle_file.hpp"
#include "kelp/sim/world.hpp"

namespace kelp {
namespace sim {

namespace detail {
namespace {

// A CSV file of numbers with a header line (`nan` and `inf` read as such).
struct ReplayCsv {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  /// The index of column `name`, or -1.
  int find(const std::string& name) const {
    for (std::size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return static_cast<int>(i);
    return -1;
  }
};

ReplayCsv read_replay_csv(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw replay_error("cannot read " + path.string());
  ReplayCsv csv;
  std::string line;
  if (!std::getline(in, line) || line.empty())
    throw replay_error(path.string() + ": no header line");
  {
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) csv.header.push_back(cell);
  }
  std::size_t number = 1;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty()) continue;
    std::vector<double> row;
    row.reserve(csv.header.size());
    const char* p = line.c_str();
    for (;;) {
      char* end = nullptr;
      const double v = std::strtod(p, &end);
      if (end == p)
        throw replay_error(path.string() + ":" + std::to_string(number) +
                           ": expected a number in column " + std::to_string(row.size() + 1));
      row.push_back(v);
      if (*end == '\0') break;
      if (*end != ',')
        throw replay_error(path.string() + ":" + std::to_string(number) +
                           ": expected ',' after column " + std::to_string(row.size()));
      p = end + 1;
    }
    if (row.size() != csv.header.size())
      throw replay_error(path.string() + ":" + std::to_string(number) + ": " +
                         std::to_string(row.size()) + " values, the header has " +
                         std::to_string(csv.header.size()));
    csv.rows.push_back(std::move(row));
  }
  return csv;
}

// `v` rounded to a multiple of 1/scale (scale a power of ten: the nearest double to the decimal
// k/scale, which JSON writes short); NaN stays NaN (written as null).
double replay_round(double v, double scale) {
  return std::isfinite(v) ? std::round(v * scale) / scale : v;
}

}  // namespace
}  // namespace detail

namespace {

using nlohmann::json;

// The sea's wave components, exactly as kelp evaluates them, and the formula in words.
json waves_json(const kelp::environment::Environmentd& env) {
  const auto& waves = env.waves();
  json a = json::array(), w = json::array(), k = json::array(), b = json::array(),
       phi = json::array();
  for (std::size_t j = 0; j < waves.size(); ++j) {
    a.push_back(waves.amplitude(j));
    w.push_back(waves.omega(j));
    k.push_back(waves.wave_number_of(j));
    b.push_back(waves.direction(j));
    phi.push_back(waves.phase(j));
  }
  return {
      {"components", {{"amplitude", a}, {"omega", w}, {"k", k}, {"direction", b}, {"phase", phi}}},
      {"ramp", env.ramp()},
      {"formula",
       "zeta = ramp(t) * sum_j amplitude_j * cos(k_j * (x * cos(direction_j) + y * "
       "sin(direction_j)) "
       "- omega_j * t + phase_j); ramp(t) = 0.5 * (1 - cos(pi * t / ramp)) for 0 <= t < ramp, 0 "
       "for t < 0, 1 otherwise (and 1 when ramp = 0); x north, y east [m], zeta up [m], "
       "direction: the azimuth the component travels towards, from north, clockwise"}};
}

// `n` samples [x, y, t, zeta] of kelp's own surface elevation over [t_first, t_last] (a fifth of
// them inside the ramp), on a spiral out to 40 m around centre(row) at the log row nearest each
// time (NaN: around the origin): where the page's camera looks.
template <class Centre>
json elevation_check(const kelp::environment::Environmentd& env, double t_first, double t_last,
                     std::size_t rows, int n, Centre&& centre) {
  json check = json::array();
  const double ramp = env.ramp(), span = std::max(0.0, t_last - t_first);
  const int in_ramp = ramp > 0 ? n / 5 : 0;  // a fifth of them inside the ramp
  for (int i = 0; i < n; ++i) {
    double t;
    if (i < in_ramp)
      t = t_first + std::min(ramp, span) * (i + 0.5) / in_ramp;
    else
      t = t_first + span * (i - in_ramp + 0.5) / (n - in_ramp);
    const std::size_t r = std::min(
        rows - 1, static_cast<std::size_t>(std::lround((t - t_first) / std::max(span, 1e-9) *
                                                       static_cast<double>(rows - 1))));
    const double radius = 40.0 * i / std::max(1, n - 1), angle = 2.39996 * i;
    const std::pair<double, double> c = centre(r);
    double x = c.first + radius * std::cos(angle);
    double y = c.second + radius * std::sin(angle);
    if (!std::isfinite(x) || !std::isfinite(y)) x = y = 0;
    check.push_back({x, y, t, env.surface_elevation(x, y, t)});
  }
  return check;
}

// The seabed and obstacles of the scenario `scj` (issue 30's "seabed" and "obstacles", in the
// replay's shape), else the environment's flat seabed.
void seabed_and_obstacles(json& d, const json& scj, const kelp::environment::Environmentd& env) {
  d["seabed"] = nullptr;
  if (scj.contains("seabed") && scj["seabed"].is_object() && scj["seabed"].contains("depth"))
    d["seabed"] = {{"depth", scj["seabed"]["depth"]}};
  else if (std::isfinite(env.seabed_depth()))
    d["seabed"] = {{"depth", env.seabed_depth()}};
  d["obstacles"] = json::array();
  if (scj.contains("obstacles") && scj["obstacles"].is_array())
    for (const auto& ob : scj["obstacles"])
      if (ob.is_object() && ob.contains("type")) d["obstacles"].push_back(ob);
}

// The legend's range: the largest tension, rounded up to 0.01 N (1 N when the line never pulls).
json tension_scale(double tension_max) {
  return {{"min", 0.0}, {"max", tension_max > 0 ? std::ceil(tension_max * 1e2) / 1e2 : 1.0}};
}

// Whether summary.json is a fleet run's (kelp/sim/fleet_run.hpp's run_fleet: its "source", or
// the scenario it echoes as "scenario_echo").
bool fleet_summary(const json& summary) {
  return summary.is_object() &&
         (summary.contains("scenario_echo") ||
          (summary.contains("source") && summary["source"] == "kelp-tethered-pair (fleet)"));
}

// A fleet's nodes.csv (`t,tether,node,x,y,z`): per tether, its snapshots (a new one where the
// node index restarts at 0) as the replay's `t` and `position`. The tether's name is what lies
// between the first comma and the last four, so a name may hold a comma.
std::vector<json> fleet_nodes(const std::filesystem::path& path,
                              const std::vector<std::string>& tethers) {
  std::ifstream in(path);
  if (!in) throw replay_error("cannot read " + path.string());
  std::string line;
  if (!std::getline(in, line) || line != "t,tether,node,x,y,z")
    throw replay_error(path.string() + ": expected the header t,tether,node,x,y,z (a fleet run's)");
  std::vector<json> out(tethers.size());
  for (json& o : out) o = {{"t", json::array()}, {"position", json::array()}};
  std::size_t number = 1;
  const auto bad = [&](const std::string& what) {
    throw replay_error(path.string() + ":" + std::to_string(number) + ": " + what);
  };
  const auto number_of = [&](const std::string& cell) {
    char* end = nullptr;
    const double v = std::strtod(cell.c_str(), &end);
    if (cell.empty() || *end != '\0') bad("expected a number, not \"" + cell + "\"");
    return v;
  };
  while (std::getline(in, line)) {
    ++number;
    if (line.empty()) continue;
    const std::size_t first = line.find(',');
    std::size_t cut[4];  // the last four commas, from the right
    std::size_t at = line.size();
    for (std::size_t& c : cut) {
      c = at == 0 ? std::string::npos : line.rfind(',', at - 1);
      if (c == std::string::npos || c <= first) bad("expected t,tether,node,x,y,z");
      at = c;
    }
    const std::string name = line.substr(first + 1, cut[3] - first - 1);
    const auto k = std::find(tethers.begin(), tethers.end(), name);
    if (k == tethers.end()) bad("\"" + name + "\" is no tether of the run's scenario");
    json& o = out[static_cast<std::size_t>(k - tethers.begin())];
    const double t = number_of(line.substr(0, first));
    const double node = number_of(line.substr(cut[3] + 1, cut[2] - cut[3] - 1));
    if (node == 0.0) {
      o["t"].push_back(detail::replay_round(t, 1e6));
      o["position"].push_back(json::array());
    } else if (o["position"].empty()) {
      bad("a snapshot of \"" + name + "\" does not start at node 0");
    }
    json& p = o["position"].back();
    p.push_back(detail::replay_round(number_of(line.substr(cut[2] + 1, cut[1] - cut[2] - 1)), 1e3));
    p.push_back(detail::replay_round(number_of(line.substr(cut[1] + 1, cut[0] - cut[1] - 1)), 1e3));
    p.push_back(detail::replay_round(number_of(line.substr(cut[0] + 1)), 1e3));
  }
  return out;
}

// The replay data of a fleet run (format version 2, docs/replay.md): every vehicle, point mass,
// anchor and tether of the scenario the summary echoes, at their logged positions.
json fleet_replay_data(const std::filesystem::path& dir, const json& summary,
                       const ReplayOptions& o) {
  namespace fs = std::filesystem;
  const fs::path summary_path = dir / "summary.json";
  // The scenario as run: echoed in the summary (since the fleet's replay), else the scenario
  // file the summary names, when it can still be read (an older fleet run).
  Scenario sc;
  std::string where, file = "(scenario)";
  if (summary.contains("scenario") && summary["scenario"].is_string())
    file = summary["scenario"].get<std::string>();
  if (summary.contains("scenario_echo") && summary["scenario_echo"].is_object()) {
    where = summary_path.string() + ": /scenario_echo";
    sc = parse_scenario(summary["scenario_echo"].dump(), where);
  } else {
    std::error_code ec;
    if (!fs::is_regular_file(file, ec))
      throw replay_error(summary_path.string() +
                         ": a fleet run's summary without \"scenario_echo\" (the scenario as run), "
                         "and its scenario file " +
                         file + " cannot be read: run the scenario again");
    where = file;
    sc = load_scenario(file);
  }
  if (!sc.fleet) throw replay_error(where + ": the scenario has no \"fleet\"");
  const FleetScenario& f = *sc.fleet;
  const auto env = scenario_environment(sc, where);

  json d;
  d["format"] = "kelp-replay";
  d["version"] = 2;
  const std::string source = o.source.empty() ? std::string("kelp-tethered-pair") : o.source;
  d["source"] = source;
  d["frame"] = "NED";

  const fs::path ts_path = dir / "timeseries.csv";
  const detail::ReplayCsv ts = detail::read_replay_csv(ts_path);
  if (ts.rows.empty()) throw replay_error(ts_path.string() + ": no rows");
  const auto col = [&](const std::string& name) {
    const int i = ts.find(name);
    if (i < 0) throw replay_error(ts_path.string() + ": no column " + name);
    return static_cast<std::size_t>(i);
  };
  const auto column = [&](const std::string& name, double scale) {
    const std::size_t c = col(name);
    json a = json::array();
    for (const auto& r : ts.rows) a.push_back(detail::replay_round(r[c], scale));
    return a;
  };
  const double mm = 1e3, rad = 1e4, cN = 1e2, us = 1e6;
  const auto point = [&](const kelp::Vector3<double>& p) {
    return json{detail::replay_round(p.x(), mm), detail::replay_round(p.y(), mm),
                detail::replay_round(p.z(), mm)};
  };
  const double t_first = ts.rows.front()[col("t")], t_last = ts.rows.back()[col("t")];
  d["duration"] = t_last;
  d["series"] = {{"t", column("t", us)}};

  // The vehicles: a preset has its own model on the page; every vehicle has its hull box when
  // known (the summary's, written from the vehicle's file or preset; else a preset's).
  const json no_vehicles = json::object();
  const json& logged_vehicles = summary.contains("vehicles") && summary["vehicles"].is_object()
                                    ? summary["vehicles"]
                                    : no_vehicles;
  const std::vector<std::string> presets = vehicle_preset_names();
  d["vehicles"] = json::array();
  for (const FleetVehicleScenario& v : f.vehicles) {
    json jv;
    jv["name"] = v.name;
    jv["vehicle"] = v.vehicle;
    const bool preset = std::find(presets.begin(), presets.end(), v.vehicle) != presets.end();
    jv["model"] = preset ? v.vehicle : std::string("box");
    jv["hull"] = nullptr;
    const json* hull = nullptr;
    if (logged_vehicles.contains(v.name) && logged_vehicles[v.name].is_object() &&
        logged_vehicles[v.name].contains("hull"))
      hull = &logged_vehicles[v.name]["hull"];
    if (hull != nullptr && hull->is_object() && hull->contains("center_m") &&
        hull->contains("half_extents_m")) {
      jv["hull"] = {{"center", (*hull)["center_m"]}, {"half_extents", (*hull)["half_extents_m"]}};
    } else if (preset) {
      if (const auto& h = vehicle_preset(v.vehicle).hull)
        jv["hull"] = {
            {"center", {h->center.x(), h->center.y(), h->center.z()}},
            {"half_extents", {h->half_extents.x(), h->half_extents.y(), h->half_extents.z()}}};
    }
    json wp = json::array();
    if (v.controller.type == FleetControl::waypoints)
      for (const auto& p : v.controller.waypoints) wp.push_back(point(p));
    jv["waypoints"] = std::move(wp);
    for (const char* k : {"x", "y", "z"})
      jv[k[0] == 'x' ? "n" : k[0] == 'y' ? "e" : "d"] = column(v.name + "." + k, mm);
    for (const char* k : {"roll", "pitch", "yaw"}) jv[k] = column(v.name + "." + k, rad);
    d["vehicles"].push_back(std::move(jv));
  }
  // The point masses: a sphere of their volume (0.3 m across without one).
  d["point_masses"] = json::array();
  for (const FleetPointMassScenario& m : f.point_masses) {
    const double diameter = m.volume > 0 ? std::cbrt(6.0 * m.volume / kelp::pi) : 0.3;
    d["point_masses"].push_back({{"name", m.name},
                                 {"diameter", detail::replay_round(diameter, mm)},
                                 {"n", column(m.name + ".x", mm)},
                                 {"e", column(m.name + ".y", mm)},
                                 {"d", column(m.name + ".z", mm)}});
  }
  d["anchors"] = json::array();
  for (const FleetAnchorScenario& a : f.anchors)
    d["anchors"].push_back({{"name", a.name}, {"position", point(a.position)}});

  // The tethers: their nodes at the node rate, their end forces and length at the log rate. The
  // segments' tensions are not logged for a fleet: the page colours each line between its two
  // end forces.
  std::vector<std::string> names;
  for (const FleetTetherScenario& t : f.tethers) names.push_back(t.name);
  std::vector<json> nodes = fleet_nodes(dir / "nodes.csv", names);
  double tension_max = 0;
  d["tethers"] = json::array();
  for (std::size_t k = 0; k < f.tethers.size(); ++k) {
    const FleetTetherScenario& t = f.tethers[k];
    for (const char* c : {".tension_start", ".tension_end"})
      for (const auto& r : ts.rows) {
        const double v = r[col(t.name + c)];
        if (std::isfinite(v)) tension_max = std::max(tension_max, v);
      }
    d["tethers"].push_back({{"name", t.name},
                            {"from", t.from},
                            {"to", t.to},
                            {"tension_start", column(t.name + ".tension_start", cN)},
                            {"tension_end", column(t.name + ".tension_end", cN)},
                            {"length", column(t.name + ".length", mm)},
                            {"nodes", std::move(nodes[k])}});
  }
  d["tension_scale"] = tension_scale(tension_max);

  // The sea; its check around the middle of the vehicles and point masses at each time.
  d["waves"] = waves_json(env);
  std::vector<std::pair<std::size_t, std::size_t>> bodies;  // their x and y columns
  for (const auto& v : f.vehicles) bodies.emplace_back(col(v.name + ".x"), col(v.name + ".y"));
  for (const auto& m : f.point_masses) bodies.emplace_back(col(m.name + ".x"), col(m.name + ".y"));
  d["elevation_check"] = elevation_check(
      env, t_first, t_last, ts.rows.size(), o.elevation_samples, [&](std::size_t r) {
        double x = 0, y = 0;
        for (const auto& b : bodies) {
          x += ts.rows[r][b.first];
          y += ts.rows[r][b.second];
        }
        const double n = std::max<double>(1.0, static_cast<double>(bodies.size()));
        return std::make_pair(x / n, y / n);
      });
  seabed_and_obstacles(d, json::parse(scenario_json(sc)), env);

  std::string title = o.title;
  if (title.empty()) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.0f s", t_last);
    title = source + " (fleet): " + file + ", " + buf;
  }
  d["title"] = title;
  return d;
}

// The replay data of the run in `dir` (replay_data_json()'s documentation), as a JSON value.
nlohmann::json replay_data(const std::filesystem::path& dir, const ReplayOptions& o) {
  namespace fs = std::filesystem;
  using nlohmann::json;
  KELP_CHECK(o.elevation_samples >= 0, "ReplayOptions::elevation_samples must be >= 0");
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw replay_error(dir.string() + " is not a directory (expected a kelp run directory)");
  for (const char* f : {"timeseries.csv", "nodes.csv", "summary.json"})
    if (!fs::is_regular_file(dir / f, ec))
      throw replay_error(dir.string() + " is not a kelp run directory: it has no " + f +
                         " (kelp-tethered-pair, kelp-sitl and kelp-sweep --keep-series write "
                         "timeseries.csv, nodes.csv and summary.json)");
  json summary;
  {
    std::ifstream in(dir / "summary.json");
    try {
      summary = json::parse(in);
    } catch (const json::exception& e) {
      throw replay_error((dir / "summary.json").string() + ": not JSON (" + e.what() + ")");
    }
  }
  if (fleet_summary(summary)) return fleet_replay_data(dir, summary, o);
  if (!summary.is_object() || !summary.contains("scenario") || !summary["scenario"].is_object())
    throw replay_error((dir / "summary.json").string() +
                       ": no \"scenario\" (the scenario the run used; summaries of kelp 0.1 "
                       "programs echo it)");
  const std::string where = (dir / "summary.json").string() + ": /scenario";
  const Scenario sc = parse_scenario(summary["scenario"].dump(), where);
  const WorldSetup world = world_setup(sc, where);
  const auto& env = world.environment;

  json d;
  d["format"] = "kelp-replay";
  d["version"] = 1;
  std::string source = o.source;
  if (source.empty()) {
    const fs::path abs = fs::absolute(dir, ec);
    const fs::path parent = (abs.filename().empty() ? abs.parent_path() : abs).parent_path();
    if (summary.contains("ardusub"))
      source = "kelp-sitl";
    else if (parent.filename() == "runs" && fs::exists(parent.parent_path() / "sweep.json", ec))
      source = "kelp-sweep";
    else
      source = "kelp-tethered-pair";
  }
  d["source"] = source;
  d["frame"] = "NED";

  // The time series.
  const detail::ReplayCsv ts = detail::read_replay_csv(dir / "timeseries.csv");
  const auto col = [&](const std::string& name) {
    const int i = ts.find(name);
    if (i < 0) throw replay_error((dir / "timeseries.csv").string() + ": no column " + name);
    return static_cast<std::size_t>(i);
  };
  if (ts.rows.empty()) throw replay_error((dir / "timeseries.csv").string() + ": no rows");
  const auto column = [&](const std::string& name, double scale) {
    const std::size_t c = col(name);
    json a = json::array();
    for (const auto& r : ts.rows) a.push_back(detail::replay_round(r[c], scale));
    return a;
  };
  const auto tuples = [&](const std::vector<std::string>& names, double scale) {
    std::vector<std::size_t> cs;
    for (const auto& n : names) cs.push_back(col(n));
    json a = json::array();
    for (const auto& r : ts.rows) {
      json t = json::array();
      for (std::size_t c : cs) t.push_back(detail::replay_round(r[c], scale));
      a.push_back(std::move(t));
    }
    return a;
  };
  const double mm = 1e3, rad = 1e4, cN = 1e2, us = 1e6;
  const auto pose = [&](const std::string& v) {
    return json{{"n", column(v + "_x", mm)},          {"e", column(v + "_y", mm)},
                {"d", column(v + "_z", mm)},          {"roll", column(v + "_roll", rad)},
                {"pitch", column(v + "_pitch", rad)}, {"yaw", column(v + "_yaw", rad)}};
  };
  json series;
  series["t"] = column("t", us);
  series["boat"] = pose("asv");
  series["rov"] = pose("auv");
  series["rov_target"] = {{"n", column("auv_target_x", mm)},
                          {"e", column("auv_target_y", mm)},
                          {"d", column("auv_target_z", mm)}};
  series["rov_error"] = column("auv_error", cN);
  series["boat_error"] = column("asv_error", cN);
  series["tension_boat"] = column("tension_asv", cN);
  series["tension_rov"] = column("tension_auv", cN);
  series["boat_thrust"] = tuples({"asv_thrust_port", "asv_thrust_starboard"}, cN);
  series["boat_command"] = tuples({"asv_command_port", "asv_command_starboard"}, rad);
  std::vector<std::string> thrust, command;
  for (int i = 1; i <= 8; ++i) {
    thrust.push_back("auv_thrust_" + std::to_string(i));
    command.push_back("auv_command_" + std::to_string(i));
  }
  series["rov_thrust"] = tuples(thrust, cN);
  series["rov_command"] = tuples(command, rad);
  const double t_first = ts.rows.front()[col("t")], t_last = ts.rows.back()[col("t")];
  d["duration"] = t_last;

  // The tether: one snapshot per time (a new one where the node index restarts at 0).
  const detail::ReplayCsv nodes = detail::read_replay_csv(dir / "nodes.csv");
  const int nt = nodes.find("t"), nn = nodes.find("node"), nx = nodes.find("x"),
            ny = nodes.find("y"), nz = nodes.find("z"), ntension = nodes.find("tension");
  if (nt < 0 || nn < 0 || nx < 0 || ny < 0 || nz < 0)
    throw replay_error((dir / "nodes.csv").string() + ": expected the columns t,node,x,y,z");
  json node_t = json::array(), node_pos = json::array(), node_tension = json::array();
  double tension_max = 0;
  {
    json pos, ten;
    const auto flush = [&] {
      if (pos.is_null()) return;
      node_pos.push_back(std::move(pos));
      node_tension.push_back(std::move(ten));
      pos = json();
      ten = json();
    };
    for (const auto& r : nodes.rows) {
      if (r[static_cast<std::size_t>(nn)] == 0.0) {
        flush();
        node_t.push_back(detail::replay_round(r[static_cast<std::size_t>(nt)], us));
        pos = json::array();
        ten = json::array();
      } else if (pos.is_null()) {
        throw replay_error((dir / "nodes.csv").string() + ": a snapshot does not start at node 0");
      }
      for (int c : {nx, ny, nz})
        pos.push_back(detail::replay_round(r[static_cast<std::size_t>(c)], mm));
      // The segment starting at this node (none after the last node of a snapshot).
      if (ntension >= 0) {
        const double v = std::max(0.0, r[static_cast<std::size_t>(ntension)]);
        tension_max = std::max(tension_max, std::isfinite(v) ? v : 0.0);
        ten.push_back(detail::replay_round(v, cN));
      }
    }
    flush();
    // nodes.csv has one tension per node; the last node starts no segment.
    for (auto& t : node_tension)
      if (!t.empty() && ntension >= 0) t.erase(t.size() - 1);
  }
  d["nodes"] = {{"t", node_t}, {"position", node_pos}, {"tension", node_tension}};
  if (ntension < 0) d["nodes"]["tension_logged"] = false;  // a run logged before issue 28
  d["series"] = std::move(series);
  // The legend's range: the largest segment tension of the run (or of the end forces when the
  // segments' were not logged).
  if (ntension < 0)
    for (const char* c : {"tension_asv", "tension_auv"})
      for (const auto& r : ts.rows)
        if (std::isfinite(r[col(c)])) tension_max = std::max(tension_max, r[col(c)]);
  d["tension_scale"] = tension_scale(tension_max);

  // The sea, exactly as kelp evaluates it.
  d["waves"] = waves_json(env);
  // Around the boat at each time (where the page's camera looks).
  d["elevation_check"] = elevation_check(
      env, t_first, t_last, ts.rows.size(), o.elevation_samples, [&](std::size_t r) {
        return std::make_pair(ts.rows[r][col("asv_x")], ts.rows[r][col("asv_y")]);
      });
  seabed_and_obstacles(d, summary["scenario"], env);

  // The ROV's waypoints: the scenario's, else ClosedLoop's default square at the mission depth
  // from the start; none for kelp-sitl (ArduPilot flies its own mission).
  json wp = json::array();
  if (source != "kelp-sitl") {
    std::vector<kelp::Vector3<double>> pts = sc.waypoints;
    if (pts.empty()) {
      const kelp::Vector3<double> s0(world.start.auv.position.x(), world.start.auv.position.y(),
                                     sc.depth);
      const double side = sc.square_side;
      pts = {s0 + kelp::Vector3<double>(side, 0, 0), s0 + kelp::Vector3<double>(side, side, 0),
             s0 + kelp::Vector3<double>(0, side, 0), s0};
    }
    for (const auto& p : pts)
      wp.push_back({detail::replay_round(p.x(), mm), detail::replay_round(p.y(), mm),
                    detail::replay_round(p.z(), mm)});
  }
  d["waypoints"] = std::move(wp);

  std::string title = o.title;
  if (title.empty()) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.0f s", t_last);
    title = source + ": " + summary.value("scenario_file", std::string("(scenario)")) + ", " + buf;
  }
  d["title"] = title;
  return d;
}

}  // namespace

double replay_ramp(double t, double ramp) {
  if (!(ramp > 0.0) || t >= ramp) return 1.0;
  if (t < 0.0) return 0.0;
  return 0.5 * (1.0 - std::cos(kelp::pi * t / ramp));
}

std::string replay_data_json(const std::filesystem::path& dir, const ReplayOptions& o) {
  return replay_data(dir, o).dump();
}

std::string replay_script(const std::string& data_json) {
  const std::string& text = data_json;
  std::string out = "window.KELP_REPLAY_DATA = ";
  out.reserve(text.size() + 64);
  for (char c : text) {
    if (c == '<')
      out += "\\u003c";
    else
      out += c;
  }
  out += ";";
  return out;
}

std::string replay_html(const std::string& template_text, const std::string& data_json) {
  const std::string marker = replay_data_marker;
  const std::size_t at = template_text.find(marker);
  if (at == std::string::npos || template_text.find(marker, at + 1) != std::string::npos)
    throw replay_error("the replay template must contain " + marker + " exactly once");
  return template_text.substr(0, at) + replay_script(data_json) +
         template_text.substr(at + marker.size());
}

std::filesystem::path write_replay(const std::filesystem::path& dir,
                                   const std::string& template_path, const ReplayOptions& o) {
  std::string text;
  {
    std::ifstream in(template_path, std::ios::binary);
    if (!in) throw replay_error("cannot read the replay template " + template_path);
    std::ostringstream ss;
    ss << in.rdbuf();
    text = ss.str();
  }
  const std::string html = replay_html(text, replay_data_json(dir, o));
  const std::filesystem::path out = dir / "replay.html", tmp = dir / ".replay.html.tmp";
  {
    std::ofstream f(tmp, std::ios::binary);
    f << html;
    if (!f) throw replay_error("cannot write " + tmp.string());
  }
  std::error_code ec;
  std::filesystem::rename(tmp, out, ec);
  if (ec) throw replay_error("cannot write " + out.string() + ": " + ec.message());
  return out;
}

}  // namespace sim
}  // namespace kelp
