// Vehicle files (kelp/sim/vehicle_file.hpp): the JSON reader and writer and the presets as
// descriptions. The format is documented in docs/vehicle-files.md; its keys are listed once per
// object here (the reader's allowed keys and the writer's order).
#include "kelp/sim/vehicle_file.hpp"

#include <cmath>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "json_reader.hpp"
#include "kelp/system/presets.hpp"
#include "kelp/vehicle/presets.hpp"
#include "kelp/vehicle/rigid_body.hpp"
#include "vehicle_check.hpp"

namespace kelp {
namespace sim {

namespace {

using nlohmann::json;
using Matrix6d = Matrix6<double>;

const char* hydrostatics_name(vehicle::Hydrostatics h) {
  switch (h) {
    case vehicle::Hydrostatics::surface:
      return "surface";
    case vehicle::Hydrostatics::submerged_free_surface:
      return "submerged_free_surface";
    case vehicle::Hydrostatics::submerged:
      break;
  }
  return "submerged";
}

// The writer builds nlohmann::json (one instantiation of the library in this unit: an
// ordered_json beside it costs seconds of compile time) and orders the keys when printing.
using ojson = json;

// The order of the keys in a written file (the reader's table, object by object).
const std::vector<std::string>& key_order() {
  static const std::vector<std::string> order = {"name",
                                                 "mass_kg",
                                                 "inertia_kg_m2",
                                                 "center_of_gravity_m",
                                                 "center_of_buoyancy_m",
                                                 "displaced_volume_m3",
                                                 "water_density_kg_m3",
                                                 "gravity_m_s2",
                                                 "added_mass",
                                                 "linear_damping",
                                                 "quadratic_damping",
                                                 "hydrostatics",
                                                 "hull_height_m",
                                                 "waterplane_area_m2",
                                                 "gm_transverse_m",
                                                 "gm_longitudinal_m",
                                                 "wind_areas",
                                                 "frontal_area_m2",
                                                 "lateral_area_m2",
                                                 "length_overall_m",
                                                 "wind_coefficients",
                                                 "cx",
                                                 "cy",
                                                 "cn",
                                                 "attachment_m",
                                                 "hull",
                                                 "center_m",
                                                 "half_extents_m",
                                                 "stiffness_n_per_m",
                                                 "damping_n_s_per_m",
                                                 "damping_depth_m",
                                                 "seabed_friction",
                                                 "friction_velocity_m_s",
                                                 "pwm",
                                                 "min_us",
                                                 "neutral_us",
                                                 "max_us",
                                                 "deadband_us",
                                                 "propulsion",
                                                 "time_constant_s",
                                                 "thrusters",
                                                 "position_m",
                                                 "direction",
                                                 "facing",
                                                 "model",
                                                 "curve",
                                                 "battery",
                                                 "capacity_ah",
                                                 "cells_in_series",
                                                 "internal_resistance_ohm",
                                                 "initial_soc",
                                                 "hotel_current_a",
                                                 "ocv",
                                                 "soc",
                                                 "cell_voltage_v"};
  return order;
}

ojson vec(const Eigen::Ref<const Eigen::VectorXd>& v) {
  ojson a = ojson::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v(i));
  return a;
}

// A square matrix as its diagonal when it is diagonal, else as rows.
template <typename M>
ojson square(const M& m) {
  if (m.isDiagonal(0.0)) return vec(m.diagonal());
  ojson rows = ojson::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) rows.push_back(vec(m.row(i).transpose()));
  return rows;
}

// Reads the keys of one vehicle file; every failure names the file and the JSON path.
class VehicleReader {
 public:
  explicit VehicleReader(const std::string& file) : r_(file) {}

