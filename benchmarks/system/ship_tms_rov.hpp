// The work-class fleet of bench_system's BM_ShipTmsRovStep and kelp-system-work-precision: a
// ship's sheave (an anchor at the surface), a 60 m armoured umbilical (60 segments, EA 3 MN) to a
// TMS (a 400 kg point mass at ~50 m), a 30 m ROV tether (60 segments) on the TMS's winch to a
// BlueROV2 Heavy: 90 m of line, in the paper's rough sea.
#pragma once

#include <vector>

#include "kelp/system/fleet.hpp"
#include "kelp/system/presets.hpp"

namespace kelp_bench {

/// The fleet's parameters (tether 0 the umbilical, tether 1 the ROV's tether).
inline kelp::system::FleetParametersd ship_tms_rov_parameters() {
  namespace ks = kelp::system;
  namespace kt = kelp::tether;
  ks::FleetParametersd p;
  p.vehicles.push_back({"rov", kelp::vehicle::bluerov2_heavy<double>().parameters, {}, {}});
  ks::PointMassParametersd tms;
  tms.name = "tms";
  tms.mass = 400;
  tms.volume = 0.2;
  tms.drag_area = 1.0;
  p.point_masses.push_back(tms);
  kt::TetherParametersd umbilical = kt::presets::rov_tether(60.0, 1.0);
  umbilical.diameter = 0.025;
  umbilical.mass_per_length = 1.2;
  umbilical.axial_stiffness = 3e6;
  umbilical.internal_damping = 0;
  umbilical.internal_damping_ratio = 0.5;
  umbilical.breaking_strength = 0;
  kt::WinchParametersd winch;
  winch.min_length = 5;
  winch.max_length = 60;
  p.tethers.push_back({"umbilical",
                       umbilical,
                       ks::TetherEnd<double>::at_anchor({0, 0, 0}),
                       ks::TetherEnd<double>::on_point_mass(0),
                       {}});
  p.tethers.push_back(
      {"tether", kt::presets::rov_tether(30.0, 0.5), ks::TetherEnd<double>::on_point_mass(0),
       ks::TetherEnd<double>::on_vehicle(0, ks::presets::bluerov2_attachment<double>()), winch});
  return p;
}

/// The ROV's start position (NED [m]); the TMS starts at ship_tms_rov_tms_start().
inline kelp::Vector3<double> ship_tms_rov_rov_start() { return {20, 0, 60}; }
/// The TMS's start position (NED [m]).
inline kelp::Vector3<double> ship_tms_rov_tms_start() { return {8, 0, 50}; }

}  // namespace kelp_bench
