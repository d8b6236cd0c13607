/// \file
/// \brief What a fleet is made of (kelp/system/fleet.hpp steps it): its vehicles, free point
/// masses and tethers, each tether end on a vehicle point, an anchor, a point mass or free;
/// fleet_of() for the tethered pair; validate() of the whole.
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "kelp/system/system.hpp"

namespace kelp::system {

/// \brief What a tether end is fixed to.
enum class EndKind {
  vehicle,     ///< a body-fixed point of a vehicle (FleetParameters::vehicles[index])
  anchor,      ///< a fixed point in the world (NED)
  point_mass,  ///< a free point mass (FleetParameters::point_masses[index])
  free,        ///< nothing: the line's end hangs free (with the tether's own end point mass)
};

/// \brief One end of a tether in a fleet.
/// \tparam Scalar double or float.
template <typename Scalar>
struct TetherEnd {
  EndKind kind = EndKind::anchor;  ///< what the end is fixed to
  int index = -1;                  ///< the vehicle's or point mass's index (else unused)
  /// vehicle: the attachment point, body frame [m]; anchor: the anchor's NED position [m];
  /// point mass and free: unused.
  Vector3<Scalar> point = Vector3<Scalar>::Zero();

  /// \brief The body point `r_body` [m] of vehicle `i`.
  /// \param i Index of the vehicle in FleetParameters::vehicles.
  /// \param r_body Attachment point, body frame, from the vehicle's CO [m].
  /// \return The end (checked by validate(const FleetParameters<Scalar>&)).
  static TetherEnd on_vehicle(int i, const Vector3<Scalar>& r_body) {
    return {EndKind::vehicle, i, r_body};
  }
  /// \brief A fixed point `p_ned` [m].
  /// \param p_ned The anchor's position, NED [m].
  /// \return The end.
  static TetherEnd at_anchor(const Vector3<Scalar>& p_ned) { return {EndKind::anchor, -1, p_ned}; }
  /// \brief Point mass `i`.
  /// \param i Index of the point mass in FleetParameters::point_masses.
  /// \return The end (the line attaches at the mass's centre).
  static TetherEnd on_point_mass(int i) {
    return {EndKind::point_mass, i, Vector3<Scalar>::Zero()};
  }
  /// \brief A free end.
  /// \return The end (the line's end node moves under the tether's own end point mass).
  static TetherEnd hanging_free() { return {EndKind::free, -1, Vector3<Scalar>::Zero()}; }
};

/// \brief A free point mass (a clump weight, a junction, a simple TMS): a sphere of volume V
/// for its buoyancy and added mass (its submerged fraction is the exact one of that sphere
/// against the free surface), with quadratic drag.
template <typename Scalar>
struct PointMassParameters {
  std::string name;                             ///< e.g. "clump"
  Scalar mass = Scalar(0);                      ///< dry mass m [kg], > 0
  Scalar volume = Scalar(0);                    ///< displaced volume V when submerged [m³], ≥ 0
  Scalar added_mass_coefficient = Scalar(0.5);  ///< C_a (0.5: a sphere) [-], ≥ 0
  /// C_d A: drag coefficient times frontal area [m²], ≥ 0; drag ½ ρ C_d A φ |u| u with u the
  /// water's velocity relative to the mass and φ the submerged fraction.
  Scalar drag_area = Scalar(0);
};

/// \brief Checks point-mass parameters.
/// \tparam Scalar double or float.
/// \param p Parameters: mass finite > 0; volume, added_mass_coefficient, drag_area finite ≥ 0.
/// \throws kelp::invalid_argument naming the field.
template <typename Scalar>
void validate(const PointMassParameters<Scalar>& p) {
  check_positive(p.mass, "point_mass.mass");
  check_non_negative(p.volume, "point_mass.volume");
  check_non_negative(p.added_mass_coefficient, "point_mass.added_mass_coefficient");
  check_non_negative(p.drag_area, "point_mass.drag_area");
}

/// \brief The state of a point mass: NED position [m] and velocity [m/s].
template <typename Scalar>
struct PointMassState {
  Vector3<Scalar> position = Vector3<Scalar>::Zero();  ///< NED [m]
  Vector3<Scalar> velocity = Vector3<Scalar>::Zero();  ///< NED [m/s]
};

/// \brief A vehicle of a fleet: its parameters and, optionally, its propulsion and hull.
template <typename Scalar>
struct FleetVehicle {
  std::string name;                               ///< unique in the fleet, e.g. "rov"
  vehicle::VehicleParameters<Scalar> parameters;  ///< rigid body, added mass, damping, ...
  /// Thrusters and battery, driven by FleetInputs::commands; empty: FleetInputs::vehicles[i].tau
  /// is the whole control wrench.
  std::optional<vehicle::PropulsionParameters<Scalar>> propulsion;
  /// The hull against the seabed and obstacles (kelp/system/hull_contact.hpp); empty: none.
  std::optional<HullContact<Scalar>> hull;
};

/// \brief A tether of a fleet: the line (both ends kinematic, or `free` at a free end: set by
/// FleetModel from the ends), its two ends and an optional winch at its start end.
template <typename Scalar>
struct FleetTether {
  std::string name;                             ///< unique in the fleet, e.g. "umbilical"
  tether::TetherParameters<Scalar> parameters;  ///< the line
  TetherEnd<Scalar> start;                      ///< node 0's end
  TetherEnd<Scalar> end;                        ///< node N's end
  /// A winch at the start end (kelp/tether/winch.hpp), commanded by
  /// FleetInputs::winch_payout_rates; empty: the line keeps its length.
  std::optional<tether::WinchParameters<Scalar>> winch;
};

/// \brief What a fleet is made of.
template <typename Scalar>
struct FleetParameters {
  std::vector<FleetVehicle<Scalar>> vehicles;             ///< any number, ≥ 0
  std::vector<PointMassParameters<Scalar>> point_masses;  ///< any number, ≥ 0
  std::vector<FleetTether<Scalar>> tethers;               ///< any number, ≥ 0
  /// Tether time integration, Newton settings, longest sub-step [s], corrector passes and the
  /// explicit fallback: as SystemParameters' fields of the same names, for every tether.
  tether::Integrator tether_integrator = tether::Integrator::bdf2;
  tether::ImplicitOptions<Scalar> tether_options;  ///< see tether_integrator
  double max_tether_dt = 0.01;                     ///< see tether_integrator
  int coupling_corrections = 0;                    ///< see tether_integrator
  bool explicit_fallback = false;                  ///< see tether_integrator
};

/// \brief The tethered pair as a fleet: vehicles "asv" (0) and "auv" (1), tether "tether" from
/// the ASV's attachment point (with the pair's winch) to the AUV's.
/// \tparam Scalar double or float.
/// \param pair The pair's parameters (not validated here; FleetModel checks the result).
/// \return The fleet: no point masses, the pair's integrator settings.
template <typename Scalar>
FleetParameters<Scalar> fleet_of(const SystemParameters<Scalar>& pair) {
  FleetParameters<Scalar> f;
  f.vehicles.push_back({"asv", pair.asv, pair.asv_propulsion, pair.asv_hull});
  f.vehicles.push_back({"auv", pair.auv, pair.auv_propulsion, pair.auv_hull});
  f.tethers.push_back({"tether", pair.tether, TetherEnd<Scalar>::on_vehicle(0, pair.asv_attachment),
                       TetherEnd<Scalar>::on_vehicle(1, pair.auv_attachment), pair.winch});
  f.tether_integrator = pair.tether_integrator;
  f.tether_options = pair.tether_options;
  f.max_tether_dt = pair.max_tether_dt;
  f.coupling_corrections = pair.coupling_corrections;
  f.explicit_fallback = pair.explicit_fallback;
  return f;
}

namespace detail {
template <typename Scalar>
void check_end(const TetherEnd<Scalar>& e, const FleetParameters<Scalar>& p,
               const std::string& where) {
  switch (e.kind) {
    case EndKind::vehicle:
      KELP_CHECK(e.index >= 0 && std::size_t(e.index) < p.vehicles.size(),
                 where + ": vehicle index " + std::to_string(e.index) + " out of range");
      check_all_finite(e.point, (where + ".point").c_str());
      break;
    case EndKind::point_mass:
      KELP_CHECK(e.index >= 0 && std::size_t(e.index) < p.point_masses.size(),
                 where + ": point mass index " + std::to_string(e.index) + " out of range");
      break;
    case EndKind::anchor:
      check_all_finite(e.point, (where + ".point").c_str());
      break;
    case EndKind::free:
      break;
    default:
      KELP_CHECK(false, where + ": unknown end kind");
  }
}

/// The tether parameters with the end modes its ends imply.
template <typename Scalar>
tether::TetherParameters<Scalar> line_of(const FleetTether<Scalar>& t) {
  tether::TetherParameters<Scalar> p = t.parameters;
  p.start_mode = t.start.kind == EndKind::free ? tether::EndMode::free : tether::EndMode::kinematic;
  p.end_mode = t.end.kind == EndKind::free ? tether::EndMode::free : tether::EndMode::kinematic;
  return p;
}
}  // namespace detail

/// \brief Checks fleet parameters: every part's own checks, unique names, end indices in
/// range, at most one free end per tether and no winch on a free end.
/// \tparam Scalar double or float.
/// \param p The fleet's parameters (also: max_tether_dt finite > 0, coupling_corrections in
/// [0, 16], valid tether_options).
/// \throws kelp::invalid_argument naming the part ("tethers[1] (tms-rov).end: ...").
template <typename Scalar>
void validate(const FleetParameters<Scalar>& p) {
  std::vector<std::string> names;
  const auto unique = [&](const std::string& n, const std::string& where) {
    KELP_CHECK(!n.empty(), where + ".name must not be empty");
    for (const auto& m : names)
      KELP_CHECK(m != n, where + ": the name \"" + n + "\" is used twice");
    names.push_back(n);
  };
  for (std::size_t i = 0; i < p.vehicles.size(); ++i) {
    const auto& v = p.vehicles[i];
    const std::string where = "vehicles[" + std::to_string(i) + "]";
    unique(v.name, where);
    vehicle::validate(v.parameters);
    if (v.propulsion) vehicle::validate(*v.propulsion);
    if (v.hull) validate(*v.hull);
  }
  for (std::size_t i = 0; i < p.point_masses.size(); ++i) {
    unique(p.point_masses[i].name, "point_masses[" + std::to_string(i) + "]");
    validate(p.point_masses[i]);
  }
  for (std::size_t i = 0; i < p.tethers.size(); ++i) {
    const auto& t = p.tethers[i];
    const std::string where = "tethers[" + std::to_string(i) + "] (" + t.name + ")";
    unique(t.name, "tethers[" + std::to_string(i) + "]");
    detail::check_end(t.start, p, where + ".start");
    detail::check_end(t.end, p, where + ".end");
    KELP_CHECK(t.start.kind != EndKind::free || t.end.kind != EndKind::free,
               where + ": at most one end may hang free");
    KELP_CHECK(!t.winch || t.start.kind != EndKind::free,
               where + ": a winch needs a start end fixed to something");
    tether::validate(detail::line_of(t));
  }
  tether::detail::check_implicit_options(p.tether_options);
  check_positive(p.max_tether_dt, "max_tether_dt");
  KELP_CHECK(p.coupling_corrections >= 0 && p.coupling_corrections <= 16,
             "coupling_corrections must be in [0, 16]");
}

}  // namespace kelp::system