  VehicleDescription read(const json& j) {
    r_.object(j, "",
              {"name",
               "mass_kg",
               "inertia_kg_m2",
               "center_of_gravity_m",
               "center_of_buoyancy_m",
               "displaced_volume_m3",
               "water_density_kg_m3",
               "gravity_m_s2",
               "added_mass",
               "linear_damping",
               "quadratic_damping",
               "hydrostatics",
               "hull_height_m",
               "waterplane_area_m2",
               "gm_transverse_m",
               "gm_longitudinal_m",
               "wind_areas",
               "wind_coefficients",
               "attachment_m",
               "hull",
               "pwm",
               "propulsion"});
    VehicleDescription d;
    const json& name = r_.require(j, "", "name");
    if (!name.is_string() || name.get<std::string>().empty())
      r_.fail("/name", "expected a non-empty string, got " + name.dump());
    d.name = name.get<std::string>();
    vehicle::VehicleParameters<double>& p = d.parameters;
    r_.require(j, "", "mass_kg");
    r_.number(j, "", "mass_kg", p.mass, 1e-9, 1e9);
    p.inertia = matrix<3>(r_.require(j, "", "inertia_kg_m2"), "/inertia_kg_m2");
    if (j.contains("center_of_gravity_m"))
      p.r_g = r_.vec3(j.at("center_of_gravity_m"), "/center_of_gravity_m");
    if (j.contains("center_of_buoyancy_m"))
      p.r_b = r_.vec3(j.at("center_of_buoyancy_m"), "/center_of_buoyancy_m");
    r_.number(j, "", "displaced_volume_m3", p.displaced_volume, 0.0, 1e9);
    r_.number(j, "", "water_density_kg_m3", p.density, 1e-9,
              environment::limits::max_fluid_density);
    r_.number(j, "", "gravity_m_s2", p.gravity, 1e-9, environment::limits::max_gravity);
    if (j.contains("added_mass")) p.added_mass = matrix<6>(j.at("added_mass"), "/added_mass");
    if (j.contains("linear_damping"))
      p.damping.linear = matrix<6>(j.at("linear_damping"), "/linear_damping");
    if (j.contains("quadratic_damping")) {
      const std::vector<double> q =
          r_.numbers(j.at("quadratic_damping"), "/quadratic_damping", {6});
      for (int i = 0; i < 6; ++i) p.damping.quadratic(i) = q[i];
    }
    std::string h = "submerged";
    r_.choice(j, "", "hydrostatics", h, {"submerged", "surface", "submerged_free_surface"});
    p.hydrostatics = h == "surface"                  ? vehicle::Hydrostatics::surface
                     : h == "submerged_free_surface" ? vehicle::Hydrostatics::submerged_free_surface
                                                     : vehicle::Hydrostatics::submerged;
    r_.number(j, "", "hull_height_m", p.hull_height, 0.0, 1e4);
    r_.number(j, "", "waterplane_area_m2", p.waterplane_area, 0.0, 1e6);
    r_.number(j, "", "gm_transverse_m", p.gm_transverse, -1e4, 1e4);
    r_.number(j, "", "gm_longitudinal_m", p.gm_longitudinal, -1e4, 1e4);
    if (j.contains("wind_areas")) {
      const json& w = j.at("wind_areas");
      r_.object(w, "/wind_areas", {"frontal_area_m2", "lateral_area_m2", "length_overall_m"});
      r_.number(w, "/wind_areas", "frontal_area_m2", p.wind_areas.frontal_area, 0.0, 1e6);
      r_.number(w, "/wind_areas", "lateral_area_m2", p.wind_areas.lateral_area, 0.0, 1e6);
      r_.number(w, "/wind_areas", "length_overall_m", p.wind_areas.length_overall, 0.0, 1e4);
    }
    if (j.contains("wind_coefficients")) {
      const json& w = j.at("wind_coefficients");
      r_.object(w, "/wind_coefficients", {"cx", "cy", "cn"});
      r_.number(w, "/wind_coefficients", "cx", p.wind_coefficients.cx, -100.0, 100.0);
      r_.number(w, "/wind_coefficients", "cy", p.wind_coefficients.cy, -100.0, 100.0);
      r_.number(w, "/wind_coefficients", "cn", p.wind_coefficients.cn, -100.0, 100.0);
    }
    if (j.contains("attachment_m")) d.attachment = r_.vec3(j.at("attachment_m"), "/attachment_m");
    if (j.contains("hull")) d.hull = hull(j.at("hull"));
    if (j.contains("pwm")) d.pwm = pwm(j.at("pwm"));
    check_mass_matrix(p);
    if (j.contains("propulsion")) propulsion(j.at("propulsion"), d);
    return d;
  }

