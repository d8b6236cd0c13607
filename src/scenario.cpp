// kelp::sim's scenario files: the reader (every error a scenario_error naming the file and the
// JSON path) and the writer, the schema's one place.
#include "scenario_json.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <limits>
#include <set>
#include <string>

#include "json_reader.hpp"
#include "kelp/sim/scenario.hpp"

namespace kelp {
namespace sim {

int json_depth(const std::string& text, int limit) {
  int depth = 0, deepest = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\')
        ++i;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
      if (deepest > limit) break;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}


kelp::environment::ObstacleSet obstacle_set(const Scenario& s) {
  kelp::environment::ObstacleSet set;
  for (const auto& c : s.cylinders) set.add(c);
  for (const auto& b : s.boxes) set.add(b);
  if (s.has_heightfield) set.set_seabed(s.heightfield);
  return set;
}


namespace detail {

/// Reads the scenario's `navigation` object (schema in examples/tethered_pair/README.md): the
/// mode, the seed and every sensor's parameters, each checked against its range.
void parse_navigation(const nlohmann::json& j, const Reader& r, NavigationSettings& out) {
  const std::string p = "/navigation";
  r.object(j, p, {"mode", "seed", "imu", "depth", "dvl", "compass", "gps", "usbl"});
  r.choice(j, p, "mode", out.mode, {"perfect", "sensors"});
  r.integer(j, p, "seed", out.seed, 0, 1e18);
  PairSensors& s = out.sensors;
  // Rates up to the closed loop's 100 steps per second: a sensor samples at most once a step.
  if (j.contains("imu")) {
    const auto& o = j.at("imu");
    const std::string q = p + "/imu";
    r.object(o, q,
             {"rate", "gyro_noise_density", "gyro_bias_walk", "gyro_bias_initial",
              "accel_noise_density", "accel_bias_walk", "accel_bias_initial"});
    r.number(o, q, "rate", s.imu.rate, 1, 100);
    r.number(o, q, "gyro_noise_density", s.imu.gyro_noise_density, 0, 0.1);
    r.number(o, q, "gyro_bias_walk", s.imu.gyro_bias_walk, 0, 0.1);
    r.number(o, q, "gyro_bias_initial", s.imu.gyro_bias_initial, 0, 0.5);
    r.number(o, q, "accel_noise_density", s.imu.accel_noise_density, 0, 1);
    r.number(o, q, "accel_bias_walk", s.imu.accel_bias_walk, 0, 1);
    r.number(o, q, "accel_bias_initial", s.imu.accel_bias_initial, 0, 2);
  }
  if (j.contains("depth")) {
    const auto& o = j.at("depth");
    const std::string q = p + "/depth";
    r.object(o, q, {"rate", "noise", "bias"});
    r.number(o, q, "rate", s.depth.rate, 0.01, 100);
    r.number(o, q, "noise", s.depth.noise, 0, 10);
    r.number(o, q, "bias", s.depth.bias, -100, 100);
  }
  if (j.contains("dvl")) {
    const auto& o = j.at("dvl");
    const std::string q = p + "/dvl";
    r.object(o, q,
             {"bottom_rate", "water_rate", "min_altitude", "max_altitude", "noise_floor",
              "noise_fraction", "water_track", "water_noise", "water_track_distance"});
    r.number(o, q, "bottom_rate", s.dvl.bottom_rate, 0.01, 100);
    r.number(o, q, "water_rate", s.dvl.water_rate, 0.01, 100);
    r.number(o, q, "min_altitude", s.dvl.min_altitude, 0, 1000);
    r.number(o, q, "max_altitude", s.dvl.max_altitude, 0, 1e4);
    if (s.dvl.max_altitude <= s.dvl.min_altitude)
      r.fail(q + "/max_altitude", "expected more than /navigation/dvl/min_altitude (" +
                                      std::to_string(s.dvl.min_altitude) + ")");
    r.number(o, q, "noise_floor", s.dvl.noise_floor, 0, 10);
    r.number(o, q, "noise_fraction", s.dvl.noise_fraction, 0, 1);
    r.boolean(o, q, "water_track", s.dvl.water_track);
    r.number(o, q, "water_noise", s.dvl.water_noise, 0, 10);
    r.number(o, q, "water_track_distance", s.dvl.water_track_distance, 0, 100);
  }
  if (j.contains("compass")) {
    const auto& o = j.at("compass");
    const std::string q = p + "/compass";
    r.object(o, q, {"rate", "noise", "bias"});
    r.number(o, q, "rate", s.compass.rate, 0.01, 100);
    r.number(o, q, "noise", s.compass.noise, 0, 1);
    r.number(o, q, "bias", s.compass.bias, -3.15, 3.15);
  }
  if (j.contains("gps")) {
    const auto& o = j.at("gps");
    const std::string q = p + "/gps";
    r.object(o, q, {"rate", "noise", "bias_sigma", "bias_time", "vertical_factor"});
    r.number(o, q, "rate", s.gps.rate, 0.01, 100);
    r.number(o, q, "noise", s.gps.noise, 0, 100);
    r.number(o, q, "bias_sigma", s.gps.bias_sigma, 0, 100);
    r.number(o, q, "bias_time", s.gps.bias_time, 0.01, 1e6);
    r.number(o, q, "vertical_factor", s.gps.vertical_factor, 0, 10);
  }
  if (j.contains("usbl")) {
    const auto& o = j.at("usbl");
    const std::string q = p + "/usbl";
    r.object(o, q, {"rate", "noise_floor", "noise_fraction", "latency", "dropout", "max_range"});
    r.number(o, q, "rate", s.usbl.rate, 0.01, 100);
    r.number(o, q, "noise_floor", s.usbl.noise_floor, 0, 100);
    r.number(o, q, "noise_fraction", s.usbl.noise_fraction, 0, 1);
    r.number(o, q, "latency", s.usbl.latency, 0, 10);
    if (s.usbl.latency * s.usbl.rate >= kelp::nav::usbl_queue_capacity - 2)
      r.fail(q, "latency × rate must be < " + std::to_string(kelp::nav::usbl_queue_capacity - 2) +
                    " (fixes in flight)");
    r.number(o, q, "dropout", s.usbl.dropout, 0, 0.99);
    r.number(o, q, "max_range", s.usbl.max_range, 0.1, 1e4);
  }
}

/// The `navigation` object of a scenario, every field with its value.
nlohmann::json navigation_json(const NavigationSettings& n) {
  const PairSensors& s = n.sensors;
  return {
      {"mode", n.mode},
      {"seed", n.seed},
      {"imu",
       {{"rate", s.imu.rate},
        {"gyro_noise_density", s.imu.gyro_noise_density},
        {"gyro_bias_walk", s.imu.gyro_bias_walk},
        {"gyro_bias_initial", s.imu.gyro_bias_initial},
        {"accel_noise_density", s.imu.accel_noise_density},
        {"accel_bias_walk", s.imu.accel_bias_walk},
        {"accel_bias_initial", s.imu.accel_bias_initial}}},
      {"depth", {{"rate", s.depth.rate}, {"noise", s.depth.noise}, {"bias", s.depth.bias}}},
      {"dvl",
       {{"bottom_rate", s.dvl.bottom_rate},
        {"water_rate", s.dvl.water_rate},
        {"min_altitude", s.dvl.min_altitude},
        {"max_altitude", s.dvl.max_altitude},
        {"noise_floor", s.dvl.noise_floor},
        {"noise_fraction", s.dvl.noise_fraction},
        {"water_track", s.dvl.water_track},
        {"water_noise", s.dvl.water_noise},
        {"water_track_distance", s.dvl.water_track_distance}}},
      {"compass", {{"rate", s.compass.rate}, {"noise", s.compass.noise}, {"bias", s.compass.bias}}},
      {"gps",
       {{"rate", s.gps.rate},
        {"noise", s.gps.noise},
        {"bias_sigma", s.gps.bias_sigma},
        {"bias_time", s.gps.bias_time},
        {"vertical_factor", s.gps.vertical_factor}}},
      {"usbl",
       {{"rate", s.usbl.rate},
        {"noise_floor", s.usbl.noise_floor},
        {"noise_fraction", s.usbl.noise_fraction},
        {"latency", s.usbl.latency},
        {"dropout", s.usbl.dropout},
        {"max_range", s.usbl.max_range}}}};
}

}  // namespace detail

namespace detail {

/// An height field (`origin`, `spacing`, `size`, `depth`: the replay's shape).
kelp::environment::HeightField parse_heightfield_object(const nlohmann::json& h,
                                                               const Reader& r,
                                                               const std::string& p,
                                                               bool with_type) {
  std::set<std::string> keys{"origin", "spacing", "size", "depth"};
  if (with_type) keys.insert("type");
  r.object(h, p, keys);
  for (const char* k : {"origin", "spacing", "size", "depth"})
    if (!h.contains(k)) r.fail(p, std::string("missing \"") + k + "\"");
  const auto pair = [&](const char* k, double lo, double hi) {
    const auto& v = h.at(k);
    if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number())
      r.fail(p + "/" + k, "expected an array of 2 numbers, got " + v.dump());
    const double a = v[0].get<double>(), b = v[1].get<double>();
    if (!(a >= lo && a <= hi && b >= lo && b <= hi))
      r.fail(p + "/" + k, "expected numbers in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                              "], got " + v.dump());
    return std::pair<double, double>(a, b);
  };
  kelp::environment::HeightField hf;
  const auto o = pair("origin", -1e6, 1e6);
  const auto sp = pair("spacing", 1e-6, 1e6);
  const auto sz = pair("size", 2, 100000);
  hf.origin = Eigen::Vector2d(o.first, o.second);
  hf.spacing = Eigen::Vector2d(sp.first, sp.second);
  if (sz.first != std::floor(sz.first) || sz.second != std::floor(sz.second))
    r.fail(p + "/size", "expected whole numbers [rows, cols]");
  hf.rows = int(sz.first);
  hf.cols = int(sz.second);
  const auto& d = h.at("depth");
  if (!d.is_array() || d.size() != std::size_t(hf.rows) * std::size_t(hf.cols))
    r.fail(p + "/depth", "expected an array of rows x cols = " +
                             std::to_string(std::size_t(hf.rows) * std::size_t(hf.cols)) +
                             " depths (row-major)");
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (!d[i].is_number() || !(std::abs(d[i].get<double>()) <= 1e5))
      r.fail(p + "/depth/" + std::to_string(i),
             "expected a depth within 1e5 m, got " + d[i].dump());
    hf.depth.push_back(d[i].get<double>());
  }
  return hf;
}

/// The contact keys an obstacle may set (`friction`, `stiffness`, `damping`).
void parse_contact(const nlohmann::json& o, const Reader& r, const std::string& p,
                          kelp::environment::ContactProperties& c) {
  r.number(o, p, "friction", c.friction, 0, 100);
  r.number(o, p, "stiffness", c.stiffness, 1e-6, 1e13);
  r.number(o, p, "damping", c.damping, 0, 1e13);
}

/// `"obstacles": [...]` into s.cylinders, s.boxes (and an height field).
void parse_obstacles(const nlohmann::json& list, const Reader& r, const std::string& file,
                            Scenario& s) {
  (void)file;
  if (!list.is_array()) r.fail("/obstacles", "expected an array of obstacles");
  if (list.size() > 100000) r.fail("/obstacles", "at most 100000 obstacles");
  std::set<std::string> names;
  kelp::environment::ObstacleSet check;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const auto& o = list[i];
    const std::string p = "/obstacles/" + std::to_string(i);
    if (!o.is_object() || !o.contains("type") || !o.at("type").is_string())
      r.fail(p, "expected an object with \"type\": \"cylinder\", \"box\" or \"heightfield\"");
    const std::string type = o.at("type").get<std::string>();
    std::string name = type + " " + std::to_string(i);
    if (o.contains("name")) {
      if (!o.at("name").is_string() || o.at("name").get<std::string>().empty())
        r.fail(p + "/name", "expected a non-empty string");
      name = o.at("name").get<std::string>();
    }
    if (type != "heightfield" && !names.insert(name).second)
      r.fail(p + "/name", "\"" + name + "\" names another obstacle already");
    try {
      if (type == "cylinder") {
        r.object(o, p,
                 {"type", "name", "from", "to", "radius", "friction", "stiffness", "damping"});
        for (const char* k : {"from", "to", "radius"})
          if (!o.contains(k)) r.fail(p, std::string("missing \"") + k + "\"");
        kelp::environment::Cylinder c;
        c.name = name;
        c.from = r.vec3(o.at("from"), p + "/from");
        c.to = r.vec3(o.at("to"), p + "/to");
        c.radius = -1;
        r.number(o, p, "radius", c.radius, 1e-6, 1e4);
        parse_contact(o, r, p, c.contact);
        check.add(c);
        s.cylinders.push_back(c);
      } else if (type == "box") {
        r.object(o, p,
                 {"type", "name", "center", "half_extents", "yaw", "roll", "pitch", "friction",
                  "stiffness", "damping"});
        for (const char* k : {"center", "half_extents"})
          if (!o.contains(k)) r.fail(p, std::string("missing \"") + k + "\"");
        kelp::environment::Box b;
        b.name = name;
        b.center = r.vec3(o.at("center"), p + "/center");
        b.half_extents = r.vec3(o.at("half_extents"), p + "/half_extents");
        r.number(o, p, "yaw", b.yaw, -100, 100);
        r.number(o, p, "roll", b.roll, -100, 100);
        r.number(o, p, "pitch", b.pitch, -100, 100);
        parse_contact(o, r, p, b.contact);
        check.add(b);
        s.boxes.push_back(b);
      } else if (type == "heightfield") {
        if (s.has_heightfield) r.fail(p, "a second height field (one seabed per scenario)");
        s.heightfield = parse_heightfield_object(o, r, p, true);
        kelp::environment::validate(s.heightfield);
        s.has_heightfield = true;
        s.heightfield_file.clear();
      } else {
        r.fail(p + "/type",
               "expected \"cylinder\", \"box\" or \"heightfield\", got \"" + type + "\"");
      }
    } catch (const scenario_error&) {
      throw;
    } catch (const kelp::invalid_argument& e) {
      r.fail(p, e.what());
    }
  }
}

