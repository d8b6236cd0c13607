/// \file
/// \brief Vehicle presets: BlueROV2 Heavy (8 thrusters, ArduSub vectored_6dof order) and BlueBoat
/// (2 thrusters, skid steering). Every number carries its source; assumptions are marked
/// "assumed" with the reasoning.
#pragma once

#include <cmath>
#include <string>

#include "kelp/core/constants.hpp"
#include "kelp/core/types.hpp"
#include "kelp/vehicle/model.hpp"
#include "kelp/vehicle/thrusters.hpp"

namespace kelp::vehicle {

/// \brief A vehicle with its thrusters: dynamics parameters, thruster geometry (positive command ⇒
/// thrust along the direction), which way each thruster faces, and PWM mapping. Thrust per
/// thruster follows t200_thrust() with its facing (ThrusterChain).
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
struct VehiclePreset {
  /// Human-readable name.
  std::string name;
  /// Rigid body, added mass, damping, hydrostatics.
  VehicleParameters<Scalar> parameters;
  /// r_i [m], 3×n, body axes relative to the CO, in autopilot output order.
  Matrix3X<Scalar> thruster_positions;
  /// d_i (unit), 3×n, body axes: thrust direction for a positive command (PWM above neutral).
  Matrix3X<Scalar> thruster_directions;
  /// ±1 per thruster: +1 when a positive command gives the thruster's forward (stronger) thrust
  /// along its direction (the T200 pushed towards its nose cone), −1 when it gives its reverse
  /// thrust (see ThrusterChain).
  Eigen::VectorXd thruster_facing;
  /// PWM ↔ command mapping of the ESCs.
  PwmMapping<Scalar> pwm;
};

/// \brief BlueROV2 Heavy.
///
/// Sources: von Benzon et al. 2022, "An Open-Source Benchmark Simulator: Control of a BlueROV2
/// Underwater Robot", J. Mar. Sci. Eng. 10(12):1898, Table A1 (= Wu 2018, Flinders University
/// thesis): m = 13.5 kg, ∇ = 0.0134 m³, r_g = 0, r_b = (0, 0, −0.01) m, I = diag(0.26, 0.23, 0.37)
/// kg m², added mass (6.36, 7.12, 18.68, 0.189, 0.135, 0.222), linear damping
/// (13.7, 0, 33, 0, 0.8, 0), quadratic damping (141, 217, 190, 1.19, 0.47, 1.5).
/// That paper used ρ = 1000 kg/m³ and g = 9.82 m/s² (then W − B = +0.98 N, slightly heavy);
/// kelp defaults to seawater (ρ = 1025, g = 9.80665: B − W = 2.3 N, slightly buoyant, as a
/// trimmed ROV is). Pass the paper's values to reproduce it.
///
/// Thrusters (8 × T200), in ArduSub's vectored_6dof motor order (ArduPilot
/// libraries/AP_Motors/AP_Motors6DOF.cpp): 1 front-right, 2 front-left, 3 rear-right, 4 rear-left
/// (horizontal, vectored 45°), 5 front-right, 6 front-left, 7 rear-right, 8 rear-left (vertical).
/// Positions from von Benzon 2022: horizontals at (±0.156, ±0.111, 0.085) m, verticals at (±0.12,
/// ±0.218, 0) m (the paper writes them as Rz(α) of the front-right one; the mirrored values are
/// used exactly). Directions are the thrust of a *positive* ArduSub output, derived from the motor
/// factor signs (forward/lateral/throttle and yaw/roll/pitch): e.g. motor 1 has forward −1, lateral
/// +1, so its positive thrust points aft-starboard, (−1, 1, 0)/√2; vertical thrusters push down
/// (+z) for PWM > 1500. They are the opposite of von Benzon's drawn directions, which is the same
/// as flipping the sign of an odd thrust curve.
///
/// Facing: all +1. ArduSub's motor factors are written for each thruster's forward direction,
/// the way the front (cable side) of the T200 points; the propeller's handedness and the
/// winding order are absorbed by MOTn_DIRECTION (Blue Robotics forum, "BlueROV2 Vectored
/// Configuration Throttle Factor", https://discuss.bluerobotics.com/t/13210, and "BlueROV2 Heavy
/// 6-DOF model", https://discuss.bluerobotics.com/t/13065: "model the force directions based on
/// the front direction of each thruster ... which is effectively what ArduSub does"). So a
/// positive output gives forward thrust along the directions above. This matches the frame:
/// "the front two thrusters facing more backwards and the rear two thrusters facing more
/// forwards" (https://discuss.bluerobotics.com/t/12044): motors 1–2 push aft and 3–4 forward
/// with their strong side, so surge is about equally strong both ways (two forward and two
/// reverse branches either way), and the verticals push down (+z) with their strong side.
///
/// Free surface (Hydrostatics::submerged_free_surface): the hull is a box of height 0.254 m about
/// the CB (Blue Robotics BlueROV2 Heavy technical details: height 254 mm); its buoyancy falls
/// linearly with the emerged fraction. With the seawater defaults the unpowered vehicle floats at
/// φ = W/B ≈ 0.983, its top ≈ 4 mm above the surface.
/// \param[in] density ρ [kg/m³]. \param[in] gravity g [m/s²].
/// \throws kelp::invalid_argument naming `density` or `gravity` and the value unless ρ is in
/// (0, 1e5] kg/m³ and g in (0, 1000] m/s² (see `validate(const VehicleParameters&)`).
/// \return the parameters, the 8 thrusters' positions and directions (body frame [m]) and facing,
/// and the PWM mapping.
template <typename Scalar>
VehiclePreset<Scalar> bluerov2_heavy(const Scalar& density = Scalar(seawater_density),
                                     const Scalar& gravity = Scalar(standard_gravity)) {
  detail::check_water(density, gravity);
  VehiclePreset<Scalar> p;
  p.name = "BlueROV2 Heavy";
  VehicleParameters<Scalar>& v = p.parameters;
  v.mass = Scalar(13.5);
  v.inertia = Vector3<Scalar>(Scalar(0.26), Scalar(0.23), Scalar(0.37)).asDiagonal();
  v.r_g = Vector3<Scalar>::Zero();
  v.r_b = Vector3<Scalar>(Scalar(0), Scalar(0), Scalar(-0.01));
  v.displaced_volume = Scalar(0.0134);
  v.density = density;
  v.gravity = gravity;
  Vector6<Scalar> ma, dl, dq;
  ma << Scalar(6.36), Scalar(7.12), Scalar(18.68), Scalar(0.189), Scalar(0.135), Scalar(0.222);
  dl << Scalar(13.7), Scalar(0), Scalar(33), Scalar(0), Scalar(0.8), Scalar(0);
  dq << Scalar(141), Scalar(217), Scalar(190), Scalar(1.19), Scalar(0.47), Scalar(1.5);
  v.added_mass = ma.asDiagonal();
  v.damping.linear = dl.asDiagonal();
  v.damping.quadratic = dq;
  v.hydrostatics = Hydrostatics::submerged_free_surface;
  v.hull_height = Scalar(0.254);

  const Scalar xh(0.156), yh(0.111), zh(0.085), xv(0.12), yv(0.218);
  const Scalar s = Scalar(1) / Scalar(std::sqrt(2.0));
  p.thruster_positions.resize(3, 8);
  p.thruster_directions.resize(3, 8);
  p.thruster_positions << xh, xh, -xh, -xh, xv, xv, -xv, -xv,  //
      yh, -yh, yh, -yh, yv, -yv, yv, -yv,                      //
      zh, zh, zh, zh, Scalar(0), Scalar(0), Scalar(0), Scalar(0);
  const Scalar o(0), one(1);
  p.thruster_directions << -s, -s, s, s, o, o, o, o,  //
      s, -s, s, -s, o, o, o, o,                       //
      o, o, o, o, one, one, one, one;
  p.thruster_facing = Eigen::VectorXd::Ones(8);
  return p;
}

/// \brief BlueBoat (Blue Robotics ASV), 6-DOF with surface hydrostatics.
///
/// Few parameters are published (Blue Robotics product data; Buchholz et al., "Tethered
/// Multi-Robot Systems in Marine Environments", and its simulation framework); the preset states
/// each choice:
/// - m = 15 kg (Blue Robotics product data: 14–15 kg without payload).
/// - Inertia about the CG diag(1.21, 1.96, 2.82) kg m²: assumed, the paper framework's Gazebo
///   model (m 30 kg, 2.42/3.92/5.64) scaled by the mass ratio 15/30.
/// - r_g = 0: the CO is placed at the CG, on the still waterline (assumed).
/// - ∇ = m/ρ (floats at z = 0). Waterplane: two hulls ≈ 1.1 m × 0.11 m each with waterplane
///   coefficient 0.8 ⇒ A_wp ≈ 0.19 m² (assumed from L ≈ 1.2 m, beam ≈ 1.0 m product data);
///   draft ∇/A_wp ≈ 7.7 cm. Metacentric heights (assumed, hull geometry): GM_T ≈ 2.0 m (hulls
///   ≈ ±0.4 m apart give BM_T = I_T/∇ ≈ 2.1 m), GM_L ≈ 1.3 m.
/// - Added mass: surge 2.25 kg, sway 23.13 kg, yaw 2.79 kg m² (Heron-class 3-DOF model of the
///   paper's framework; the unsymmetric sway–yaw coupling is dropped); heave 15 kg
///   (assumed ≈ m), roll 0.12, pitch 0.2 kg m² (assumed ≈ 10 % of the inertia).
/// - Damping: surge linear 5 N s/m (assumed) and quadratic 8.8 N s²/m², chosen so that the
///   simulated top speed at full command is 3.0 m/s, the maximum speed Blue Robotics lists for the
///   standard BlueBoat with two batteries on board (Blue Robotics staff, "Blueboat | 4x M200?",
///   discuss.bluerobotics.com/t/blueboat-4x-m200/19831: "We do list the maximum speed of the
///   standard BlueBoat, with only two batteries on board, as 3.0 m/s"), with two T200 on the
///   datasheet curve (t200.hpp) at the voltage of a full blueboat_battery() under their full
///   current: 15.76 V, 2 × 50.8 N (see below); sway linear 20 (assumed) and quadratic 99.99
///   (Heron model); heave linear
///   100, roll 8, pitch 8 (assumed, ≈ 0.2 of critical damping), quadratic heave 50, roll 2,
///   pitch 2 (assumed); yaw linear 10 (assumed) and quadratic 3.49 (Heron model).
/// - Thrusters: 2 × T200, left (port) first then right, as ArduRover's skid steering outputs
///   ThrottleLeft (SERVO1) and ThrottleRight (SERVO3) (ArduPilot
///   Tools/autotest/default_params/rover-skid.parm). Positions (−0.488, ∓0.295)
///   m from the paper framework's Gazebo model (converted from its y-left axes); depth 0.10 m
///   below the waterline (assumed). Directions +x, both facing forward (+1: a positive throttle
///   gives each T200's stronger, forward thrust). PWM 1000–1500–2000 µs (rover.parm SERVO
///   limits) with the ±25 µs dead band.
/// - Hull depth keel to deck 0.20 m (assumed; product height ≈ 0.33 m including the deck
///   electronics): the heave force saturates at the draft (fully emerged, net force = weight) and
///   at 0.20 m (fully submerged, reserve buoyancy ρ g A_wp 0.20 − W ≈ 235 N).
/// - Wind: frontal area 0.15 m² (1.0 m beam × 0.15 m above water), lateral area 0.25 m² (1.2 m ×
///   ≈ 0.2 m hulls and deck box), L_oa = 1.2 m (assumed from the product dimensions); constant
///   coefficients c_x = 0.6, c_y = 0.8 (assumed, mid-range of Fossen 2021 §10.1.1's values for
///   small craft), c_n = 0 (fore-aft symmetric profile assumed: no wind yaw moment).
/// Resulting behaviour (checked by tests/vehicle): top speed 3.00 m/s with the T200 datasheet
/// thrust at the full pack's 15.76 V (2 × 50.8 N; 4 % below the pure surge balance
/// 5u + 8.8u² = 101.5 N ⇒ 3.12 m/s: the thrusters' lever arm below the CO and the Munk moment
/// of the heave added mass, (Z_ẇ − X_u̇) u w, trim the bow up ≈ 8° at that speed, and the heave
/// restoring force then has a surge component); damped natural periods heave 0.81 s, roll
/// 0.43 s, pitch 0.68 s. (Until 2026-11 the surge quadratic damping was 5, chosen for von
/// Benzon's 30.4 N curve: with the datasheet thrust it gave 3.3 m/s.)
/// \param[in] density ρ [kg/m³]. \param[in] gravity g [m/s²].
/// \throws kelp::invalid_argument naming `density` or `gravity` and the value unless ρ is in
/// (0, 1e5] kg/m³ and g in (0, 1000] m/s² (the displaced volume is m/ρ).
/// \return the parameters, the 2 thrusters' positions and directions (body frame [m]) and facing,
/// and the PWM mapping.
template <typename Scalar>
VehiclePreset<Scalar> blueboat(const Scalar& density = Scalar(seawater_density),
                               const Scalar& gravity = Scalar(standard_gravity)) {
  detail::check_water(density, gravity);
  VehiclePreset<Scalar> p;
  p.name = "BlueBoat";
  VehicleParameters<Scalar>& v = p.parameters;
  v.mass = Scalar(15.0);
  v.inertia = Vector3<Scalar>(Scalar(1.21), Scalar(1.96), Scalar(2.82)).asDiagonal();
  v.r_g = Vector3<Scalar>::Zero();
  v.r_b = Vector3<Scalar>::Zero();
  v.density = density;
  v.gravity = gravity;
  v.displaced_volume = v.mass / density;
  v.hydrostatics = Hydrostatics::surface;
  v.waterplane_area = Scalar(0.19);
  v.gm_transverse = Scalar(2.0);
  v.gm_longitudinal = Scalar(1.3);
  v.hull_height = Scalar(0.20);
  v.wind_areas.frontal_area = 0.15;
  v.wind_areas.lateral_area = 0.25;
  v.wind_areas.length_overall = 1.2;
  v.wind_coefficients.cx = 0.6;
  v.wind_coefficients.cy = 0.8;
  v.wind_coefficients.cn = 0.0;
  Vector6<Scalar> ma, dl, dq;
  ma << Scalar(2.25), Scalar(23.13), Scalar(15.0), Scalar(0.12), Scalar(0.2), Scalar(2.79);
  dl << Scalar(5.0), Scalar(20.0), Scalar(100.0), Scalar(8.0), Scalar(8.0), Scalar(10.0);
  dq << Scalar(8.8), Scalar(99.99), Scalar(50.0), Scalar(2.0), Scalar(2.0), Scalar(3.49);
  v.added_mass = ma.asDiagonal();
  v.damping.linear = dl.asDiagonal();
  v.damping.quadratic = dq;

  p.thruster_positions.resize(3, 2);
  p.thruster_directions.resize(3, 2);
  p.thruster_positions << Scalar(-0.488), Scalar(-0.488),  //
      Scalar(-0.295), Scalar(0.295),                       //
      Scalar(0.10), Scalar(0.10);
  p.thruster_directions << Scalar(1), Scalar(1), Scalar(0), Scalar(0), Scalar(0), Scalar(0);
  p.thruster_facing = Eigen::VectorXd::Ones(2);
  p.pwm.min_us = Scalar(1000);
  p.pwm.max_us = Scalar(2000);
  return p;
}

/// \brief Vehicle preset in double precision.
using VehiclePresetd = VehiclePreset<double>;
/// \brief Vehicle preset in single precision.
using VehiclePresetf = VehiclePreset<float>;

}  // namespace kelp::vehicle