 private:
  // A 3×3 or 6×6 matrix written as its diagonal (n numbers) or as n rows of n.
  template <int N>
  Eigen::Matrix<double, N, N> matrix(const json& v, const std::string& p) const {
    Eigen::Matrix<double, N, N> m = Eigen::Matrix<double, N, N>::Zero();
    const std::string shape = std::to_string(N) + " numbers (the diagonal) or " +
                              std::to_string(N) + " rows of " + std::to_string(N);
    if (!v.is_array() || v.size() != std::size_t(N)) fail_shape(v, p, shape);
    if (v[0].is_array()) {
      for (int i = 0; i < N; ++i) {
        const std::string row = p + "/" + std::to_string(i);
        if (!v[i].is_array() || v[i].size() != std::size_t(N)) fail_shape(v[i], row, shape);
        for (int k = 0; k < N; ++k) m(i, k) = r_.finite(v[i][k], row + "/" + std::to_string(k));
      }
    } else {
      for (int i = 0; i < N; ++i) m(i, i) = r_.finite(v[i], p + "/" + std::to_string(i));
    }
    return m;
  }
  [[noreturn]] void fail_shape(const json& v, const std::string& p,
                               const std::string& shape) const {
    r_.fail(p, "expected " + shape + ", got " + v.dump());
  }

  // M = M_RB + M_A must be positive definite (before the library's field checks, which would
  // name the added mass alone).
  void check_mass_matrix(const vehicle::VehicleParameters<double>& p) const {
    const Eigen::Matrix3d sym_i = 0.5 * (p.inertia + p.inertia.transpose());
    const Eigen::LDLT<Eigen::Matrix3d> li(sym_i);
    if (li.info() != Eigen::Success || !(li.vectorD().minCoeff() > 0.0) ||
        !p.inertia.isApprox(p.inertia.transpose(), 1e-9))
      r_.fail("/inertia_kg_m2", "the inertia must be symmetric positive definite");
    Matrix6d m = Matrix6d::Zero();
    m.topLeftCorner<3, 3>() = p.mass * Eigen::Matrix3d::Identity();
    Eigen::Matrix3d s;
    s << 0, -p.r_g(2), p.r_g(1), p.r_g(2), 0, -p.r_g(0), -p.r_g(1), p.r_g(0), 0;
    m.topRightCorner<3, 3>() = -p.mass * s;
    m.bottomLeftCorner<3, 3>() = p.mass * s;
    m.bottomRightCorner<3, 3>() = sym_i - p.mass * s * s;
    m += 0.5 * (p.added_mass + p.added_mass.transpose());
    const Eigen::LDLT<Matrix6d> l(m);
    if (l.info() != Eigen::Success || !(l.vectorD().minCoeff() > 0.0))
      r_.fail("/added_mass", "the mass matrix M_RB + M_A is not positive definite");
  }

  system::HullContact<double> hull(const json& h) const {
    const std::string p = "/hull";
    r_.object(h, p,
              {"center_m", "half_extents_m", "stiffness_n_per_m", "damping_n_s_per_m",
               "damping_depth_m", "seabed_friction", "friction_velocity_m_s"});
    system::HullContact<double> c;
    if (h.contains("center_m")) c.center = r_.vec3(h.at("center_m"), p + "/center_m");
    c.half_extents = r_.vec3(r_.require(h, p, "half_extents_m"), p + "/half_extents_m");
    if ((c.half_extents.array() <= 0.0).any())
      r_.fail(p + "/half_extents_m",
              "expected positive half extents, got " + h.at("half_extents_m").dump());
    r_.number(h, p, "stiffness_n_per_m", c.stiffness, 1e-9, 1e12);
    r_.number(h, p, "damping_n_s_per_m", c.damping, 0.0, 1e12);
    r_.number(h, p, "damping_depth_m", c.damping_depth, 0.0, 1e3);
    r_.number(h, p, "seabed_friction", c.seabed_friction, 0.0, 1e3);
    r_.number(h, p, "friction_velocity_m_s", c.friction_velocity, 1e-12, 1e3);
    return c;
  }