/// `"seabed": {"depth": m}` or `{"heightfield": "file" | {...}}`, optional `"friction"`.
void parse_seabed(const nlohmann::json& b, const Reader& r, const std::string& file,
                         Scenario& s) {
  r.object(b, "/seabed", {"depth", "heightfield", "friction"});
  if (b.contains("depth") && b.contains("heightfield"))
    r.fail("/seabed", "expected \"depth\" (flat) or \"heightfield\", not both");
  r.number(b, "/seabed", "depth", s.seabed_depth, 0.1, 1e5);
  r.number(b, "/seabed", "friction", s.seabed_friction, 0, 100);
  if (!b.contains("heightfield")) return;
  if (s.has_heightfield)
    r.fail("/seabed/heightfield", "a second height field (one seabed per scenario)");
  const auto& h = b.at("heightfield");
  try {
    if (h.is_string()) {
      const std::string name = h.get<std::string>();
      std::string path = name;
      // Relative to the scenario file's directory (when the scenario is a file).
      const auto slash = file.find_last_of('/');
      if (!name.empty() && name[0] != '/' && slash != std::string::npos) {
        const std::string beside = file.substr(0, slash + 1) + name;
        if (std::ifstream(beside).good()) path = beside;
      }
      s.heightfield = kelp::environment::load_heightfield(path);
      s.heightfield_file = name;
    } else {
      s.heightfield = parse_heightfield_object(h, r, "/seabed/heightfield", false);
      kelp::environment::validate(s.heightfield);
      s.heightfield_file.clear();
    }
  } catch (const scenario_error&) {
    throw;
  } catch (const kelp::invalid_argument& e) {
    r.fail("/seabed/heightfield", e.what());
  }
  s.has_heightfield = true;
}

