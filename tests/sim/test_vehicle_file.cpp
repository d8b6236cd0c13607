// Vehicle files and the SDF importer (kelp/sim/vehicle_file.hpp): the shipped preset files equal
// the C++ presets bit for bit, a description round-trips exactly, bad files name their JSON
// path, a thruster's curve in a file or an SDF drives the propulsion's thrust and current, and
// the import of a BlueROV2 Heavy written in Gazebo's conventions reproduces a hand-written kelp
// description (mass matrix, damping, thruster allocation) within 1e-12, with the FLU → FRD
// conversion checked axis by axis.
#include <catch2/catch.hpp>

#include "kelp/sim/vehicle_file.hpp"
#include "kelp/vehicle/rigid_body.hpp"

#ifndef KELP_VEHICLE_DIR
#error "KELP_VEHICLE_DIR (data/vehicles) must be defined"
#endif
#ifndef KELP_TEST_DATA_DIR
#error "KELP_TEST_DATA_DIR (tests/data) must be defined"
#endif

namespace {

using kelp::sim::VehicleDescription;

// Field by field, with ==: the description's every number bit for bit (−0 == 0 aside).
void require_equal(const VehicleDescription& a, const VehicleDescription& b) {
  const auto& p = a.parameters;
  const auto& q = b.parameters;
  CHECK(a.name == b.name);
  CHECK(p.mass == q.mass);
  CHECK(p.inertia == q.inertia);
  CHECK(p.r_g == q.r_g);
  CHECK(p.r_b == q.r_b);
  CHECK(p.displaced_volume == q.displaced_volume);
  CHECK(p.density == q.density);
  CHECK(p.gravity == q.gravity);
  CHECK(p.added_mass == q.added_mass);
  CHECK(p.damping.linear == q.damping.linear);
  CHECK(p.damping.quadratic == q.damping.quadratic);
  CHECK(p.hydrostatics == q.hydrostatics);
  CHECK(p.waterplane_area == q.waterplane_area);
  CHECK(p.gm_transverse == q.gm_transverse);
  CHECK(p.gm_longitudinal == q.gm_longitudinal);
  CHECK(p.hull_height == q.hull_height);
  CHECK(p.wind_areas.frontal_area == q.wind_areas.frontal_area);
  CHECK(p.wind_areas.lateral_area == q.wind_areas.lateral_area);
  CHECK(p.wind_areas.length_overall == q.wind_areas.length_overall);
  CHECK(p.wind_coefficients.cx == q.wind_coefficients.cx);
  CHECK(p.wind_coefficients.cy == q.wind_coefficients.cy);
  CHECK(p.wind_coefficients.cn == q.wind_coefficients.cn);
  CHECK(a.attachment == b.attachment);
  CHECK(a.pwm.min_us == b.pwm.min_us);
  CHECK(a.pwm.neutral_us == b.pwm.neutral_us);
  CHECK(a.pwm.max_us == b.pwm.max_us);
  CHECK(a.pwm.deadband_us == b.pwm.deadband_us);
  REQUIRE(a.hull.has_value() == b.hull.has_value());
  if (a.hull) {
    CHECK(a.hull->center == b.hull->center);
    CHECK(a.hull->half_extents == b.hull->half_extents);
    CHECK(a.hull->stiffness == b.hull->stiffness);
    CHECK(a.hull->damping == b.hull->damping);
    CHECK(a.hull->damping_depth == b.hull->damping_depth);
    CHECK(a.hull->seabed_friction == b.hull->seabed_friction);
    CHECK(a.hull->friction_velocity == b.hull->friction_velocity);
  }
  REQUIRE(a.propulsion.has_value() == b.propulsion.has_value());
  if (a.propulsion) {
    const auto& s = *a.propulsion;
    const auto& t = *b.propulsion;
    CHECK(s.positions == t.positions);
    CHECK(s.directions == t.directions);
    CHECK(s.facing == t.facing);
    CHECK(s.esc_scale_forward == t.esc_scale_forward);
    CHECK(s.esc_scale_reverse == t.esc_scale_reverse);
    CHECK(s.time_constant == t.time_constant);
    CHECK(s.battery.capacity_ah == t.battery.capacity_ah);
    CHECK(s.battery.cells_in_series == t.battery.cells_in_series);
    CHECK(s.battery.internal_resistance == t.battery.internal_resistance);
    CHECK(s.battery.initial_soc == t.battery.initial_soc);
    CHECK(s.battery.hotel_current == t.battery.hotel_current);
    REQUIRE(s.battery.ocv.size == t.battery.ocv.size);
    for (int i = 0; i < s.battery.ocv.size; ++i) {
      CHECK(s.battery.ocv.soc[i] == t.battery.ocv.soc[i]);
      CHECK(s.battery.ocv.cell_voltage[i] == t.battery.ocv.cell_voltage[i]);
    }
    for (std::size_t i = 0; i < s.curves.size(); ++i) {
      CHECK(s.curves[i].command == t.curves[i].command);
      CHECK(s.curves[i].thrust == t.curves[i].thrust);
      CHECK(s.curves[i].current == t.curves[i].current);
    }
  }
}

// The steady thrust and current of thruster i of `p` under command u on every thruster (the
// lag's time constant set to 0: the first step's thrust is the static one).
std::pair<double, double> steady(kelp::vehicle::PropulsionParametersd p, int i, double u) {
  p.time_constant = 0.0;
  const kelp::vehicle::PropulsionModeld m(p);
  kelp::vehicle::PropulsionStated s = kelp::vehicle::initial_state(m);
  kelp::vehicle::advance(m, s, kelp::vehicle::ThrusterVector<double>::Constant(m.size(), u), 0.01);
  return {s.thrust(i), s.current(i)};
}

// The message of the scenario_error that `f` throws.
template <typename F>
std::string error_of(F f) {
  try {
    f();
  } catch (const kelp::sim::scenario_error& e) {
    return e.what();
  }
  FAIL("no scenario_error");
  return "";
}

std::string rov_json(const std::string& extra) {
  return R"({"name": "rov", "mass_kg": 10, "inertia_kg_m2": [0.2, 0.2, 0.3],
             "added_mass": [5, 5, 10, 0.1, 0.1, 0.1],
             "propulsion": {"thrusters": [{"position_m": [0, 0, 0], "direction": [1, 0, 0]}]})" +
         extra + "}";
}

