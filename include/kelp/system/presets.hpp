/// \file
/// \brief The paper's configuration as a system preset: a BlueBoat, a BlueROV2 Heavy, a 5, 10 or
/// 15 m tether (a Fathom-class ROV tether, or the lumped-mass equivalent of the paper's Gazebo
/// bead chain) attached to both, in the calm, moderate or rough sea of the paper's evaluation
/// (Buchholz, Carlucho, Grimaldi, Petillot 2025, "Tethered Multi-Robot Systems in Marine
/// Environments", arXiv:2508.02264).
///
/// Attachment points (assumed; neither vehicle has a standard tow point):
/// - BlueBoat: on the transom at the keel, (−0.5, 0, 0.08) m from the CO (which is on the still
///   waterline; hull length ≈ 1.2 m, draft 7.7 cm, see vehicle::blueboat), so the line leaves
///   the hull under water;
/// - BlueROV2 Heavy: the tether penetrator on the aft end cap of the electronics enclosure,
///   (−0.2, 0, −0.05) m from the CO (frame length 457 mm; Blue Robotics BlueROV2 technical
///   details).
///
/// Propulsion: both vehicles' thrusters and batteries are part of the system
/// (SystemParameters::asv_propulsion / auv_propulsion: T200 thrust lag of
/// vehicle::t200_time_constant, the Blue Robotics battery presets of vehicle/battery.hpp); set
/// them to std::nullopt for the earlier behaviour, where `inputs.tau` is the whole control wrench.
///
/// Tether discretisation: 0.5 m segments, the spacing of the paper's Gazebo beads (20 segments
/// for 10 m). Against 0.25 m segments, the static shape of the default configuration moves by
/// 2 cm (the nearly neutral line hangs under forces of a few centinewtons) and the end tensions
/// by under 1 % (tests/system/test_system.cpp), for half the cost.
#pragma once

#include <algorithm>
#include <cmath>

#include "kelp/core/error.hpp"
#include "kelp/core/types.hpp"
#include "kelp/environment/sea_state.hpp"
#include "kelp/system/system.hpp"
#include "kelp/tether/presets.hpp"
#include "kelp/vehicle/battery.hpp"
#include "kelp/vehicle/presets.hpp"
#include "kelp/vehicle/propulsion.hpp"