/// The obstacles and the seabed as JSON (to_json).
void obstacles_json(const Scenario& s, nlohmann::json& j) {
  const auto v3 = [](const Eigen::Vector3d& v) {
    return nlohmann::json::array({v(0), v(1), v(2)});
  };
  const auto contact = [](const kelp::environment::ContactProperties& c, nlohmann::json& o) {
    o["friction"] = c.friction;
    o["stiffness"] = c.stiffness;
    o["damping"] = c.damping;
  };
  nlohmann::json list = nlohmann::json::array();
  for (const auto& c : s.cylinders) {
    nlohmann::json o = {{"type", "cylinder"},
                        {"name", c.name},
                        {"from", v3(c.from)},
                        {"to", v3(c.to)},
                        {"radius", c.radius}};
    contact(c.contact, o);
    list.push_back(o);
  }
  for (const auto& b : s.boxes) {
    nlohmann::json o = {{"type", "box"},
                        {"name", b.name},
                        {"center", v3(b.center)},
                        {"half_extents", v3(b.half_extents)},
                        {"yaw", b.yaw}};
    if (b.roll != 0) o["roll"] = b.roll;
    if (b.pitch != 0) o["pitch"] = b.pitch;
    contact(b.contact, o);
    list.push_back(o);
  }
  if (!list.empty()) j["obstacles"] = list;
  nlohmann::json bed = nlohmann::json::object();
  if (std::isfinite(s.seabed_depth)) bed["depth"] = s.seabed_depth;
  if (s.has_heightfield) {
    if (!s.heightfield_file.empty()) {
      bed["heightfield"] = s.heightfield_file;
    } else {
      const auto& h = s.heightfield;
      bed["heightfield"] = {{"origin", {h.origin.x(), h.origin.y()}},
                            {"spacing", {h.spacing.x(), h.spacing.y()}},
                            {"size", {h.rows, h.cols}},
                            {"depth", h.depth}};
    }
  }
  if (s.seabed_friction >= 0) bed["friction"] = s.seabed_friction;
  if (!bed.empty()) j["seabed"] = bed;
}

}  // namespace detail