// A vehicle with the given `propulsion` object (and `extra` keys after it).
std::string rov_with(const std::string& propulsion, const std::string& extra = "") {
  return R"({"name": "rov", "mass_kg": 10, "inertia_kg_m2": [0.2, 0.2, 0.3],
             "added_mass": [5, 5, 10, 0.1, 0.1, 0.1], "propulsion": )" +
         propulsion + extra + "}";
}

Eigen::Matrix<double, 6, Eigen::Dynamic> allocation(const Eigen::Matrix3Xd& r,
                                                    const Eigen::Matrix3Xd& d) {
  Eigen::Matrix<double, 6, Eigen::Dynamic> B(6, r.cols());
  for (Eigen::Index i = 0; i < r.cols(); ++i) {
    const Eigen::Vector3d u = d.col(i).normalized();
    B.col(i) << u, Eigen::Vector3d(r.col(i)).cross(u);
  }
  return B;
}

kelp::Matrix6<double> mass_matrix(const kelp::vehicle::VehicleParameters<double>& p) {
  return kelp::vehicle::rigid_body_mass_matrix(p.mass, p.inertia, p.r_g) + p.added_mass;
}

}  // namespace

TEST_CASE("each shipped vehicle file loads to the C++ preset exactly", "[vehicle_file]") {
  for (const std::string& name : kelp::sim::vehicle_preset_names()) {
    INFO(name);
    const VehicleDescription preset = kelp::sim::vehicle_preset(name);
    const VehicleDescription file =
        kelp::sim::read_vehicle_file(std::string(KELP_VEHICLE_DIR) + "/" + name + ".json");
    require_equal(file, preset);
    // The file is the writer's own text: writing the preset gives it back.
    CHECK(kelp::sim::write_vehicle_file(file) == kelp::sim::write_vehicle_file(preset));
  }
  // What the paper's system uses (system::presets::paper_system: propulsion_of on the battery
  // presets, T200s with their 20 ms lag; the hull presets), spot-checked against the numbers.
  const VehicleDescription rov = kelp::sim::vehicle_preset("bluerov2_heavy");
  CHECK(rov.parameters.mass == 13.5);
  CHECK(rov.propulsion->positions.cols() == 8);
  CHECK(rov.propulsion->time_constant == 0.02);
  CHECK(rov.hull->half_extents(2) == 0.127);
  const VehicleDescription boat = kelp::sim::vehicle_preset("blueboat");
  CHECK(boat.propulsion->esc_scale_forward == 1.25);
  CHECK(boat.propulsion->battery.capacity_ah == 2 * 15.6);
  CHECK(boat.parameters.hydrostatics == kelp::vehicle::Hydrostatics::surface);
  CHECK_THROWS_AS(kelp::sim::vehicle_preset("bluerov3"), kelp::invalid_argument);
}