  vehicle::PwmMapping<double> pwm(const json& w) const {
    const std::string p = "/pwm";
    r_.object(w, p, {"min_us", "neutral_us", "max_us", "deadband_us"});
    vehicle::PwmMapping<double> m;
    r_.number(w, p, "min_us", m.min_us, 0.0, 1e5);
    r_.number(w, p, "neutral_us", m.neutral_us, 0.0, 1e5);
    r_.number(w, p, "max_us", m.max_us, 0.0, 1e5);
    r_.number(w, p, "deadband_us", m.deadband_us, 0.0, 1e5);
    try {
      vehicle::validate(m);
    } catch (const error& e) {
      r_.fail(p, e.what());
    }
    return m;
  }

  void propulsion(const json& j, VehicleDescription& d) const {
    const std::string p = "/propulsion";
    r_.object(j, p, {"time_constant_s", "thrusters", "battery"});
    vehicle::PropulsionParameters<double> prop;
    r_.number(j, p, "time_constant_s", prop.time_constant, 0.0, 1e3);
    const json& ts = r_.require(j, p, "thrusters");
    if (!ts.is_array() || ts.empty() || ts.size() > std::size_t(vehicle::max_thrusters))
      r_.fail(p + "/thrusters", "expected an array of 1 to " +
                                    std::to_string(vehicle::max_thrusters) + " thrusters, got " +
                                    ts.dump());
    const Eigen::Index n = Eigen::Index(ts.size());
    prop.positions.resize(3, n);
    prop.directions.resize(3, n);
    prop.facing = vehicle::ThrusterVector<int>::Ones(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const std::string q = p + "/thrusters/" + std::to_string(i);
      const json& t = ts[std::size_t(i)];
      r_.object(t, q, {"position_m", "direction", "facing", "model"});
      if (t.contains("model")) prop.curves[std::size_t(i)] = model(t.at("model"), q + "/model");
      prop.positions.col(i) = r_.vec3(r_.require(t, q, "position_m"), q + "/position_m");
      prop.directions.col(i) = r_.vec3(r_.require(t, q, "direction"), q + "/direction");
      if (!(prop.directions.col(i).norm() > 1e-12))
        r_.fail(q + "/direction", "expected a non-zero direction, got " + t.at("direction").dump());
      if (t.contains("facing")) {
        const json& f = t.at("facing");
        if (!f.is_number_integer() || (f.get<int>() != 1 && f.get<int>() != -1))
          r_.fail(q + "/facing", "expected 1 or -1, got " + f.dump());
        prop.facing(i) = f.get<int>();
        if (prop.facing(i) != 1 && !prop.curves[std::size_t(i)].empty())
          r_.fail(q + "/facing",
                  "a thruster on a curve takes facing 1 (the curve gives its thrust as mounted, "
                  "in both directions)");
      }
    }
    prop.esc_scale_forward = (d.pwm.max_us - d.pwm.neutral_us) / vehicle::t200_esc_half_range_us;
    prop.esc_scale_reverse = (d.pwm.neutral_us - d.pwm.min_us) / vehicle::t200_esc_half_range_us;
    if (j.contains("battery")) prop.battery = battery(j.at("battery"));
    d.propulsion = prop;
  }