/// \brief Reads and validates a scenario from JSON text.
/// \param[in] text the JSON text \param[in] file names the scenario in error messages
/// \throws scenario_error naming the file, the JSON path and what was expected.
Scenario parse_scenario(const std::string& text, const std::string& file) {
  const detail::Reader r(file);
  if (json_depth(text, max_json_depth) > max_json_depth)
    r.fail("", "arrays and objects nested more than " + std::to_string(max_json_depth) +
                   " levels deep");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    // Includes numbers beyond double (JSON has no NaN or infinity: 1e999 fails here, named by
    // its text).
    r.fail("", std::string("not valid JSON: ") + e.what());
  }
  Scenario s;
  r.object(j, "",
           {"duration", "seed", "sea", "tether", "vehicles", "start", "control", "mission",
            "output", "kernel", "deterministic", "navigation", "thrusters", "battery", "obstacles",
            "seabed", "entanglement"});
  r.number(j, "", "duration", s.duration, 1e-3, 1e7);
  r.integer(j, "", "seed", s.seed, 0, 1e18);
  if (j.contains("sea")) {
    const auto& sea = j.at("sea");
    if (sea.is_string()) {
      r.choice(j, "", "sea", s.sea, {"calm", "moderate", "rough"});
    } else {
      r.object(sea, "/sea",
               {"significant_height", "peak_period", "wave_direction", "wind_speed",
                "wind_direction", "current_speed", "current_direction", "wave_components"});
      s.sea = "custom";
      s.peak_period = 8.0;
      r.number(sea, "/sea", "significant_height", s.significant_height, 0, 20);
      r.number(sea, "/sea", "peak_period", s.peak_period, 1, 30);
      r.number(sea, "/sea", "wave_direction", s.wave_direction, -10, 10);
      r.number(sea, "/sea", "wind_speed", s.wind_speed, 0, 60);
      r.number(sea, "/sea", "wind_direction", s.wind_direction, -10, 10);
      r.number(sea, "/sea", "current_speed", s.current_speed, 0, 5);
      r.number(sea, "/sea", "current_direction", s.current_direction, -10, 10);
      double n = s.wave_components;
      r.number(sea, "/sea", "wave_components", n, 1, 4096);
      if (n != std::floor(n)) r.fail("/sea/wave_components", "expected an integer");
      s.wave_components = static_cast<int>(n);
    }
  }
  if (j.contains("tether")) {
    const auto& t = j.at("tether");
    r.object(t, "/tether",
             {"length", "kind", "segment_length", "diameter", "mass_per_length", "axial_stiffness",
              "internal_damping", "normal_drag", "tangential_drag", "explicit_fallback",
              "line_model", "breaking_strength", "winch"});
    r.number(t, "/tether", "breaking_strength", s.breaking_strength, 0, 1e7);
    r.number(t, "/tether", "diameter", s.diameter, 1e-4, 0.5);
    r.number(t, "/tether", "mass_per_length", s.mass_per_length, 1e-4, 100);
    r.number(t, "/tether", "axial_stiffness", s.axial_stiffness, 1, 1e10);
    r.number(t, "/tether", "internal_damping", s.internal_damping, 0, 1e6);
    r.number(t, "/tether", "normal_drag", s.normal_drag, 0, 10);
    r.number(t, "/tether", "tangential_drag", s.tangential_drag, 0, 10);
    r.number(t, "/tether", "length", s.tether_length, 0.5, 1000);
    r.choice(t, "/tether", "kind", s.tether_kind, {"rov_tether", "bead_chain"});
    r.number(t, "/tether", "segment_length", s.segment_length, 0.05, 10);
    r.boolean(t, "/tether", "explicit_fallback", s.explicit_fallback);
    r.choice(t, "/tether", "line_model", s.line_model, {"kelp", "moordyn"});
    if (t.contains("winch")) {
      const auto& w = t.at("winch");
      const std::string p = "/tether/winch";
      r.object(w, p,
               {"max_speed", "max_acceleration", "max_pull", "min_length", "max_length", "strategy",
                "tension_low", "tension_high", "tension_gain", "slack", "extra_length",
                "length_per_depth", "length_per_offset", "length_gain"});
      WinchScenario& x = s.winch;
      x.enabled = true;
      r.number(w, p, "max_speed", x.max_speed, 0.01, 10);
      r.number(w, p, "max_acceleration", x.max_acceleration, 0.01, 100);
      r.number(w, p, "max_pull", x.max_pull, 1, 1e6);
      r.number(w, p, "min_length", x.min_length, 0.5, 1000);
      r.number(w, p, "max_length", x.max_length, 0.5, 1000);
      r.choice(w, p, "strategy", s.winch_strategy,
               {"hold", "constant_tension", "slack", "depth_following"});
      r.number(w, p, "tension_low", x.tension_low, 0, 1e5);
      r.number(w, p, "tension_high", x.tension_high, 0, 1e5);
      r.number(w, p, "tension_gain", x.tension_gain, 0, 10);
      r.number(w, p, "slack", x.slack, 0, 10);
      r.number(w, p, "extra_length", x.extra_length, 0, 1000);
      r.number(w, p, "length_per_depth", x.length_per_depth, 0, 10);
      r.number(w, p, "length_per_offset", x.length_per_offset, 0, 10);
      r.number(w, p, "length_gain", x.length_gain, 0, 100);
      if (x.max_length < x.min_length) r.fail(p + "/max_length", "expected at least min_length");
      if (x.tension_high <= x.tension_low)
        r.fail(p + "/tension_high", "expected more than tension_low");
      if (s.tether_length < x.min_length || s.tether_length > x.max_length)
        r.fail("/tether/length", "expected within the winch's [min_length, max_length]");
    }
  }
  if (j.contains("vehicles")) {
    const auto& v = j.at("vehicles");
    r.object(v, "/vehicles", {"asv_attachment", "auv_attachment", "auv_start"});
    if (v.contains("asv_attachment"))
      s.asv_attachment = r.vec3(v.at("asv_attachment"), "/vehicles/asv_attachment");
    if (v.contains("auv_attachment"))
      s.auv_attachment = r.vec3(v.at("auv_attachment"), "/vehicles/auv_attachment");
    if (v.contains("auv_start")) {
      const kelp::Vector3<double> p = r.vec3(v.at("auv_start"), "/vehicles/auv_start");
      s.auv_start = {p(0), p(1), p(2)};
    }
  }
  if (j.contains("start")) {
    const auto& st = j.at("start");
    r.object(st, "/start", {"ramp", "with_water"});
    r.number(st, "/start", "ramp", s.start_ramp, 0, 1e5);
    r.boolean(st, "/start", "with_water", s.start_with_water);
  }
  if (j.contains("control")) {
    const auto& c = j.at("control");
    r.object(c, "/control", {"preset", "compensation", "asv", "auv"});
    r.choice(c, "/control", "preset", s.control_preset, {"kelp", "paper"});
    if (s.control_preset == "paper") s.asv_thrust_clip = 15.0;  // the paper's, unless set below
    r.boolean(c, "/control", "compensation", s.compensation);
    if (c.contains("asv")) {
      const auto& a = c.at("asv");
      r.object(a, "/control/asv", {"linear", "angular", "yaw", "thrust_clip", "rate", "station"});
      r.boolean(a, "/control/asv", "station", s.asv_station);
      r.gains(a, "/control/asv", "linear", s.asv_linear);
      r.gains(a, "/control/asv", "angular", s.asv_angular);
      r.gains(a, "/control/asv", "yaw", s.asv_yaw);
      r.number(a, "/control/asv", "thrust_clip", s.asv_thrust_clip, 0.1, 30.6);
      r.number(a, "/control/asv", "rate", s.asv_rate, 0.1, 1000);
    }
    if (c.contains("auv")) {
      const auto& a = c.at("auv");
      r.object(a, "/control/auv", {"surge", "sway", "heave", "yaw", "rate"});
      r.gains(a, "/control/auv", "surge", s.auv_surge);
      r.gains(a, "/control/auv", "sway", s.auv_sway);
      r.gains(a, "/control/auv", "heave", s.auv_heave);
      r.gains(a, "/control/auv", "yaw", s.auv_yaw);
      r.number(a, "/control/auv", "rate", s.auv_rate, 0.1, 1000);
    }
  }
  if (j.contains("mission")) {
    const auto& m = j.at("mission");
    r.object(m, "/mission", {"waypoints", "depth", "square_side"});
    r.number(m, "/mission", "depth", s.depth, 0.5, 1000);
    r.number(m, "/mission", "square_side", s.square_side, 0.5, 1000);
    if (m.contains("waypoints")) {
      const auto& w = m.at("waypoints");
      if (!w.is_array()) r.fail("/mission/waypoints", "expected an array of [x, y, z]");
      if (w.empty()) r.fail("/mission/waypoints", "expected at least one waypoint, got []");
      for (std::size_t i = 0; i < w.size(); ++i)
        s.waypoints.push_back(r.vec3(w[i], "/mission/waypoints/" + std::to_string(i)));
    }
  }
  if (j.contains("output")) {
    const auto& o = j.at("output");
    r.object(o, "/output", {"log_rate", "node_rate", "mcap"});
    r.number(o, "/output", "log_rate", s.log_rate, 0.01, 100);
    r.number(o, "/output", "node_rate", s.node_rate, 0.001, 100);
    r.boolean(o, "/output", "mcap", s.mcap);
  }
  if (j.contains("navigation")) detail::parse_navigation(j.at("navigation"), r, s.navigation);
  // Propulsion (thrusters' lag, batteries).
  if (j.contains("thrusters")) {
    const auto& t = j.at("thrusters");
    r.object(t, "/thrusters", {"propulsion", "lag", "time_constant"});
    r.boolean(t, "/thrusters", "propulsion", s.propulsion);
    r.boolean(t, "/thrusters", "lag", s.thruster_lag);
    r.number(t, "/thrusters", "time_constant", s.thruster_time_constant, 0.0, 10.0);
  }
  if (j.contains("battery")) {
    const auto& b = j.at("battery");
    r.object(b, "/battery", {"asv", "auv"});
    for (const char* v : {"asv", "auv"}) {
      if (!b.contains(v)) continue;
      const std::string path = std::string("/battery/") + v;
      BatteryScenario& x = std::string(v) == "asv" ? s.asv_battery : s.auv_battery;
      const auto& o = b.at(v);
      r.object(o, path,
               {"capacity_ah", "cells_in_series", "internal_resistance", "initial_soc",
                "hotel_current"});
      r.number(o, path, "capacity_ah", x.capacity_ah, 0.01, 1e5);
      std::uint64_t cells = std::uint64_t(x.cells_in_series);
      r.integer(o, path, "cells_in_series", cells, 1, 1000);
      x.cells_in_series = int(cells);
      r.number(o, path, "internal_resistance", x.internal_resistance, 0.0, 100.0);
      r.number(o, path, "initial_soc", x.initial_soc, 0.0, 1.0);
      r.number(o, path, "hotel_current", x.hotel_current, 0.0, 1000.0);
    }
  }
  if (j.contains("obstacles")) detail::parse_obstacles(j.at("obstacles"), r, file, s);
  if (j.contains("seabed")) detail::parse_seabed(j.at("seabed"), r, file, s);
  if (j.contains("entanglement")) {
    const auto& e = j.at("entanglement");
    const std::string p = "/entanglement";
    r.object(e, p,
             {"wrap_threshold", "wrap_hysteresis", "contact_margin", "pin_slip_speed",
              "pin_tension_difference", "pin_hold_time"});
    EntanglementSettings& x = s.entanglement;
    r.number(e, p, "wrap_threshold", x.wrap_threshold, 1e-3, 1e3);
    r.number(e, p, "wrap_hysteresis", x.wrap_hysteresis, 0, 1e3);
    r.number(e, p, "contact_margin", x.contact_margin, 0, 10);
    r.number(e, p, "pin_slip_speed", x.pin_slip_speed, 1e-6, 10);
    r.number(e, p, "pin_tension_difference", x.pin_tension_difference, 1e-3, 1e6);
    r.number(e, p, "pin_hold_time", x.pin_hold_time, 0, 1e4);
    if (x.wrap_hysteresis > x.wrap_threshold)
      r.fail(p + "/wrap_hysteresis", "expected at most wrap_threshold");
  }
  r.choice(j, "", "kernel", s.kernel, {"auto", "portable", "avx2", "avx512"});
  bool deterministic = false;
  r.boolean(j, "", "deterministic", deterministic);
  if (deterministic) {
    if (s.kernel != "auto" && s.kernel != "portable")
      r.fail("/deterministic",
             "true pins the \"portable\" kernel, but /kernel is \"" + s.kernel + "\"");
    s.kernel = "portable";
  }
  return s;
}