TEST_CASE("a vehicle description round-trips exactly, curves and full matrices included",
          "[vehicle_file]") {
  VehicleDescription d = kelp::sim::vehicle_preset("bluerov2_heavy");
  d.parameters.inertia(0, 1) = d.parameters.inertia(1, 0) = 0.1 / 3;
  d.parameters.added_mass(0, 4) = d.parameters.added_mass(4, 0) = -0.3;
  d.parameters.damping.linear(0, 4) = d.parameters.damping.linear(4, 0) = 0.7;
  d.parameters.r_g << 1.0 / 3, -2.0 / 7, 0.011;
  kelp::vehicle::ThrustCurve& c = d.propulsion->curves[2];
  c.command.resize(4);
  c.thrust.resize(4);
  c.command << -1, -0.25, 0.5, 1;
  c.thrust << -40.1, -3.3, 12.0 / 7, 51.2;
  d.propulsion->curves[5] = c;
  d.propulsion->curves[5].current = kelp::vehicle::CurveVector::Constant(4, 0.1 / 3);
  d.propulsion->facing(2) = 1;
  d.propulsion->facing(3) = -1;
  d.propulsion->battery.ocv.size = 2;
  d.propulsion->battery.ocv.soc[1] = 1.0;
  d.propulsion->battery.ocv.cell_voltage[1] = 4.2;
  for (int i = 2; i < kelp::vehicle::OcvCurve::max_points; ++i)
    d.propulsion->battery.ocv.soc[i] = d.propulsion->battery.ocv.cell_voltage[i] = 0.0;
  d.hull.reset();
  const std::string text = kelp::sim::write_vehicle_file(d);
  require_equal(kelp::sim::parse_vehicle(text, "d.json"), d);
}

TEST_CASE("a vehicle file's thruster curve drives the propulsion's thrust and current",
          "[vehicle_file]") {
  const VehicleDescription d = kelp::sim::parse_vehicle(rov_with(R"({"thrusters": [
        {"position_m": [0, 0, 0], "direction": [1, 0, 0]},
        {"position_m": [0, 0.2, 0], "direction": [1, 0, 0],
         "model": {"curve": [[-1, -28, 11], [-0.1, 0, 0.2], [0.1, 0, 0.2], [0.6, 21, 6.5],
                             [1, 36, 15]]}}]})",
                                                                 R"(, "pwm": {"max_us": 2000})"),
                                                        "rov.json");
  const kelp::vehicle::ThrustCurve& c = d.propulsion->curves[1];
  REQUIRE(c.command.size() == 5);
  CHECK(d.propulsion->curves[0].empty());  // no model: the T200
  CHECK(c.current.size() == 5);
  // u = 0.5 between the points 0.1 and 0.6 (w = 0.8): 0.2 · 0 + 0.8 · 21 N, 0.2 · 0.2 + 0.8 · 6.5
  // A.
  const auto [f, i] = steady(*d.propulsion, 1, 0.5);
  CHECK(f == Approx(0.8 * 21.0).epsilon(1e-14));
  CHECK(i == Approx(0.2 * 0.2 + 0.8 * 6.5).epsilon(1e-14));
  // The file's pwm scales the T200 beside it (1.25 from 1900 µs on), not the curve: u = 0.8
  // saturates the T200 and gives the curve's own 0.5 · 21 + 0.5 · 36 N.
  CHECK(d.propulsion->esc_scale_forward == 1.25);
  const auto [f1, i1] = steady(*d.propulsion, 1, 0.8);
  CHECK(f1 == Approx(28.5).epsilon(1e-14));
  kelp::vehicle::PropulsionParametersd stiff = *d.propulsion;  // the same voltage at any load
  stiff.battery.internal_resistance = 0.0;
  CHECK(steady(stiff, 0, 0.8).first == steady(stiff, 0, 1.0).first);
  // Without currents the curve draws nothing.
  const VehicleDescription q = kelp::sim::parse_vehicle(
      rov_with(R"({"thrusters": [{"position_m": [0, 0, 0], "direction": [1, 0, 0],
                                  "model": {"curve": [[-1, -10], [1, 10]]}}]})"),
      "rov.json");
  CHECK(steady(*q.propulsion, 0, 0.5) == std::pair<double, double>(5.0, 0.0));
}