  // A thruster's model: the T200 (an empty curve) or its own curve, points [u, thrust_N] or
  // [u, thrust_N, current_A] (vehicle::ThrustCurve; the library's validate() runs after).
  vehicle::ThrustCurve model(const json& m, const std::string& p) const {
    if (m.is_string() && m.get<std::string>() == "t200") return {};
    if (!m.is_object() || !m.contains("curve"))
      r_.fail(p, "unknown thruster model " + m.dump() +
                     " (allowed: \"t200\", {\"curve\": " + "[[command, thrust_N], ...]})");
    r_.object(m, p, {"curve"});
    const json& c = m.at("curve");
    const std::string q = p + "/curve";
    constexpr int most = vehicle::max_curve_points;
    if (!c.is_array() || c.size() < 2 || c.size() > std::size_t(most))
      r_.fail(q, "expected 2 to " + std::to_string(most) +
                     " points [command, thrust_N] or [command, thrust_N, current_A], got " +
                     (c.is_array() ? std::to_string(c.size()) + " points" : c.dump()));
    const std::vector<double> first = r_.numbers(c[0], q + "/0", {2, 3});
    const std::size_t width = first.size();
    const Eigen::Index n = Eigen::Index(c.size());
    vehicle::ThrustCurve out;
    out.command.resize(n);
    out.thrust.resize(n);
    if (width == 3) out.current.resize(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const std::string pi = q + "/" + std::to_string(i);
      const json& point = c[std::size_t(i)];
      if (!point.is_array() || point.size() != width)
        r_.fail(pi, "expected an array of " + std::to_string(width) + " numbers (every point " +
                        (width == 3 ? "[command, thrust_N, current_A]" : "[command, thrust_N]") +
                        " like the first), got " + point.dump());
      const std::vector<double> pt = r_.numbers(point, pi, {width});
      if (pt[0] < -1.0 || pt[0] > 1.0 || (i > 0 && !(pt[0] > out.command(i - 1))))
        r_.fail(pi + "/0",
                "expected commands strictly ascending within [-1, 1], got " + point.dump());
      out.command(i) = pt[0];
      out.thrust(i) = pt[1];
      if (width == 3) {
        if (pt[2] < 0.0) r_.fail(pi + "/2", "expected a current >= 0, got " + point[2].dump());
        out.current(i) = pt[2];
      }
    }
    if (out.command(0) != -1.0 || out.command(n - 1) != 1.0)
      r_.fail(q, "expected the commands to run from -1 to 1");
    return out;
  }

  vehicle::BatteryParameters battery(const json& b) const {
    const std::string p = "/propulsion/battery";
    r_.object(b, p,
              {"capacity_ah", "cells_in_series", "internal_resistance_ohm", "initial_soc",
               "hotel_current_a", "ocv"});
    vehicle::BatteryParameters out;
    r_.number(b, p, "capacity_ah", out.capacity_ah, 1e-9, 1e9);
    std::uint64_t cells = std::uint64_t(out.cells_in_series);
    r_.integer(b, p, "cells_in_series", cells, 1, 1000);
    out.cells_in_series = int(cells);
    r_.number(b, p, "internal_resistance_ohm", out.internal_resistance, 0.0, 1e6);
    r_.number(b, p, "initial_soc", out.initial_soc, 0.0, 1.0);
    r_.number(b, p, "hotel_current_a", out.hotel_current, 0.0, 1e6);
    if (b.contains("ocv")) {
      const json& o = b.at("ocv");
      const std::string q = p + "/ocv";
      r_.object(o, q, {"soc", "cell_voltage_v"});
      const std::vector<double> soc = r_.numbers(r_.require(o, q, "soc"), q + "/soc");
      const std::vector<double> v =
          r_.numbers(r_.require(o, q, "cell_voltage_v"), q + "/cell_voltage_v");
      if (soc.size() < 2 || soc.size() > std::size_t(vehicle::OcvCurve::max_points) ||
          v.size() != soc.size())
        r_.fail(q, "expected 2 to 32 points, as many voltages as states of charge");
      out.ocv = vehicle::OcvCurve{};
      out.ocv.size = int(soc.size());
      for (std::size_t i = 0; i < soc.size(); ++i) {
        out.ocv.soc[i] = soc[i];
        out.ocv.cell_voltage[i] = v[i];
      }
    }
    return out;
  }

  detail::Reader r_;
};

}  // namespace

namespace detail {
void check_vehicle(const VehicleDescription& d, const std::string& file) {
  try {
    vehicle::validate(d.parameters);
    if (d.propulsion) {
      vehicle::validate(*d.propulsion);
      // The allocation must build (its pseudo-inverse is left to the model: a rank-deficient
      // thruster layout is allowed).
      (void)vehicle::allocation_matrix(d.propulsion->positions, d.propulsion->directions);
    }
    if (d.hull) system::validate(*d.hull);
    vehicle::validate(d.pwm);
    check_all_finite(d.attachment, "attachment");
  } catch (const scenario_error&) {
    throw;
  } catch (const error& e) {
    throw scenario_error(file + ": " + e.what());
  }
}
}  // namespace detail