/// \brief Reads a scenario file. \throws scenario_error naming the file (also when it cannot be
/// read).
Scenario load_scenario(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw scenario_error(file + ": cannot be read");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return parse_scenario(text, file);
}

/// \brief The scenario as JSON, every field with its value (echoed in the run's summary; it reads
/// back through parse_scenario to the same scenario); `kernel` only when it is not "auto".
nlohmann::json scenario_to_json(const Scenario& s) {
  const auto v3 = [](const kelp::Vector3<double>& v) {
    return nlohmann::json::array({v(0), v(1), v(2)});
  };
  const auto g = [](const Gains& x) { return nlohmann::json::array({x.kp, x.ki, x.kd}); };
  nlohmann::json j;
  j["duration"] = s.duration;
  j["seed"] = s.seed;
  if (s.sea == "custom")
    j["sea"] = {
        {"significant_height", s.significant_height}, {"peak_period", s.peak_period},
        {"wave_direction", s.wave_direction},         {"wind_speed", s.wind_speed},
        {"wind_direction", s.wind_direction},         {"current_speed", s.current_speed},
        {"current_direction", s.current_direction},   {"wave_components", s.wave_components}};
  else
    j["sea"] = s.sea;
  j["tether"] = {
      {"length", s.tether_length}, {"kind", s.tether_kind}, {"segment_length", s.segment_length}};
  const auto opt = [&](const char* key, double v, double unset) {
    if (v > unset) j["tether"][key] = v;
  };
  opt("diameter", s.diameter, 0);
  opt("mass_per_length", s.mass_per_length, 0);
  opt("axial_stiffness", s.axial_stiffness, 0);
  opt("internal_damping", s.internal_damping, -1);
  opt("normal_drag", s.normal_drag, -1);
  opt("tangential_drag", s.tangential_drag, -1);
  opt("breaking_strength", s.breaking_strength, -1);
  j["tether"]["explicit_fallback"] = s.explicit_fallback;
  if (s.line_model != "kelp") j["tether"]["line_model"] = s.line_model;
  if (s.winch.enabled) {
    const WinchScenario& w = s.winch;
    j["tether"]["winch"] = {{"max_speed", w.max_speed},
                            {"max_acceleration", w.max_acceleration},
                            {"max_pull", w.max_pull},
                            {"min_length", w.min_length},
                            {"max_length", w.max_length},
                            {"strategy", s.winch_strategy},
                            {"tension_low", w.tension_low},
                            {"tension_high", w.tension_high},
                            {"tension_gain", w.tension_gain},
                            {"slack", w.slack},
                            {"extra_length", w.extra_length},
                            {"length_per_depth", w.length_per_depth},
                            {"length_per_offset", w.length_per_offset},
                            {"length_gain", w.length_gain}};
  }
  j["vehicles"] = {{"asv_attachment", v3(s.asv_attachment)},
                   {"auv_attachment", v3(s.auv_attachment)}};
  if (!s.auv_start.empty()) j["vehicles"]["auv_start"] = s.auv_start;
  j["start"] = {{"ramp", s.start_ramp}, {"with_water", s.start_with_water}};
  j["control"] = {{"preset", s.control_preset},
                  {"compensation", s.compensation},
                  {"asv",
                   {{"linear", g(s.asv_linear)},
                    {"angular", g(s.asv_angular)},
                    {"yaw", g(s.asv_yaw)},
                    {"thrust_clip", s.asv_thrust_clip},
                    {"rate", s.asv_rate}}},
                  {"auv",
                   {{"surge", g(s.auv_surge)},
                    {"sway", g(s.auv_sway)},
                    {"heave", g(s.auv_heave)},
                    {"yaw", g(s.auv_yaw)},
                    {"rate", s.auv_rate}}}};
  if (s.asv_station) j["control"]["asv"]["station"] = true;
  nlohmann::json wp = nlohmann::json::array();
  for (const auto& w : s.waypoints) wp.push_back(v3(w));
  j["mission"] = {{"depth", s.depth}, {"square_side", s.square_side}};
  if (!s.waypoints.empty()) j["mission"]["waypoints"] = wp;
  j["output"] = {{"log_rate", s.log_rate}, {"node_rate", s.node_rate}};
  // Only when off: writing a bag does not change the run, so the default leaves the JSON (and the
  // run hashes of kelp-sweep, which key stored results) as they were.
  if (!s.mcap) j["output"]["mcap"] = false;
  // Only when pinned: the default leaves the JSON (and kelp-sweep's run hashes) as they were.
  if (s.kernel != "auto") j["kernel"] = s.kernel;
  // Navigation: likewise only when it differs from the default (perfect navigation).
  const nlohmann::json nav = detail::navigation_json(s.navigation);
  if (nav != detail::navigation_json(NavigationSettings{})) j["navigation"] = nav;
  // Propulsion (thrusters' lag, batteries).
  j["thrusters"] = {{"propulsion", s.propulsion},
                    {"lag", s.thruster_lag},
                    {"time_constant", s.thruster_time_constant}};
  const auto battery = [](const BatteryScenario& b) {
    return nlohmann::json{{"capacity_ah", b.capacity_ah},
                          {"cells_in_series", b.cells_in_series},
                          {"internal_resistance", b.internal_resistance},
                          {"initial_soc", b.initial_soc},
                          {"hotel_current", b.hotel_current}};
  };
  j["battery"] = {{"asv", battery(s.asv_battery)}, {"auv", battery(s.auv_battery)}};
  // Obstacles and seabed: only when the scenario has them.
  detail::obstacles_json(s, j);
  // Entanglement thresholds: only when they differ from the defaults (the JSON of a scenario
  // without them, and kelp-sweep's run hashes, stay as they were).
  {
    const EntanglementSettings& e = s.entanglement;
    const EntanglementSettings d;
    if (e.wrap_threshold != d.wrap_threshold || e.wrap_hysteresis != d.wrap_hysteresis ||
        e.contact_margin != d.contact_margin || e.pin_slip_speed != d.pin_slip_speed ||
        e.pin_tension_difference != d.pin_tension_difference || e.pin_hold_time != d.pin_hold_time)
      j["entanglement"] = {{"wrap_threshold", e.wrap_threshold},
                           {"wrap_hysteresis", e.wrap_hysteresis},
                           {"contact_margin", e.contact_margin},
                           {"pin_slip_speed", e.pin_slip_speed},
                           {"pin_tension_difference", e.pin_tension_difference},
                           {"pin_hold_time", e.pin_hold_time}};
  }
  return j;
}

std::string scenario_json(const Scenario& s, int indent) { return scenario_to_json(s).dump(indent); }

}  // namespace sim
}  // namespace kelp