TEST_CASE("bad vehicle files name the file and the JSON path", "[vehicle_file]") {
  using kelp::sim::parse_vehicle;
  CHECK(error_of([] { parse_vehicle(R"({"name": "rov", "mass_kg": 10})", "rov.json"); }) ==
        "rov.json: /inertia_kg_m2: missing (required)");
  CHECK_THAT(error_of([] {
               parse_vehicle(R"({"name": "rov", "mass_kg": -1, "inertia_kg_m2": [1, 1, 1]})",
                             "rov.json");
             }),
             Catch::StartsWith("rov.json: /mass_kg: expected a number in"));
  // A heave added mass of −50 kg on a 10 kg vehicle.
  CHECK(error_of([] {
          parse_vehicle(R"({"name": "rov", "mass_kg": 10, "inertia_kg_m2": [0.2, 0.2, 0.3],
                            "added_mass": [5, 5, -50, 0.1, 0.1, 0.1]})",
                        "rov.json");
        }) == "rov.json: /added_mass: the mass matrix M_RB + M_A is not positive definite");
  CHECK_THAT(error_of([] {
               parse_vehicle(R"({"name": "rov", "mass_kg": 10, "inertia_kg_m2": [1, 1, 1],
                   "propulsion": {"thrusters": [{"position_m": [0, 0, 0], "direction": [1, 0, 0]},
                     {"position_m": [0, 0, 0], "direction": [1, 0, 0], "model": "t300"}]}})",
                             "rov.json");
             }),
             Catch::StartsWith(
                 "rov.json: /propulsion/thrusters/1/model: unknown thruster model \"t300\""));
  CHECK_THAT(error_of([] { parse_vehicle(rov_json(R"(, "mass": 3)"), "rov.json"); }),
             Catch::StartsWith("rov.json: /mass: unknown key"));
  CHECK_THAT(error_of([] { parse_vehicle(rov_json(R"(, "center_of_gravity_m": "up")"), "r"); }),
             Catch::StartsWith("r: /center_of_gravity_m: expected an array of 3 numbers"));
  CHECK_THAT(error_of([] { parse_vehicle(R"({"name": )", "rov.json"); }),
             Catch::StartsWith("rov.json: not valid JSON"));
  // The library's checks, with the file name: a negative quadratic damping.
  CHECK_THAT(error_of([] {
               parse_vehicle(rov_json(R"(, "quadratic_damping": [1, 1, 1, 1, 1, -1])"), "rov.json");
             }),
             Catch::StartsWith("rov.json: ") && Catch::Contains("quadratic_damping"));
  CHECK_THAT(error_of([] { kelp::sim::read_vehicle_file("/nonexistent/rov.json"); }),
             Catch::Equals("/nonexistent/rov.json: cannot be read"));
  // Curves: measured as mounted (facing 1), points of one length, at most 64 of them.
  const auto thruster = [](const std::string& t) {
    return rov_with(R"({"thrusters": [{"position_m": [0, 0, 0], "direction": [1, 0, 0], )" + t +
                    "}]}");
  };
  CHECK(error_of([&] {
          parse_vehicle(thruster(R"("facing": -1, "model": {"curve": [[-1, -5], [1, 5]]})"), "r");
        }) ==
        "r: /propulsion/thrusters/0/facing: a thruster on a curve takes facing 1 (the curve "
        "gives its thrust as mounted, in both directions)");
  CHECK(error_of([&] {
          parse_vehicle(thruster(R"("model": {"curve": [[-1, -5, 1], [1, 5]]})"), "r");
        }) ==
        "r: /propulsion/thrusters/0/model/curve/1: expected an array of 3 numbers "
        "(every point [command, thrust_N, current_A] like the first), got [1,5]");
  CHECK(error_of([&] {
          parse_vehicle(thruster(R"("model": {"curve": [[-1, -5, -1], [1, 5, 2]]})"), "r");
        }) == "r: /propulsion/thrusters/0/model/curve/0/2: expected a current >= 0, got -1");
  std::string many = "[-1, 0]";
  for (int k = 1; k < 65; ++k) many += ", [" + std::to_string(-1.0 + k / 32.0) + ", 0]";
  CHECK_THAT(
      error_of([&] { parse_vehicle(thruster(R"("model": {"curve": [)" + many + "]}"), "r"); }),
      Catch::StartsWith("r: /propulsion/thrusters/0/model/curve: expected 2 to 64 points"));
}