namespace {

ojson battery_json(const vehicle::BatteryParameters& b) {
  ojson o = ojson::object();
  o["capacity_ah"] = b.capacity_ah;
  o["cells_in_series"] = b.cells_in_series;
  o["internal_resistance_ohm"] = b.internal_resistance;
  o["initial_soc"] = b.initial_soc;
  o["hotel_current_a"] = b.hotel_current;
  ojson soc = ojson::array(), v = ojson::array();
  for (int i = 0; i < b.ocv.size; ++i) {
    soc.push_back(b.ocv.soc[i]);
    v.push_back(b.ocv.cell_voltage[i]);
  }
  o["ocv"] = {{"soc", soc}, {"cell_voltage_v", v}};
  return o;
}

// JSON text for people: objects one key a line, arrays of numbers (and of such arrays) on one
// line; numbers in nlohmann-json's shortest form that reads back to the same double.
void pretty(const ojson& j, int indent, std::string& out) {
  const auto flat = [](const ojson& a) {
    for (const auto& e : a)
      if (e.is_object() || (e.is_array() && !e.empty() && e[0].is_array())) return false;
    return true;
  };
  const std::string pad(std::size_t(indent + 2), ' ');
  if (j.is_object() && !j.empty()) {
    out += "{\n";
    std::size_t i = 0;
    for (const std::string& key : key_order()) {
      if (!j.contains(key)) continue;
      out += pad + ojson(key).dump() + ": ";
      pretty(j.at(key), indent + 2, out);
      out += ++i < j.size() ? ",\n" : "\n";
    }
    KELP_ASSERT(i == j.size());  // every key the writer writes is in key_order()
    out += std::string(std::size_t(indent), ' ') + "}";
  } else if (j.is_array() && !j.empty() && !flat(j)) {
    out += "[\n";
    for (std::size_t i = 0; i < j.size(); ++i) {
      out += pad;
      pretty(j[i], indent + 2, out);
      out += i + 1 < j.size() ? ",\n" : "\n";
    }
    out += std::string(std::size_t(indent), ' ') + "]";
  } else if (j.is_array()) {
    out += "[";
    for (std::size_t i = 0; i < j.size(); ++i) out += (i ? ", " : "") + j[i].dump();
    out += "]";
  } else {
    out += j.dump();
  }
}

}  // namespace

VehicleDescription parse_vehicle(const std::string& text, const std::string& file) {
  if (json_depth(text, max_json_depth) > max_json_depth)
    throw scenario_error(file + ": nested deeper than " + std::to_string(max_json_depth) +
                         " levels");
  json j;
  try {
    j = json::parse(text);
  } catch (const json::parse_error& e) {
    throw scenario_error(file + ": not valid JSON: " + e.what());
  }
  VehicleDescription d = VehicleReader(file).read(j);
  detail::check_vehicle(d, file);
  return d;
}

VehicleDescription read_vehicle_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw scenario_error(path + ": cannot be read");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return parse_vehicle(text, path);
}

