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
#include <utility>

#include "json_reader.hpp"
#include "kelp/sim/heightfield_file.hpp"
#include "kelp/sim/ros2/names.hpp"
#include "kelp/sim/scenario.hpp"
#include "scenario_reference.hpp"
#include "scenario_schema.hpp"

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
  if (s.heightfield) set.set_seabed(*s.heightfield);
  return set;
}

namespace detail {

/// An height field (`origin`, `spacing`, `size`, `depth`: the replay's shape).
kelp::environment::HeightField parse_heightfield_object(const nlohmann::json& h, const Reader& r,
                                                        const std::string& p, bool with_type) {
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

/// The seabed's `heightfield`: a file in MoorDyn's seafloor format (a path relative to the
/// scenario file when one is beside it) or an object (parse_heightfield_object).
void parse_seabed_heightfield(const nlohmann::json& h, const Reader& r, const std::string& p,
                              Scenario& s) {
  if (s.heightfield) r.fail(p, "a second height field (one seabed per scenario)");
  try {
    if (h.is_string()) {
      const std::string name = h.get<std::string>();
      std::string path = name;
      // Relative to the scenario file's directory (when the scenario is a file).
      const std::string& file = r.file();
      const auto slash = file.find_last_of('/');
      if (!name.empty() && name[0] != '/' && slash != std::string::npos) {
        const std::string beside = file.substr(0, slash + 1) + name;
        if (std::ifstream(beside).good()) path = beside;
      }
      s.heightfield = load_heightfield(path);
      s.heightfield_file = name;
    } else {
      kelp::environment::HeightField hf = parse_heightfield_object(h, r, p, false);
      kelp::environment::validate(hf);
      s.heightfield = std::move(hf);
      s.heightfield_file.clear();
    }
  } catch (const scenario_error&) {
    throw;
  } catch (const kelp::invalid_argument& e) {
    r.fail(p, e.what());
  }
}

/// The seabed's `heightfield` as JSON: the file's name, or the grid; null when there is none.
nlohmann::json seabed_heightfield_json(const Scenario& s) {
  if (!s.heightfield) return nullptr;
  if (!s.heightfield_file.empty()) return s.heightfield_file;
  const auto& h = *s.heightfield;
  return {{"origin", {h.origin.x(), h.origin.y()}},
          {"spacing", {h.spacing.x(), h.spacing.y()}},
          {"size", {h.rows, h.cols}},
          {"depth", h.depth}};
}

// ------------------------------------------------------------------------------------------------
// The schema: one table per JSON object, in the order the keys are read (the first error found is
// the one reported). Each line is one key: its name, the member, its kind with its range or
// options, and (after the range) when it is written back. scenario_json writes objects with
// sorted keys, so the order matters to the reading only. See scenario_schema.hpp for the kinds
// and rules.
// ------------------------------------------------------------------------------------------------
using namespace schema;

/// The contact keys an obstacle may set.
template <class V>
void contact_fields(V& v, kelp::environment::ContactProperties& c) {
  v.unit("1").number("friction", c.friction, 0, 100);
  v.unit("N/m³").number("stiffness", c.stiffness, 1e-6, 1e13);
  v.unit("Pa s/m").number("damping", c.damping, 0, 1e13);
}

/// An obstacle `{"type": "cylinder", ...}` (`type` and `name` are read by the list).
template <class V>
void cylinder_fields(V& v, kelp::environment::Cylinder& c) {
  v.key("type");
  v.key("name");
  v.unit("m").vec3("from", c.from, required);
  v.unit("m").vec3("to", c.to, required);
  v.unit("m").number("radius", c.radius, 1e-6, 1e4, required);
  contact_fields(v, c.contact);
}

/// An obstacle `{"type": "box", ...}` (`type` and `name` are read by the list).
template <class V>
void box_fields(V& v, kelp::environment::Box& b) {
  v.key("type");
  v.key("name");
  v.unit("m").vec3("center", b.center, required);
  v.unit("m").vec3("half_extents", b.half_extents, required);
  v.unit("rad").number("yaw", b.yaw, -100, 100);
  v.unit("rad").number("roll", b.roll, -100, 100, unless(0.0));
  v.unit("rad").number("pitch", b.pitch, -100, 100, unless(0.0));
  contact_fields(v, b.contact);
}

/// `"seabed": {"depth": m}` or `{"heightfield": "file" | {...}}`, optional `"friction"`.
template <class V>
void seabed_fields(V& v, Scenario& s) {
  v.check([](const Reader& r, const std::string& p, const nlohmann::json& b) {
    if (b.contains("depth") && b.contains("heightfield"))
      r.fail(p, "expected \"depth\" (flat) or \"heightfield\", not both");
  });
  v.unit("m").number("depth", s.seabed_depth, 0.1, 1e5, finite);
  v.unit("1").number("friction", s.seabed_friction, 0, 100, if_set);
  v.custom(
      "heightfield",
      [&](const nlohmann::json& h, const Reader& r, const std::string& p) {
        parse_seabed_heightfield(h, r, p, s);
      },
      [&] { return seabed_heightfield_json(s); });
}

/// The boat's winch (`"tether": {"winch": {...}}`); given, it is enabled.
template <class V>
void winch_fields(V& v, Scenario& s) {
  WinchScenario& x = s.winch;
  v.on_read([&] { x.enabled = true; });
  v.unit("m/s").number("max_speed", x.max_speed, 0.01, 10);
  v.unit("m/s²").number("max_acceleration", x.max_acceleration, 0.01, 100);
  v.unit("N").number("max_pull", x.max_pull, 1, 1e6);
  v.unit("m").number("min_length", x.min_length, 0.5, 1000);
  v.unit("m").number("max_length", x.max_length, 0.5, 1000);
  v.choice("strategy", s.winch_strategy, winch_strategy_names);
  v.unit("N").number("tension_low", x.tension_low, 0, 1e5);
  v.unit("N").number("tension_high", x.tension_high, 0, 1e5);
  v.unit("m/s/N").number("tension_gain", x.tension_gain, 0, 10);
  v.unit("1").number("slack", x.slack, 0, 10);
  v.unit("m").number("extra_length", x.extra_length, 0, 1000);
  v.unit("1").number("length_per_depth", x.length_per_depth, 0, 10);
  v.unit("1").number("length_per_offset", x.length_per_offset, 0, 10);
  v.unit("1/s").number("length_gain", x.length_gain, 0, 100);
  v.check([&](const Reader& r, const std::string& p) {
    if (x.max_length < x.min_length) r.fail(p + "/max_length", "expected at least min_length");
    if (x.tension_high <= x.tension_low)
      r.fail(p + "/tension_high", "expected more than tension_low");
    if (s.tether_length < x.min_length || s.tether_length > x.max_length)
      r.fail("/tether/length", "expected within the winch's [min_length, max_length]");
  });
}

/// The `navigation` object: the mode, the seed and every sensor's parameters. Rates up to the
/// closed loop's 100 steps per second: a sensor samples at most once a step.
template <class V>
void navigation_fields(V& v, NavigationSettings& n) {
  v.choice("mode", n.mode, navigation_mode_names);
  v.integer("seed", n.seed, 0, 1e18);
  PairSensors& s = n.sensors;
  v.object("imu", true, [&](auto& o) {
    o.unit("Hz").number("rate", s.imu.rate, 1, 100);
    o.unit("rad/s/√Hz").number("gyro_noise_density", s.imu.gyro_noise_density, 0, 0.1);
    o.unit("rad/s²/√Hz").number("gyro_bias_walk", s.imu.gyro_bias_walk, 0, 0.1);
    o.unit("rad/s").number("gyro_bias_initial", s.imu.gyro_bias_initial, 0, 0.5);
    o.unit("m/s²/√Hz").number("accel_noise_density", s.imu.accel_noise_density, 0, 1);
    o.unit("m/s³/√Hz").number("accel_bias_walk", s.imu.accel_bias_walk, 0, 1);
    o.unit("m/s²").number("accel_bias_initial", s.imu.accel_bias_initial, 0, 2);
  });
  v.object("depth", true, [&](auto& o) {
    o.unit("Hz").number("rate", s.depth.rate, 0.01, 100);
    o.unit("m").number("noise", s.depth.noise, 0, 10);
    o.unit("m").number("bias", s.depth.bias, -100, 100);
  });
  v.object("dvl", true, [&](auto& o) {
    o.unit("Hz").number("bottom_rate", s.dvl.bottom_rate, 0.01, 100);
    o.unit("Hz").number("water_rate", s.dvl.water_rate, 0.01, 100);
    o.unit("m").number("min_altitude", s.dvl.min_altitude, 0, 1000);
    o.unit("m").number("max_altitude", s.dvl.max_altitude, 0, 1e4);
    o.check([&](const Reader& r, const std::string& p) {
      if (s.dvl.max_altitude <= s.dvl.min_altitude)
        r.fail(p + "/max_altitude", "expected more than /navigation/dvl/min_altitude (" +
                                        std::to_string(s.dvl.min_altitude) + ")");
    });
    o.unit("m/s").number("noise_floor", s.dvl.noise_floor, 0, 10);
    o.unit("1").number("noise_fraction", s.dvl.noise_fraction, 0, 1);
    o.boolean("water_track", s.dvl.water_track);
    o.unit("m/s").number("water_noise", s.dvl.water_noise, 0, 10);
    o.unit("m").number("water_track_distance", s.dvl.water_track_distance, 0, 100);
  });
  v.object("compass", true, [&](auto& o) {
    o.unit("Hz").number("rate", s.compass.rate, 0.01, 100);
    o.unit("rad").number("noise", s.compass.noise, 0, 1);
    o.unit("rad").number("bias", s.compass.bias, -3.15, 3.15);
  });
  v.object("gps", true, [&](auto& o) {
    o.unit("Hz").number("rate", s.gps.rate, 0.01, 100);
    o.unit("m").number("noise", s.gps.noise, 0, 100);
    o.unit("m").number("bias_sigma", s.gps.bias_sigma, 0, 100);
    o.unit("s").number("bias_time", s.gps.bias_time, 0.01, 1e6);
    o.unit("1").number("vertical_factor", s.gps.vertical_factor, 0, 10);
  });
  v.object("usbl", true, [&](auto& o) {
    o.unit("Hz").number("rate", s.usbl.rate, 0.01, 100);
    o.unit("m").number("noise_floor", s.usbl.noise_floor, 0, 100);
    o.unit("1").number("noise_fraction", s.usbl.noise_fraction, 0, 1);
    o.unit("s").number("latency", s.usbl.latency, 0, 10);
    o.check([&](const Reader& r, const std::string& p) {
      if (s.usbl.latency * s.usbl.rate >= kelp::nav::usbl_queue_capacity - 2)
        r.fail(p, "latency × rate must be < " + std::to_string(kelp::nav::usbl_queue_capacity - 2) +
                      " (fixes in flight)");
    });
    o.unit("1").number("dropout", s.usbl.dropout, 0, 0.99);
    o.unit("m").number("max_range", s.usbl.max_range, 0.1, 1e4);
  });
}

/// A regular wave of a custom sea (`"sea": {"regular": {...}}`): its height and exactly one of
/// period and wavelength (the breaking limit is the environment's check, in world_setup).
template <class V>
void regular_wave_fields(V& v, RegularWaveScenario& x) {
  v.on_read([&] { x.enabled = true; });
  v.check([](const Reader& r, const std::string& p, const nlohmann::json& b) {
    if (b.contains("period") == b.contains("wavelength"))
      r.fail(p, "expected \"period\" or \"wavelength\" (exactly one)");
  });
  v.unit("m").number("height", x.height, 0, 30, required);
  v.unit("s").number("period", x.period, 0.5, 60, if_set);
  v.unit("m").number("wavelength", x.wavelength, 0.5, 5000, if_set);
  v.unit("rad").number("direction", x.direction, -10, 10);
  v.unit("rad").number("phase", x.phase, -10, 10);
}

/// A vehicle's battery (`"battery": {"asv": {...}, "auv": {...}}`).
template <class V>
void battery_fields(V& v, BatteryScenario& b) {
  v.unit("A h").number("capacity_ah", b.capacity_ah, 0.01, 1e5);
  v.integer("cells_in_series", b.cells_in_series, 1, 1000);
  v.unit("Ω").number("internal_resistance", b.internal_resistance, 0.0, 100.0);
  v.unit("1").number("initial_soc", b.initial_soc, 0.0, 1.0);
  v.unit("A").number("hotel_current", b.hotel_current, 0.0, 1000.0);
}

void parse_fleet(const nlohmann::json& fleet, const Reader& r, Scenario& s);
nlohmann::json fleet_json(Scenario& s);

/// A fleet vehicle (`name`, `vehicle` and the controller's `target` are read by the list).
template <class V>
void fleet_vehicle_fields(V& v, FleetVehicleScenario& x) {
  v.key("name");
  v.key("vehicle");
  v.unit("m").vec3("start", x.start);
  v.unit("rad").number("heading", x.heading, -10, 10);
  v.object("controller", true, [&](auto& o) {
    FleetControllerScenario& c = x.controller;
    o.choice("type", c.type, fleet_control_names, required);
    o.unit("m").vec3("position", c.position);
    o.unit("rad").number("heading", c.heading, -10, 10);
    o.unit("m").vec3_list("waypoints", c.waypoints, if_set);
    o.unit("m/s").number("leg_speed", c.leg_speed, 0.01, 10);
    o.key("target");
    o.unit("m").vec3("offset", c.offset);
  });
}

/// A fleet point mass (`name` read by the list).
template <class V>
void fleet_point_mass_fields(V& v, FleetPointMassScenario& x) {
  v.key("name");
  v.unit("kg").number("mass", x.mass, 1e-3, 1e7, required);
  v.unit("m³").number("volume", x.volume, 0, 1e4);
  v.unit("1").number("added_mass_coefficient", x.added_mass_coefficient, 0, 10);
  v.unit("m²").number("drag_area", x.drag_area, 0, 1e4);
  v.unit("m").vec3("start", x.start, required);
}

/// A fleet anchor (`name` read by the list).
template <class V>
void fleet_anchor_fields(V& v, FleetAnchorScenario& x) {
  v.key("name");
  v.unit("m").vec3("position", x.position, required);
}

/// A fleet tether (`name`, `from` and `to` read by the list).
template <class V>
void fleet_tether_fields(V& v, FleetTetherScenario& x) {
  v.key("name");
  v.key("from");
  v.key("to");
  v.unit("m").vec3("from_point", x.from_point, if_set);
  v.unit("m").vec3("to_point", x.to_point, if_set);
  v.unit("m").number("length", x.length, 0.5, 10000, required);
  v.unit("m").number("segment_length", x.segment_length, 0.05, 100);
  v.unit("m").number("diameter", x.diameter, 1e-4, 0.5, if_set);
  v.unit("kg/m").number("mass_per_length", x.mass_per_length, 1e-4, 1000, if_set);
  v.unit("N").number("axial_stiffness", x.axial_stiffness, 1, 1e11, if_set);
  v.unit("1").number("internal_damping_ratio", x.internal_damping_ratio, 0, 1000, if_set);
  v.unit("1").number("normal_drag", x.normal_drag, 0, 10, if_set);
  v.unit("1").number("tangential_drag", x.tangential_drag, 0, 10, if_set);
  v.unit("N").number("breaking_strength", x.breaking_strength, 0, 1e9, if_set);
  v.object("winch", x.winch.enabled, [&](auto& o) {
    FleetWinchScenario& w = x.winch;
    o.on_read([&] { w.enabled = true; });
    o.unit("m/s").number("max_speed", w.max_speed, 0.01, 10);
    o.unit("m/s²").number("max_acceleration", w.max_acceleration, 0.01, 100);
    o.unit("N").number("max_pull", w.max_pull, 1, 1e7);
    o.unit("m").number("min_length", w.min_length, 0.5, 10000);
    o.unit("m").number("max_length", w.max_length, 0.5, 10000);
    o.unit("m/s").number("payout_rate", w.payout_rate, -10, 10);
    o.check([&](const Reader& r, const std::string& p) {
      if (w.max_length < w.min_length) r.fail(p + "/max_length", "expected at least min_length");
      if (x.length < w.min_length || x.length > w.max_length)
        r.fail(p, "the tether's length must be within [min_length, max_length]");
    });
  });
}

void parse_obstacles(const nlohmann::json& list, const Reader& r, Scenario& s);
nlohmann::json obstacles_json(Scenario& s);

/// The scenario file: every key of the schema (the nested objects' tables above or inline).
template <class V>
void scenario_fields(V& v, Scenario& s) {
  v.unit("s").number("duration", s.duration, 1e-3, 1e7);
  v.integer("seed", s.seed, 0, 1e18);
  // The sea: a preset's name, or an object of values (then "custom", its peak period 8 s unless
  // set).
  v.preset_or_object("sea", s.sea, sea_names, Sea::custom, [&](auto& o) {
    o.on_read([&] {
      s.sea = Sea::custom;
      s.peak_period = 8.0;
    });
    o.unit("m").number("significant_height", s.significant_height, 0, 20);
    o.unit("s").number("peak_period", s.peak_period, 1, 30);
    o.unit("rad").number("wave_direction", s.wave_direction, -10, 10);
    o.unit("m/s").number("wind_speed", s.wind_speed, 0, 60);
    o.unit("rad").number("wind_direction", s.wind_direction, -10, 10);
    o.unit("m/s").number("current_speed", s.current_speed, 0, 5);
    o.unit("rad").number("current_direction", s.current_direction, -10, 10);
    o.whole("wave_components", s.wave_components, 1, 4096);
    o.object("regular", s.regular_wave.enabled,
             [&](auto& r) { regular_wave_fields(r, s.regular_wave); });
    o.choice("stretching", s.wave_stretching, wave_stretching_names,
             unless(kelp::environment::WaveStretching::vertical));
  });
  // The cable properties are written when set (unset: keep the kind's).
  v.object("tether", true, [&](auto& o) {
    o.unit("N").number("breaking_strength", s.breaking_strength, 0, 1e7, if_set);
    o.unit("m").number("diameter", s.diameter, 1e-4, 0.5, if_set);
    o.unit("kg/m").number("mass_per_length", s.mass_per_length, 1e-4, 100, if_set);
    o.unit("N").number("axial_stiffness", s.axial_stiffness, 1, 1e10, if_set);
    o.unit("N s").number("internal_damping", s.internal_damping, 0, 1e6, if_set);
    o.unit("1").number("internal_damping_ratio", s.internal_damping_ratio, 0, 1000, if_set);
    o.unit("1").number("normal_drag", s.normal_drag, 0, 10, if_set);
    o.unit("1").number("tangential_drag", s.tangential_drag, 0, 10, if_set);
    o.unit("m").number("length", s.tether_length, 0.5, 1000);
    o.choice("kind", s.tether_kind, tether_kind_names);
    o.unit("m").number("segment_length", s.segment_length, 0.05, 10);
    o.boolean("explicit_fallback", s.explicit_fallback);
    o.choice("line_model", s.line_model, line_model_names, unless(kelp::tether::LineModel::kelp));
    o.object("winch", s.winch.enabled, [&](auto& w) { winch_fields(w, s); });
  });
  v.object("vehicles", true, [&](auto& o) {
    o.unit("m").vec3("asv_attachment", s.asv_attachment);
    o.unit("m").vec3("auv_attachment", s.auv_attachment);
    o.unit("m").vec3("auv_start", s.auv_start, if_set);
  });
  v.object("start", true, [&](auto& o) {
    o.unit("s").number("ramp", s.start_ramp, 0, 1e5);
    o.boolean("with_water", s.start_with_water);
  });
  v.object("control", true, [&](auto& o) {
    o.choice("preset", s.control_preset, control_preset_names);
    o.on_read([&] {
      // the paper's, unless set
      if (s.control_preset == ControlPreset::paper) s.asv_thrust_clip = 15.0;
    });
    o.boolean("compensation", s.compensation);
    o.object("asv", true, [&](auto& a) {
      a.boolean("station", s.asv_station, unless(false));
      a.gains("linear", s.asv_linear);
      a.gains("angular", s.asv_angular);
      a.gains("yaw", s.asv_yaw);
      a.unit("N").number("thrust_clip", s.asv_thrust_clip, 0.1, 30.6);
      a.unit("Hz").number("rate", s.asv_rate, 0.1, 1000);
    });
    o.object("auv", true, [&](auto& a) {
      a.gains("surge", s.auv_surge);
      a.gains("sway", s.auv_sway);
      a.gains("heave", s.auv_heave);
      a.gains("yaw", s.auv_yaw);
      a.unit("Hz").number("rate", s.auv_rate, 0.1, 1000);
    });
  });
  v.object("mission", true, [&](auto& o) {
    o.unit("m").number("depth", s.depth, 0.5, 1000);
    o.unit("m").number("square_side", s.square_side, 0.5, 1000);
    o.unit("m").vec3_list("waypoints", s.waypoints, if_set);
  });
  // mcap only when off: writing a bag does not change the run, so the default leaves the JSON
  // (and the run hashes of kelp-sweep, which key stored results) as they were.
  v.object("output", true, [&](auto& o) {
    o.unit("Hz").number("log_rate", s.log_rate, 0.01, 100);
    o.unit("Hz").number("node_rate", s.node_rate, 0.001, 100);
    o.boolean("mcap", s.mcap, unless(true));
  });
  // Navigation: likewise only when it differs from the default (perfect navigation).
  v.object("navigation", unless_default, [&](auto& o) { navigation_fields(o, s.navigation); });
  // Propulsion (thrusters' lag, batteries).
  v.object("thrusters", true, [&](auto& o) {
    o.boolean("propulsion", s.propulsion);
    o.boolean("lag", s.thruster_lag);
    o.unit("s").number("time_constant", s.thruster_time_constant, 0.0, 10.0);
  });
  v.object("battery", true, [&](auto& o) {
    o.object("asv", true, [&](auto& b) { battery_fields(b, s.asv_battery); });
    o.object("auv", true, [&](auto& b) { battery_fields(b, s.auv_battery); });
  });
  // Obstacles and seabed: only when the scenario has them.
  v.custom(
      "obstacles",
      [&](const nlohmann::json& list, const Reader& r, const std::string&) {
        parse_obstacles(list, r, s);
      },
      [&] { return obstacles_json(s); });
  v.object("seabed", non_empty, [&](auto& o) { seabed_fields(o, s); });
  // Any fleet instead of the pair: only when the scenario has one.
  v.custom(
      "fleet",
      [&](const nlohmann::json& fleet, const Reader& r, const std::string&) {
        parse_fleet(fleet, r, s);
      },
      [&] { return fleet_json(s); });
  // Entanglement thresholds: only when they differ from the defaults (the JSON of a scenario
  // without them, and kelp-sweep's run hashes, stay as they were).
  v.object("entanglement", unless_default, [&](auto& o) {
    EntanglementSettings& x = s.entanglement;
    o.unit("rad").number("wrap_threshold", x.wrap_threshold, 1e-3, 1e3);
    o.unit("rad").number("wrap_hysteresis", x.wrap_hysteresis, 0, 1e3);
    o.unit("m").number("contact_margin", x.contact_margin, 0, 10);
    o.unit("m/s").number("pin_slip_speed", x.pin_slip_speed, 1e-6, 10);
    o.unit("N").number("pin_tension_difference", x.pin_tension_difference, 1e-3, 1e6);
    o.unit("s").number("pin_hold_time", x.pin_hold_time, 0, 1e4);
    o.check([&](const Reader& r, const std::string& p) {
      if (x.wrap_hysteresis > x.wrap_threshold)
        r.fail(p + "/wrap_hysteresis", "expected at most wrap_threshold");
    });
  });
  // The kernel only when pinned: the default leaves the JSON (and kelp-sweep's run hashes) as they
  // were. `deterministic` is read only: true pins "portable".
  using kelp::simd::KernelPath;
  v.choice("kernel", s.kernel, kernel_path_names, unless(KernelPath::automatic));
  bool deterministic = false;
  v.boolean("deterministic", deterministic, never);
  v.check([&](const Reader& r, const std::string&) {
    if (!deterministic) return;
    if (s.kernel != KernelPath::automatic && s.kernel != KernelPath::portable)
      r.fail("/deterministic", std::string("true pins the \"portable\" kernel, but /kernel is \"") +
                                   to_string(s.kernel) + "\"");
    s.kernel = KernelPath::portable;
  });
}

/// `"obstacles": [...]` into s.cylinders, s.boxes (and an height field).
void parse_obstacles(const nlohmann::json& list, const Reader& r, Scenario& s) {
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
        kelp::environment::Cylinder c;
        c.name = name;
        c.radius = -1;
        auto fields = [&](auto& v) { cylinder_fields(v, c); };
        parse_object(r, o, p, fields);
        check.add(c);
        s.cylinders.push_back(c);
      } else if (type == "box") {
        kelp::environment::Box b;
        b.name = name;
        auto fields = [&](auto& v) { box_fields(v, b); };
        parse_object(r, o, p, fields);
        check.add(b);
        s.boxes.push_back(b);
      } else if (type == "heightfield") {
        if (s.heightfield) r.fail(p, "a second height field (one seabed per scenario)");
        kelp::environment::HeightField hf = parse_heightfield_object(o, r, p, true);
        kelp::environment::validate(hf);
        s.heightfield = std::move(hf);
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

/// The obstacles as JSON (cylinders, then boxes); null when there are none.
namespace {
/// A non-empty string at o[key] (or `fallback` when absent and allowed).
std::string fleet_string(const Reader& r, const nlohmann::json& o, const std::string& p,
                         const char* key, bool required_key) {
  if (!o.contains(key)) {
    if (required_key) r.fail(p, std::string("missing \"") + key + "\"");
    return {};
  }
  const auto& v = o.at(key);
  if (!v.is_string() || v.get<std::string>().empty())
    r.fail(p + "/" + key, "expected a non-empty string");
  return v.get<std::string>();
}

/// Parses `list` (an array at `path`) element by element with `one(element, path)`.
template <class F>
void fleet_list(const Reader& r, const nlohmann::json& fleet, const char* key, F&& one) {
  const std::string p = std::string("/fleet/") + key;
  if (!fleet.contains(key)) return;
  const auto& list = fleet.at(key);
  if (!list.is_array()) r.fail(p, "expected an array");
  if (list.size() > 1000) r.fail(p, "at most 1000 entries");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string q = p + "/" + std::to_string(i);
    if (!list[i].is_object()) r.fail(q, "expected an object");
    one(list[i], q);
  }
}
}  // namespace

void parse_fleet(const nlohmann::json& fleet, const Reader& r, Scenario& s) {
  r.object(fleet, "/fleet", {"vehicles", "point_masses", "anchors", "tethers"});
  FleetScenario f;
  std::set<std::string> names;  // every vehicle, point mass and anchor: the tethers' ends
  // A part's name becomes topics, frames (kelp/sim/ros2/fleet.hpp) and CSV column names.
  const auto ros_name = [&](const std::string& name, const std::string& p) {
    if (!ros2::is_ros_name(name))
      r.fail(p + "/name", "\"" + name +
                              "\" is not a ROS name (a letter, then letters, digits and single "
                              "underscores, at most 64 characters)");
  };
  const auto unique = [&](const std::string& name, const std::string& p) {
    ros_name(name, p);
    if (name == "free") r.fail(p + "/name", "\"free\" names a free tether end");
    if (!names.insert(name).second) r.fail(p + "/name", "\"" + name + "\" names another part");
  };
  fleet_list(r, fleet, "vehicles", [&](const nlohmann::json& o, const std::string& p) {
    FleetVehicleScenario x;
    x.name = fleet_string(r, o, p, "name", true);
    unique(x.name, p);
    x.vehicle = fleet_string(r, o, p, "vehicle", true);
    auto fields = [&](auto& v) { fleet_vehicle_fields(v, x); };
    parse_object(r, o, p, fields);
    if (o.contains("controller"))
      x.controller.target = fleet_string(r, o.at("controller"), p + "/controller", "target",
                                         x.controller.type == FleetControl::follow);
    if (x.controller.type == FleetControl::waypoints && x.controller.waypoints.empty())
      r.fail(p + "/controller/waypoints", "expected at least one waypoint");
    f.vehicles.push_back(std::move(x));
  });
  if (f.vehicles.empty() && !fleet.contains("point_masses"))
    r.fail("/fleet/vehicles", "expected at least one vehicle or point mass");
  fleet_list(r, fleet, "point_masses", [&](const nlohmann::json& o, const std::string& p) {
    FleetPointMassScenario x;
    x.name = fleet_string(r, o, p, "name", true);
    unique(x.name, p);
    auto fields = [&](auto& v) { fleet_point_mass_fields(v, x); };
    parse_object(r, o, p, fields);
    f.point_masses.push_back(x);
  });
  fleet_list(r, fleet, "anchors", [&](const nlohmann::json& o, const std::string& p) {
    FleetAnchorScenario x;
    x.name = fleet_string(r, o, p, "name", true);
    unique(x.name, p);
    auto fields = [&](auto& v) { fleet_anchor_fields(v, x); };
    parse_object(r, o, p, fields);
    f.anchors.push_back(x);
  });
  // The follow targets name vehicles.
  for (std::size_t i = 0; i < f.vehicles.size(); ++i) {
    const auto& c = f.vehicles[i].controller;
    if (c.type != FleetControl::follow) continue;
    const bool found = std::any_of(f.vehicles.begin(), f.vehicles.end(),
                                   [&](const auto& v) { return v.name == c.target; });
    if (!found || c.target == f.vehicles[i].name)
      r.fail("/fleet/vehicles/" + std::to_string(i) + "/controller/target",
             "\"" + c.target + "\" is not another vehicle of the fleet");
  }
  std::set<std::string> tether_names;
  fleet_list(r, fleet, "tethers", [&](const nlohmann::json& o, const std::string& p) {
    FleetTetherScenario x;
    x.name = fleet_string(r, o, p, "name", true);
    ros_name(x.name, p);
    if (!tether_names.insert(x.name).second)
      r.fail(p + "/name", "\"" + x.name + "\" names another tether");
    x.from = fleet_string(r, o, p, "from", true);
    x.to = fleet_string(r, o, p, "to", true);
    for (const char* end : {"from", "to"}) {
      const std::string& n = end[0] == 'f' ? x.from : x.to;
      if (n != "free" && !names.count(n))
        r.fail(p + "/" + end, "\"" + n + "\" is not a vehicle, point mass or anchor of the fleet");
    }
    if (x.from == "free" && x.to == "free") r.fail(p + "/to", "at most one end may be free");
    auto fields = [&](auto& v) { fleet_tether_fields(v, x); };
    parse_object(r, o, p, fields);
    if (x.winch.enabled && x.from == "free")
      r.fail(p + "/winch", "a winch needs a fixed start end");
    f.tethers.push_back(std::move(x));
  });
  s.fleet = std::move(f);
}

nlohmann::json fleet_json(Scenario& s) {
  if (!s.fleet) return nullptr;
  nlohmann::json out = nlohmann::json::object();
  const auto list = [&](const char* key, auto& items, auto&& fields, auto&& strings) {
    if (items.empty()) return;
    nlohmann::json a = nlohmann::json::array();
    for (auto& x : items) {
      nlohmann::json o = write_object([&](auto& v) { fields(v, x); });
      strings(o, x);
      a.push_back(o);
    }
    out[key] = a;
  };
  list(
      "vehicles", s.fleet->vehicles, [](auto& v, auto& x) { fleet_vehicle_fields(v, x); },
      [](nlohmann::json& o, const FleetVehicleScenario& x) {
        o["name"] = x.name;
        o["vehicle"] = x.vehicle;
        if (!x.controller.target.empty()) o["controller"]["target"] = x.controller.target;
      });
  list(
      "point_masses", s.fleet->point_masses,
      [](auto& v, auto& x) { fleet_point_mass_fields(v, x); },
      [](nlohmann::json& o, const FleetPointMassScenario& x) { o["name"] = x.name; });
  list(
      "anchors", s.fleet->anchors, [](auto& v, auto& x) { fleet_anchor_fields(v, x); },
      [](nlohmann::json& o, const FleetAnchorScenario& x) { o["name"] = x.name; });
  list(
      "tethers", s.fleet->tethers, [](auto& v, auto& x) { fleet_tether_fields(v, x); },
      [](nlohmann::json& o, const FleetTetherScenario& x) {
        o["name"] = x.name;
        o["from"] = x.from;
        o["to"] = x.to;
      });
  return out;
}

nlohmann::json obstacles_json(Scenario& s) {
  if (s.cylinders.empty() && s.boxes.empty()) return nullptr;
  nlohmann::json list = nlohmann::json::array();
  for (auto& c : s.cylinders) {
    nlohmann::json o = write_object([&](auto& v) { cylinder_fields(v, c); });
    o["type"] = "cylinder";
    o["name"] = c.name;
    list.push_back(o);
  }
  for (auto& b : s.boxes) {
    nlohmann::json o = write_object([&](auto& v) { box_fields(v, b); });
    o["type"] = "box";
    o["name"] = b.name;
    list.push_back(o);
  }
  return list;
}

namespace {

/// The rows of `table` walked over `x` at `path`, as a Markdown table.
template <class X, class Table>
std::string reference_table(const std::string& path, X& x, Table&& table) {
  std::vector<schema::Reference::Row> rows;
  schema::Reference ref(rows, path);
  table(ref, x);
  // One table per object, in the order the objects are first met.
  std::vector<std::pair<std::string, std::string>> tables;
  for (const auto& r : rows) {
    const std::string p = r.path.substr(0, r.path.rfind('/'));
    auto t =
        std::find_if(tables.begin(), tables.end(), [&](const auto& e) { return e.first == p; });
    if (t == tables.end()) {
      tables.push_back({p,
                        "| key | type | unit | default | allowed | notes |\n"
                        "|---|---|---|---|---|---|\n"});
      t = tables.end() - 1;
    }
    const std::string key = r.path.substr(r.path.rfind('/') + 1);
    t->second += "| `" + key + "` | " + r.type + " | " + r.unit + " | " +
                 (r.value.empty() ? "" : "`" + r.value + "`") + " | " + r.allowed + " | " + r.note +
                 " |\n";
  }
  std::string out;
  for (const auto& [p, rows_md] : tables)
    out += "\n### `" + (p.empty() ? std::string("/") : p) + "`\n\n" + rows_md;
  return out;
}

}  // namespace

std::vector<std::string> scenario_reference_examples() {
  return {
      R"({
  "duration": 120,
  "seed": 1,
  "sea": "rough",
  "tether": {"length": 15, "segment_length": 0.5},
  "control": {"preset": "paper", "compensation": true},
  "mission": {"depth": 5, "square_side": 10}
})",
      R"({
  "sea": {"significant_height": 1.5, "peak_period": 7, "wind_speed": 5, "current_speed": 0.3,
          "regular": {"height": 0.5, "period": 6, "direction": 0.5}, "stretching": "wheeler"},
  "start": {"ramp": 20}
})",
      R"({
  "tether": {"length": 20, "winch": {"strategy": "constant_tension", "tension_low": 5,
                                     "tension_high": 25, "max_length": 40}},
  "mission": {"waypoints": [[0, 0, 5], [10, 0, 10], [10, 10, 10]]}
})",
      R"({
  "navigation": {"mode": "sensors", "seed": 3, "usbl": {"rate": 0.5, "latency": 1}},
  "output": {"log_rate": 20, "node_rate": 2, "mcap": false},
  "deterministic": true
})",
      R"({
  "obstacles": [{"type": "cylinder", "name": "pile", "from": [5, 5, -2], "to": [5, 5, 30],
                 "radius": 0.5}],
  "seabed": {"depth": 30, "friction": 0.5}
})",
      R"({
  "fleet": {
    "vehicles": [{"name": "boat", "vehicle": "blueboat", "controller": {"type": "hold"}},
                 {"name": "rov", "vehicle": "bluerov2_heavy", "start": [2, 0, 5],
                  "controller": {"type": "follow", "target": "boat", "offset": [0, 0, 5]}}],
    "tethers": [{"name": "umbilical", "from": "boat", "to": "rov", "length": 12}]
  }
})",
  };
}