TEST_CASE("the SDF import of a BlueROV2 Heavy equals its hand-written kelp description",
          "[vehicle_file][sdf]") {
  const kelp::sim::SdfImport im =
      kelp::sim::import_sdf(std::string(KELP_TEST_DATA_DIR) + "/bluerov2_heavy.sdf");
  const auto& v = im.vehicle.parameters;
  // The same vehicle written by hand in kelp's FRD frame and positive magnitudes.
  kelp::vehicle::VehicleParameters<double> h;
  h.mass = 13.0;
  h.inertia = Eigen::Vector3d(0.26, 0.23, 0.37).asDiagonal();
  h.r_g << 0, 0, -0.011;  // 11 mm above the link origin
  h.added_mass.diagonal() << 6.36, 7.12, 18.68, 0.189, 0.135, 0.222;
  h.added_mass(0, 4) = h.added_mass(4, 0) = -0.3;  // xDotQ = mDotU = −0.3 in FLU: q flips
  h.damping.linear.diagonal() << 5, 5, 0, 0, 0, 0;
  h.damping.quadratic << 58.42, 55.137, 124.818, 4, 4, 4;
  CHECK((mass_matrix(v) - mass_matrix(h)).cwiseAbs().maxCoeff() <= 1e-12);
  CHECK((v.damping.linear - h.damping.linear).cwiseAbs().maxCoeff() <= 1e-12);
  CHECK((v.damping.quadratic - h.damping.quadratic).cwiseAbs().maxCoeff() <= 1e-12);
  CHECK(v.displaced_volume == Approx(0.457 * 0.575 * 0.05).epsilon(1e-14));
  CHECK((v.r_b - Eigen::Vector3d(0, 0, -0.02)).norm() <= 1e-12);
  CHECK(v.density == 1000.0);
  // Thrusters: kelp's preset geometry (ArduSub order), FRD.
  const double s = std::sqrt(0.5);
  Eigen::Matrix3Xd r(3, 8), d(3, 8);
  r << 0.156, 0.156, -0.156, -0.156, 0.12, 0.12, -0.12, -0.12,     //
      0.111, -0.111, 0.111, -0.111, 0.218, -0.218, 0.218, -0.218,  //
      0.085, 0.085, 0.085, 0.085, 0, 0, 0, 0;
  d << -s, -s, s, s, 0, 0, 0, 0,  //
      s, -s, s, -s, 0, 0, 0, 0,   //
      0, 0, 0, 0, 1, 1, 1, 1;     // verticals push down (the SDF's −z, up being +z)
  REQUIRE(im.vehicle.propulsion.has_value());
  const auto& prop = *im.vehicle.propulsion;
  CHECK((allocation(prop.positions, prop.directions) - allocation(r, d)).cwiseAbs().maxCoeff() <=
        1e-12);
  // T = Ct ρ D⁴ ω|ω| with ω = 160 u rad/s (the joints' velocity limit): 51.2 N at u = 1.
  for (const auto& c : prop.curves) {
    REQUIRE(c.command.size() == 41);
    CHECK(c.current.size() == 0);  // Gazebo's thruster has no electrical model: draws nothing
    CHECK(kelp::vehicle::curve_thrust(c, 1.0) == Approx(51.2).epsilon(1e-14));
    CHECK(kelp::vehicle::curve_thrust(c, -0.5) == Approx(-12.8).epsilon(1e-14));
  }
  CHECK(prop.time_constant == 0.0);
  // And the propulsion drives it: thrust = Ct ρ D⁴ |ω| ω at ω = u · 160 rad/s on every thruster,
  // exactly at the tabulated commands (every 0.05), and between them the chord of the parabola,
  // k ω² + k (ω − ω_lo)(ω_hi − ω) for ω > 0 (at most k (0.05 · 160)² / 4 = 0.032 N above it).
  const double k = 0.02 * 1000.0 * std::pow(0.1, 4);
  const kelp::vehicle::PropulsionModeld pm(prop);
  for (double u : {-1.0, -0.5, 0.35, 0.5, 0.9, 0.33, -0.71}) {
    INFO("u = " << u);
    kelp::vehicle::PropulsionStated st = kelp::vehicle::initial_state(pm);
    const kelp::vehicle::PropulsionStep<double> step =
        kelp::vehicle::advance(pm, st, kelp::vehicle::ThrusterVector<double>::Constant(8, u), 0.01);
    const double w = u * 160.0, exact = k * std::abs(w) * w;
    const double lo = std::floor(u / 0.05 + 1e-9) * 0.05 * 160.0, hi = lo + 0.05 * 160.0;
    const double chord_error = k * (w - lo) * (hi - w);  // chord minus parabola, same sign as ω
    for (int i = 0; i < 8; ++i)
      CHECK(st.thrust(i) == Approx(exact + (w >= 0 ? 1 : -1) * chord_error).epsilon(1e-12));
    CHECK(step.current == 0.0);
  }
  // The chord's error at u = 0.33 (0.031 N) is what the tolerance above resolves: 1e-12 of 14 N.
  CHECK(k * (0.33 * 160 - 0.30 * 160) * (0.35 * 160 - 0.33 * 160) == Approx(0.03072));
  // The hull: the collision box, 5 cm high, 2 cm above the link origin.
  REQUIRE(im.vehicle.hull.has_value());
  CHECK((im.vehicle.hull->half_extents - Eigen::Vector3d(0.2285, 0.2875, 0.025)).norm() <= 1e-15);
  const auto listed = [&](const std::string& part) {
    for (const auto& n : im.not_carried)
      if (n.find(part) != std::string::npos) return true;
    return false;
  };
  CHECK(listed("Coriolis uses only the diagonal of the added mass"));
  CHECK(listed("link thruster5 (thruster thruster5_joint): its mass 0.002"));
  CHECK(listed("propeller speed u*160 rad/s"));
}