std::string write_vehicle_file(const VehicleDescription& d) {
  detail::check_vehicle(d, "write_vehicle_file(" + d.name + ")");
  const vehicle::VehicleParameters<double>& p = d.parameters;
  ojson j = ojson::object();
  j["name"] = d.name;
  j["mass_kg"] = p.mass;
  j["inertia_kg_m2"] = square(p.inertia);
  j["center_of_gravity_m"] = vec(p.r_g);
  j["center_of_buoyancy_m"] = vec(p.r_b);
  j["displaced_volume_m3"] = p.displaced_volume;
  j["water_density_kg_m3"] = p.density;
  j["gravity_m_s2"] = p.gravity;
  j["added_mass"] = square(p.added_mass);
  j["linear_damping"] = square(p.damping.linear);
  j["quadratic_damping"] = vec(p.damping.quadratic);
  j["hydrostatics"] = hydrostatics_name(p.hydrostatics);
  j["hull_height_m"] = p.hull_height;
  j["waterplane_area_m2"] = p.waterplane_area;
  j["gm_transverse_m"] = p.gm_transverse;
  j["gm_longitudinal_m"] = p.gm_longitudinal;
  j["wind_areas"] = {{"frontal_area_m2", p.wind_areas.frontal_area},
                     {"lateral_area_m2", p.wind_areas.lateral_area},
                     {"length_overall_m", p.wind_areas.length_overall}};
  j["wind_coefficients"] = {{"cx", p.wind_coefficients.cx},
                            {"cy", p.wind_coefficients.cy},
                            {"cn", p.wind_coefficients.cn}};
  j["attachment_m"] = vec(d.attachment);
  if (d.hull) {
    const system::HullContact<double>& h = *d.hull;
    j["hull"] = {{"center_m", vec(h.center)},
                 {"half_extents_m", vec(h.half_extents)},
                 {"stiffness_n_per_m", h.stiffness},
                 {"damping_n_s_per_m", h.damping},
                 {"damping_depth_m", h.damping_depth},
                 {"seabed_friction", h.seabed_friction},
                 {"friction_velocity_m_s", h.friction_velocity}};
  }
  j["pwm"] = {{"min_us", d.pwm.min_us},
              {"neutral_us", d.pwm.neutral_us},
              {"max_us", d.pwm.max_us},
              {"deadband_us", d.pwm.deadband_us}};
  if (d.propulsion) {
    const vehicle::PropulsionParameters<double>& prop = *d.propulsion;
    const double fwd = (d.pwm.max_us - d.pwm.neutral_us) / vehicle::t200_esc_half_range_us;
    const double rev = (d.pwm.neutral_us - d.pwm.min_us) / vehicle::t200_esc_half_range_us;
    KELP_CHECK(prop.esc_scale_forward == fwd && prop.esc_scale_reverse == rev,
               "propulsion.esc_scale_forward/reverse must be those of the description's pwm "
               "mapping (the file carries the mapping)");
    ojson ts = ojson::array();
    for (Eigen::Index i = 0; i < prop.positions.cols(); ++i) {
      ojson t = ojson::object();
      t["position_m"] = vec(prop.positions.col(i));
      t["direction"] = vec(prop.directions.col(i));
      t["facing"] = prop.facing.size() > 0 ? prop.facing(i) : 1;
      const vehicle::ThrustCurve& c = prop.curves[std::size_t(i)];
      if (c.empty()) {
        t["model"] = "t200";
      } else {
        ojson pts = ojson::array();
        for (Eigen::Index k = 0; k < c.command.size(); ++k) {
          ojson pt = ojson::array({c.command(k), c.thrust(k)});
          if (c.current.size() > 0) pt.push_back(c.current(k));
          pts.push_back(pt);
        }
        t["model"] = {{"curve", pts}};
      }
      ts.push_back(t);
    }
    j["propulsion"] = {{"time_constant_s", prop.time_constant},
                       {"thrusters", ts},
                       {"battery", battery_json(prop.battery)}};
  }
  std::string out;
  pretty(j, 0, out);
  return out + "\n";
}

std::vector<std::string> vehicle_preset_names() { return {"bluerov2_heavy", "blueboat"}; }

VehicleDescription vehicle_preset(const std::string& name) {
  VehicleDescription d;
  vehicle::VehiclePreset<double> preset;
  vehicle::BatteryParameters battery;
  if (name == "bluerov2_heavy") {
    preset = vehicle::bluerov2_heavy<double>();
    battery = vehicle::battery_presets::bluerov2_battery();
    d.hull = system::bluerov2_heavy_hull<double>();
    d.attachment = system::presets::bluerov2_attachment<double>();
  } else if (name == "blueboat") {
    preset = vehicle::blueboat<double>();
    battery = vehicle::battery_presets::blueboat_battery();
    d.hull = system::blueboat_hull<double>();
    d.attachment = system::presets::blueboat_attachment<double>();
  } else {
    throw invalid_argument("unknown vehicle preset \"" + name +
                           "\" (known: bluerov2_heavy, blueboat)");
  }
  d.name = preset.name;
  d.parameters = preset.parameters;
  d.pwm = preset.pwm;
  d.propulsion = system::presets::propulsion_of(preset, battery);
  return d;
}

}  // namespace sim
}  // namespace kelp