namespace kelp::system::presets {

/// \brief Which line joins the vehicles.
enum class TetherKind {
  rov_tether,  ///< Fathom-class 7.6 mm ROV tether (tether::presets::rov_tether)
  bead_chain  ///< the paper's Gazebo bead chain as a lumped-mass line (tether::presets::bead_chain)
};

/// \brief The paper's sea states.
enum class Sea {
  calm,      ///< environment::presets::calm()
  moderate,  ///< environment::presets::moderate()
  rough      ///< environment::presets::rough()
};

/// \brief The sea state of `sea` (environment::presets).
/// \param sea One of the paper's sea states.
/// \return Its waves, wind and current.
/// \throws kelp::invalid_argument when `sea` is not a Sea value.
inline environment::SeaState sea_state(Sea sea) {
  switch (sea) {
    case Sea::calm:
      return environment::presets::calm();
    case Sea::moderate:
      return environment::presets::moderate();
    case Sea::rough:
      return environment::presets::rough();
  }
  ::kelp::detail::throw_invalid_argument("sea is not a kelp::system::presets::Sea value");
}

/// \brief The environment of `sea`: JONSWAP waves with the default number of components, wind
/// with gusts and current, in seawater (environment::make_environment).
/// \tparam Scalar double or float.
/// \param sea One of the paper's sea states.
/// \param options How the sea state becomes an environment (components, seeds, ...).
/// \return The environment.
/// \throws kelp::invalid_argument when `sea` is not a Sea value or `options` is invalid.
template <typename Scalar>
environment::Environment<Scalar> environment(Sea sea,
                                             const environment::SeaStateOptions& options = {}) {
  return environment::make_environment<Scalar>(sea_state(sea), options);
}

/// \brief BlueBoat tether point, body axes [m] (see the file comment).
/// \tparam Scalar double or float.
/// \return (−0.5, 0, 0.08) m from the CO, body axes.
template <typename Scalar>
Vector3<Scalar> blueboat_attachment() {
  return Vector3<Scalar>(Scalar(-0.5), Scalar(0), Scalar(0.08));
}

/// \brief BlueROV2 Heavy tether point, body axes [m] (see the file comment).
/// \tparam Scalar double or float.
/// \return (−0.2, 0, −0.05) m from the CO, body axes.
template <typename Scalar>
Vector3<Scalar> bluerov2_attachment() {
  return Vector3<Scalar>(Scalar(-0.2), Scalar(0), Scalar(-0.05));
}

/// \brief The propulsion of a vehicle preset: its thrusters (positions, directions, facing; the
/// ESC command scale of its PWM mapping) on `battery`, with the T200 lag of `time_constant` [s]
/// (0: none).
/// \tparam Scalar double or float.
/// \param preset The vehicle preset (vehicle::blueboat, vehicle::bluerov2_heavy, ...).
/// \param battery The battery the thrusters draw from.
/// \param time_constant First-order thrust lag [s] (default vehicle::t200_time_constant).
/// \return Propulsion parameters (not validated here; the propulsion model checks them).
template <typename Scalar>
vehicle::PropulsionParameters<Scalar> propulsion_of(
    const vehicle::VehiclePreset<Scalar>& preset, const vehicle::BatteryParameters& battery,
    double time_constant = vehicle::t200_time_constant) {
  vehicle::PropulsionParameters<Scalar> p;
  p.positions = preset.thruster_positions;
  p.directions = preset.thruster_directions;
  p.time_constant = time_constant;
  p.battery = battery;
  const Eigen::Index n = preset.thruster_positions.cols();
  p.facing = vehicle::ThrusterVector<int>::Ones(n);
  for (Eigen::Index i = 0; i < preset.thruster_facing.size() && i < n; ++i)
    p.facing(i) = preset.thruster_facing(i) < 0 ? -1 : 1;
  p.esc_scale_forward =
      double(value_of(preset.pwm.max_us - preset.pwm.neutral_us)) / vehicle::t200_esc_half_range_us;
  p.esc_scale_reverse =
      double(value_of(preset.pwm.neutral_us - preset.pwm.min_us)) / vehicle::t200_esc_half_range_us;
  return p;
}

/// \brief The paper's system: BlueBoat (ASV), BlueROV2 Heavy (AUV) and a tether of
/// `tether_length` [m] (the paper evaluates 5, 10 and 15 m), in seawater; BDF2 tether steps of at
/// most 10 ms with the library's Newton settings (tether::ImplicitOptions' defaults) and no
/// explicit fallback (SystemParameters' default): a step Newton's method cannot converge, even
/// split in halves, throws with the state unchanged. Both vehicles have their propulsion (see the
/// file comment): T200s with a 20 ms lag on the BlueBoat's two packs in parallel and the
/// BlueROV2's one (vehicle::battery_presets).
/// \tparam Scalar double or float.
/// \param tether_length Unstretched tether length L [m] (> 0; default 10 m).
/// \param kind Which line: the ROV tether (0.5 m segments) or the bead chain.
/// \return The system's parameters.
/// \throws kelp::invalid_argument for a non-positive length or a `kind` that is not a TetherKind.
template <typename Scalar>
SystemParameters<Scalar> paper_system(Scalar tether_length = Scalar(10),
                                      TetherKind kind = TetherKind::rov_tether) {
  check_positive(tether_length, "tether_length");
  SystemParameters<Scalar> p;
  const vehicle::VehiclePreset<Scalar> boat = vehicle::blueboat<Scalar>();
  const vehicle::VehiclePreset<Scalar> rov = vehicle::bluerov2_heavy<Scalar>();
  p.asv = boat.parameters;
  p.auv = rov.parameters;
  p.asv_propulsion = propulsion_of(boat, vehicle::battery_presets::blueboat_battery());
  p.auv_propulsion = propulsion_of(rov, vehicle::battery_presets::bluerov2_battery());
  p.asv_attachment = blueboat_attachment<Scalar>();
  p.auv_attachment = bluerov2_attachment<Scalar>();
  switch (kind) {
    case TetherKind::rov_tether:
      p.tether = tether::presets::rov_tether(tether_length, Scalar(0.5));
      break;
    case TetherKind::bead_chain:
      p.tether = tether::presets::bead_chain(tether_length);
      break;
    default:
      ::kelp::detail::throw_invalid_argument("kind is not a TetherKind value");
  }
  return p;
}

/// \brief Where the paper's vehicles start: the boat at the origin heading north, the ROV
/// straight astern of it at 5 m depth (0.6 L for tethers shorter than 8.3 m), at a distance
/// between the tether points of 80 % of the tether length, both at rest.
/// \tparam Scalar double or float.
template <typename Scalar>
struct StartPoses {
  vehicle::VehicleState<Scalar> asv,  ///< the boat's state: at the origin, level, heading north
      auv;                            ///< the ROV's state: astern of the boat, level, at rest
};

/// \brief The start poses of `paper_system(tether_length)` (see StartPoses).
/// \tparam Scalar double or float.
/// \param tether_length Unstretched tether length L [m] (> 0; default 10 m).
/// \return Both vehicles' start states.
/// \throws kelp::invalid_argument for a non-positive length.
template <typename Scalar>
StartPoses<Scalar> paper_start(Scalar tether_length = Scalar(10)) {
  using std::sqrt;
  check_positive(tether_length, "tether_length");
  StartPoses<Scalar> s;
  const Vector3<Scalar> a = s.asv.point_position(blueboat_attachment<Scalar>());
  const Scalar depth = std::min(Scalar(5), Scalar(0.6) * tether_length);
  const Scalar chord = Scalar(0.8) * tether_length;
  // The ROV's tether point at (a.x − d, 0, depth) with |chord| = 0.8 L.
  const Scalar dz = depth - a(2);
  const Scalar d = sqrt(std::max(Scalar(0), chord * chord - dz * dz));
  const Vector3<Scalar> b(a(0) - d, Scalar(0), depth);
  s.auv.position = b - bluerov2_attachment<Scalar>();
  return s;
}

/// \brief The paper's system built in the sea `sea`, its workspace and its start state.
/// \tparam Scalar double or float.
template <typename Scalar>
struct PaperWorld {
  SystemModel<Scalar> model;          ///< the system
  SystemWorkspace<Scalar> workspace;  ///< its buffers
  SystemState<Scalar> state;          ///< the start state (paper_start, static tether)

  /// \brief Builds the system, its workspace and the start state (the tether's static shape).
  /// \param tether_length Unstretched tether length L [m] (> 0).
  /// \param sea One of the paper's sea states.
  /// \param kind Which line joins the vehicles.
  /// \param options How the sea state becomes an environment.
  /// \throws kelp::invalid_argument for bad arguments (see paper_system and environment);
  /// kelp::numerical_error when the tether's static solve does not converge (see initial_state).
  PaperWorld(Scalar tether_length, Sea sea, TetherKind kind = TetherKind::rov_tether,
             const environment::SeaStateOptions& options = {})
      : model(paper_system(tether_length, kind), environment<Scalar>(sea, options)),
        workspace(model) {
    const StartPoses<Scalar> p = paper_start(tether_length);
    state = initial_state(model, workspace, p.asv, p.auv);
  }
};

}  // namespace kelp::system::presets