TEST_CASE("SDF frames: surge stays, sway and heave flip (FLU to FRD)", "[vehicle_file][sdf]") {
  // Three thrusters along +x, +y (left), +z (up) of the link, at +x, +y, +z; a heave velocity
  // that makes a surge force (xW); the CG above the origin.
  const std::string sdf = R"(<sdf version="1.9"><model name="m">
    <link name="body"><inertial><pose>0 0 0.1 0 0 0</pose><mass>1</mass>
      <inertia><ixx>1</ixx><iyy>1</iyy><izz>1</izz></inertia></inertial></link>
    <link name="px"><pose>1 0 0 0 0 0</pose></link>
    <link name="py"><pose>0 1 0 0 0 0</pose></link>
    <link name="pz"><pose>0 0 1 0 0 0</pose></link>
    <joint name="jx" type="revolute"><parent>body</parent><child>px</child><axis><xyz>1 0 0</xyz></axis></joint>
    <joint name="jy" type="revolute"><parent>body</parent><child>py</child><axis><xyz>0 1 0</xyz></axis></joint>
    <joint name="jz" type="revolute"><parent>body</parent><child>pz</child><axis><xyz>0 0 1</xyz></axis></joint>
    <plugin filename="gz-sim-hydrodynamics-system" name="gz::sim::systems::Hydrodynamics">
      <link_name>body</link_name><xU>-1</xU><yV>-2</yV><zW>-3</zW><xW>-0.5</xW><zU>-0.5</zU></plugin>
    <plugin filename="gz-sim-thruster-system" name="gz::sim::systems::Thruster"><joint_name>jx</joint_name><max_thrust_cmd>10</max_thrust_cmd></plugin>
    <plugin filename="gz-sim-thruster-system" name="gz::sim::systems::Thruster"><joint_name>jy</joint_name><max_thrust_cmd>10</max_thrust_cmd></plugin>
    <plugin filename="gz-sim-thruster-system" name="gz::sim::systems::Thruster"><joint_name>jz</joint_name><max_thrust_cmd>10</max_thrust_cmd></plugin>
  </model></sdf>)";
  const kelp::sim::SdfImport im = kelp::sim::parse_sdf(sdf, "frames.sdf");
  const auto& prop = *im.vehicle.propulsion;
  Eigen::Matrix3d frd;
  frd << 1, 0, 0, 0, -1, 0, 0, 0, -1;  // columns: surge, sway, heave thrust in FRD
  CHECK((prop.directions - frd).cwiseAbs().maxCoeff() <= 1e-15);
  CHECK((prop.positions - frd).cwiseAbs().maxCoeff() <= 1e-15);
  CHECK(im.vehicle.parameters.r_g == Eigen::Vector3d(0, 0, -0.1));
  const auto& D = im.vehicle.parameters.damping.linear;
  CHECK(D(0, 0) == 1.0);
  CHECK(D(1, 1) == 2.0);
  CHECK(D(2, 2) == 3.0);
  CHECK(D(0, 2) == -0.5);  // surge from heave: w flips, so the coupling's sign does
  CHECK(D(2, 0) == -0.5);
  // Force commands up to max_thrust_cmd: u = 1 gives 10 N along the direction.
  CHECK(kelp::vehicle::curve_thrust(prop.curves[1], 1.0) == Approx(10.0));
}

