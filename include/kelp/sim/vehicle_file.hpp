/// \file
/// \brief Vehicles described in data: a vehicle description (the parameters kelp's physics takes,
/// its thrusters and battery, its hull box and tether point), its JSON file format, the shipped
/// presets as such descriptions, and an importer of Gazebo (gz-sim) SDF models. Part of the
/// compiled `kelp::sim` component; the file format is documented in docs/vehicle-files.md.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "kelp/core/types.hpp"
#include "kelp/sim/export.hpp"
#include "kelp/system/hull_contact.hpp"
#include "kelp/vehicle/model.hpp"
#include "kelp/vehicle/propulsion.hpp"
#include "kelp/vehicle/thrusters.hpp"

namespace kelp {
namespace sim {

/// \brief A vehicle as data: everything kelp's physics needs to simulate it.
///
/// Frames and units are kelp's: body axes x forward, y starboard, z down (FRD) about the body
/// origin (CO), SI units, added mass and damping as positive magnitudes (Fossen 2021).
struct VehicleDescription {
  /// The vehicle's name (e.g. "BlueROV2 Heavy").
  std::string name;
  /// Rigid body, added mass, damping, hydrostatics (vehicle::validate holds).
  vehicle::VehicleParameters<double> parameters;
  /// Thrusters (positions, directions, facing, each a T200 or on its own curve, lag) and
  /// battery; std::nullopt: no thrusters. Its ESC scales are those of `pwm` (as
  /// system::presets::propulsion_of derives them).
  std::optional<vehicle::PropulsionParameters<double>> propulsion;
  /// PWM ↔ command mapping of the ESCs (ArduSub's 1100–1500–1900 µs by default).
  vehicle::PwmMapping<double> pwm;
  /// The hull box for contact with the seabed and obstacles; std::nullopt: none.
  std::optional<system::HullContact<double>> hull;
  /// Default tether attachment point [m], body axes.
  Vector3<double> attachment = Vector3<double>::Zero();
};

/// \brief Reads a vehicle description from JSON text (docs/vehicle-files.md) and checks it with
/// the library's own checks (vehicle::validate for the parameters, the propulsion and the hull).
/// \param[in] json_text the JSON text \param[in] name_for_errors names the file in messages
/// \return the description (FRD body axes, SI units), checked
/// \throws scenario_error (a kelp::invalid_argument) whose message names the file and the JSON
/// path, e.g. `rov.json: /propulsion/thrusters/3/model: unknown thruster model "t300" (allowed:
/// "t200", {"curve": ...})`: a wrong type, an unknown key, a missing required key (`mass_kg`,
/// `inertia_kg_m2`), a value out of range, a mass matrix M_RB + M_A that is not positive definite,
/// a thruster curve that is not one (vehicle::ThrustCurve; facing −1 on a curve), or any error of
/// the library's checks (prefixed with the file name).
KELP_SIM_API VehicleDescription parse_vehicle(const std::string& json_text,
                                              const std::string& name_for_errors);

/// \brief Reads a vehicle file (parse_vehicle() of its text).
/// \param[in] path the file (also names it in errors) \return the description, checked
/// \throws scenario_error naming the file (also when it cannot be read) and the JSON path (see
/// parse_vehicle).
KELP_SIM_API VehicleDescription read_vehicle_file(const std::string& path);

/// \brief The description as JSON text (2-space indent), every field written; numbers in the
/// shortest form that reads back to the same double, so parse_vehicle(write_vehicle_file(d))
/// equals d bit for bit. \throws kelp::invalid_argument when `d` does not pass the checks of
/// parse_vehicle.
/// \param[in] d the description \return the JSON text (UTF-8; write it to a file to keep it)
KELP_SIM_API std::string write_vehicle_file(const VehicleDescription& d);

/// \brief The shipped vehicles as descriptions, built from the C++ presets (no data directory
/// needed): "bluerov2_heavy" (vehicle::bluerov2_heavy, its battery, hull and tether point, as
/// system::presets::paper_system uses them) and "blueboat" (vehicle::blueboat, likewise). The
/// files data/vehicles/NAME.json hold the same descriptions (a test keeps them equal).
/// \param[in] name "bluerov2_heavy" or "blueboat" (vehicle_preset_names())
/// \return the description
/// \throws kelp::invalid_argument naming the known presets for any other name.
KELP_SIM_API VehicleDescription vehicle_preset(const std::string& name);

/// \brief Names of the presets vehicle_preset() knows.
/// \return the names ("bluerov2_heavy", "blueboat")
KELP_SIM_API std::vector<std::string> vehicle_preset_names();

/// \brief Choices the SDF importer cannot take from the file.
struct SdfImportOptions {
  /// The link that is the vehicle's body; empty: the model's first `<link>`.
  std::string link;
  /// Propeller speed ω_max [rad/s] at command ±1 of every thruster; 0: the thruster joint's
  /// `<axis><limit><velocity>`, else the plugin's `<max_thrust_cmd>` (a thrust [N], or a speed
  /// with `<use_angvel_cmd>`). One of them is needed to normalise the command.
  double max_propeller_speed_rad_s = 0.0;
  /// Points of each thruster's curve (odd, 3 … 63: vehicle::max_curve_points), evenly spaced in
  /// u ∈ [−1, 1].
  int curve_points = 41;
  /// Water density [kg/m³] when the file gives none (Buoyancy's `uniform_fluid_density`, else
  /// Hydrodynamics' `water_density`); 1000 is the Buoyancy system's default.
  double density_kg_m3 = 1000.0;
  /// g [m/s²] (a model file carries none).
  double gravity_m_s2 = standard_gravity;
  /// The restoring model: submerged (default) or submerged_free_surface (hull height: the
  /// collision boxes' vertical extent). `surface` needs a waterplane the file does not have.
  vehicle::Hydrostatics hydrostatics = vehicle::Hydrostatics::submerged;
  /// Tether attachment point [m], kelp body axes (FRD).
  Vector3<double> attachment = Vector3<double>::Zero();
};

/// \brief What an SDF import gives: the description and what the file has that kelp cannot carry.
struct SdfImport {
  /// The vehicle (converted to kelp's frames and signs; see docs/vehicle-files.md).
  VehicleDescription vehicle;
  /// One sentence per element or behaviour of the file that the description does not carry,
  /// naming the element (e.g. a plugin kelp does not know, a propeller link's mass, Gazebo's
  /// diagonal-only added-mass Coriolis).
  std::vector<std::string> not_carried;
};

/// \brief Imports a Gazebo (gz-sim) SDF model: the body link's `<inertial>`, the Hydrodynamics
/// system (added mass xDotU … nDotR, linear xU … nR, quadratic xUabsU … nRabsR), the Thruster
/// systems (joint pose and axis, thrust coefficient, density, propeller diameter) and buoyancy
/// (the volume and centre of the body link's collision boxes, cylinders and spheres), converted
/// from Gazebo's FLU link frame to kelp's FRD body frame (docs/vehicle-files.md).
/// \throws scenario_error naming the file and the element for an unreadable file, malformed XML,
/// no model or link, a missing or non-positive mass, a missing inertia, a thruster whose joint is
/// missing or whose command cannot be normalised, a bad number; or the library's checks' errors
/// with the file name prefixed. kelp::error when kelp::sim was built without tinyxml2.
/// \param[in] path the `.sdf` file (also names it in errors)
/// \param[in] options what the file cannot say (body link, propeller speed, density, g, …)
/// \return the description and the list of what it does not carry
KELP_SIM_API SdfImport import_sdf(const std::string& path, const SdfImportOptions& options = {});

/// \brief import_sdf() of SDF text. \param[in] xml_text the SDF \param[in] name_for_errors names
/// the file in messages. \param[in] options as import_sdf()'s
/// \return the description and the list of what it does not carry \throws as import_sdf().
KELP_SIM_API SdfImport parse_sdf(const std::string& xml_text, const std::string& name_for_errors,
                                 const SdfImportOptions& options = {});

}  // namespace sim
}  // namespace kelp