std::string scenario_reference_markdown() {
  std::string out =
      "# Scenario file reference\n\n"
      "<!-- Generated by kelp_scenario_reference from the parser's table (scenario_fields in\n"
      "     src/scenario.cpp); do not edit: `cmake --build <build> --target "
      "scenario_reference_update`. -->\n\n"
      "Every key a scenario file may hold (JSON), as kelp-tethered-pair, kelp-sweep, kelp-sitl,\n"
      "`kelp.run_scenario` and `kelp::sim::parse_scenario` read it. Every key is optional unless\n"
      "marked required; a missing key keeps its default, which is the embedded default run\n"
      "(`{}`). A key outside these tables, a value of the wrong type or outside its range is\n"
      "refused with the file's name and the JSON path. Frames: positions and waypoints are NED\n"
      "(north, east, down) [m]; attachment points are in the vehicle's body frame (x forward,\n"
      "y starboard, z down) [m]; directions are azimuths from north, clockwise [rad]. A unit\n"
      "of 1 is a ratio. The keys are listed in the order they are read (the first error found\n"
      "is the one reported). How the keys work together: [scenarios.md](scenarios.md) and\n"
      "[apps/tethered_pair/README.md](../apps/tethered_pair/README.md#scenario-files).\n";
  Scenario s;
  out += reference_table("", s, [](auto& v, Scenario& x) { scenario_fields(v, x); });
  out +=
      "\n## Lists\n\n`/obstacles` is an array of obstacles, each an object with `\"type\"`: "
      "`\"cylinder\"`, `\"box\"` or `\"heightfield\"` and an optional `\"name\"`; "
      "`/seabed/heightfield` is a file in MoorDyn's seafloor format (relative to the scenario "
      "file) or an object `{\"origin\": [x, y], \"spacing\": [dx, dy], \"size\": [rows, cols], "
      "\"depth\": [...]}` [m] (as the height-field obstacle).\n";
  kelp::environment::Cylinder c;
  out += reference_table("/obstacles/N (cylinder)", c,
                         [](auto& v, kelp::environment::Cylinder& x) { cylinder_fields(v, x); });
  kelp::environment::Box b;
  out += reference_table("/obstacles/N (box)", b,
                         [](auto& v, kelp::environment::Box& x) { box_fields(v, x); });
  out +=
      "\n`/fleet` runs any fleet instead of the pair: `vehicles`, `point_masses`, `anchors` "
      "and `tethers`, arrays of objects, each with a `\"name\"` (a ROS name: a letter, then "
      "letters, digits and single underscores); a vehicle's `\"vehicle\"` names a preset "
      "(\"bluerov2_heavy\", \"blueboat\") or a vehicle file; a tether's `\"from\"` and "
      "`\"to\"` name a vehicle, a point mass, an anchor or `\"free\"`; a follow controller's "
      "`\"target\"` names another vehicle.\n";
  FleetVehicleScenario fv;
  out += reference_table("/fleet/vehicles/N", fv,
                         [](auto& v, FleetVehicleScenario& x) { fleet_vehicle_fields(v, x); });
  FleetPointMassScenario fp;
  out += reference_table("/fleet/point_masses/N", fp,
                         [](auto& v, FleetPointMassScenario& x) { fleet_point_mass_fields(v, x); });
  FleetAnchorScenario fa;
  out += reference_table("/fleet/anchors/N", fa,
                         [](auto& v, FleetAnchorScenario& x) { fleet_anchor_fields(v, x); });
  FleetTetherScenario ft;
  out += reference_table("/fleet/tethers/N", ft,
                         [](auto& v, FleetTetherScenario& x) { fleet_tether_fields(v, x); });
  out += "\n## Examples\n\nEach of these parses (the test `docs_scenario_reference` reads them).\n";
  for (const std::string& e : scenario_reference_examples()) out += "\n```json\n" + e + "\n```\n";
  return out;
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
  auto fields = [&](auto& v) { detail::scenario_fields(v, s); };
  detail::schema::parse_object(r, j, "", fields);
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
nlohmann::json scenario_to_json(const Scenario& scenario) {
  // The default scenario's JSON, every object written: what `unless_default` compares with.
  static const nlohmann::json defaults = [] {
    Scenario d;
    return detail::schema::write_object([&](auto& v) { detail::scenario_fields(v, d); });
  }();
  Scenario s = scenario;  // the table's members are mutable (it also reads); the writer only reads
  nlohmann::json j = nlohmann::json::object();
  detail::schema::Writer w(j, &defaults);
  detail::scenario_fields(w, s);
  return j;
}

std::string scenario_json(const Scenario& s, int indent) {
  return scenario_to_json(s).dump(indent);
}

}  // namespace sim
}  // namespace kelp