TEST_CASE("SDF: what kelp cannot carry is listed, bad files are errors naming the file",
          "[vehicle_file][sdf]") {
  const std::string boat = R"(<sdf version="1.9"><model name="boat">
    <link name="hull"><inertial><mass>30</mass><inertia><ixx>2.4</ixx><iyy>3.9</iyy><izz>5.6</izz></inertia></inertial>
      <collision name="left"><pose>0 0.4 0 0 0 0</pose><geometry><cylinder><radius>0.1</radius><length>1.2</length></cylinder></geometry></collision>
      <collision name="right"><pose>0 -0.4 0 0 0 0</pose><geometry><cylinder><radius>0.1</radius><length>1.2</length></cylinder></geometry></collision></link>
    <plugin filename="gz-waves1-hydrodynamics-system" name="gz::sim::systems::WavesHydrodynamics"><damping_on>1</damping_on></plugin>
  </model></sdf>)";
  const kelp::sim::SdfImport im = kelp::sim::parse_sdf(boat, "boat.sdf");
  REQUIRE(im.not_carried.size() == 1);
  CHECK_THAT(im.not_carried[0], Catch::StartsWith("plugin gz-waves1-hydrodynamics-system "
                                                  "(gz::sim::systems::WavesHydrodynamics) is "
                                                  "not a Gazebo system kelp imports"));
  CHECK(im.vehicle.parameters.damping.linear.isZero(0.0));  // not misread as Hydrodynamics
  CHECK(im.vehicle.parameters.displaced_volume == Approx(2 * M_PI * 0.01 * 1.2));

  using kelp::sim::parse_sdf;
  CHECK_THAT(error_of([] { kelp::sim::import_sdf("/nonexistent/rov.sdf"); }),
             Catch::Equals("/nonexistent/rov.sdf: cannot be read"));
  CHECK_THAT(error_of([] { parse_sdf("<sdf><model name=\"m\"></model></sdf>", "a.sdf"); }),
             Catch::Equals("a.sdf: /sdf/model[m]: no <link>"));
  CHECK_THAT(error_of([] { parse_sdf("<sdf><model><link>", "b.sdf"); }),
             Catch::StartsWith("b.sdf: /: malformed XML"));
  CHECK_THAT(error_of([] {
               parse_sdf(
                   "<sdf><model name=\"m\"><link name=\"l\"><inertial><mass>-2</mass>"
                   "</inertial></link></model></sdf>",
                   "c.sdf");
             }),
             Catch::StartsWith("c.sdf: /sdf/model[m]/link[l]/inertial/mass: expected a "
                               "positive mass"));
  CHECK_THAT(error_of([] {
               parse_sdf(
                   "<sdf><model name=\"m\"><link name=\"l\"><inertial><mass>2</mass>"
                   "</inertial></link></model></sdf>",
                   "d.sdf");
             }),
             Catch::Equals("d.sdf: /sdf/model[m]/link[l]/inertial/inertia: missing"));
}
