/// \file
/// \brief Tether presets: a real ROV tether of the kind the paper's vehicles use, and the
/// lumped-mass equivalent of the paper's Gazebo bead chain, so that users can compare with it.
///
/// Sources:
/// - Blue Robotics, "Fathom ROV Tether" product page: the standard (not Slim) tether is 7.6 mm in
///   outer diameter and sold in a variant that is neutrally buoyant in fresh water.
/// - von Benzon, M. et al. (2022), "An open-source benchmark simulator: control of a BlueROV2
///   underwater robot", J. Mar. Sci. Eng. 10(12), 1898, Table A1: a 7.5 mm ROV tether with
///   Young's modulus 6.437e7 Pa, normal drag 1.2, tangential drag 0.01, internal damping 100 N s.
/// - Buchholz, Carlucho, Grimaldi, Petillot (2025), "Tethered Multi-Robot Systems in Marine
///   Environments", arXiv:2508.02264: the Gazebo tether is a chain of spheres 0.5 m apart
///   (radius 0.01 m, 0.00429 kg each, neutrally buoyant in seawater) on ball joints.
#pragma once

#include <cmath>

#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/tether/lumped_mass.hpp"

namespace kelp::tether::presets {

/// \brief A Fathom-class ROV tether of `length` [m] (the paper evaluates 5, 10 and 15 m), cut into
/// segments of at most `max_segment_length` [m], both ends kinematic (attached to vehicles).
///
/// Diameter 7.6 mm (Blue Robotics, standard Fathom); mass per length ρ_fresh A = 0.0454 kg/m, the
/// neutrally-buoyant-in-fresh-water variant, so it is slightly buoyant in seawater
/// (−0.011 N/m); EA = E π d²/4 = 2.92 kN with von Benzon et al.'s E = 6.437e7 Pa; Cdn 1.2,
/// Cdt 0.01, internal damping 100 N s (von Benzon et al. 2022, Table A1); Can 1, Cat 0;
/// breaking strength 1557 N (350 lbf, Blue Robotics' Fathom ROV Tether R2 documentation).
/// The internal damping as a damping ratio (TetherParameters::internal_damping_ratio, MoorDyn's
/// `BA/-zeta`): ζ = BA / (l sqrt(EA μ)) with sqrt(EA μ) = 11.51 N s/m, i.e. 34.8 at the default
/// 0.25 m segments and 8.7 at 1 m: the axial mode is far above critical damping at any
/// practical segment length.
/// \throws kelp::invalid_argument for a length not finite in (0, 1e5] m, a segment length not
/// finite and > 0, more than 100000 segments, or segments L / N shorter than
/// limits::min_segment_length (1 µm): the counts and lengths TetherModel refuses.
/// \tparam Scalar double or float.
/// \param length the unstretched length L [m], in (0, 1e5].
/// \param max_segment_length the longest segment [m] (default 0.25 m): N = ⌈L / it⌉, at least 1;
/// L / N must be at least 1 µm.
/// \return the parameters (not yet validated: TetherModel does that).
template <typename Scalar>
TetherParameters<Scalar> rov_tether(Scalar length, Scalar max_segment_length = Scalar(0.25)) {
  check_positive(length, "length");
  check_at_most(length, limits::max_length, "length");
  check_positive(max_segment_length, "max_segment_length");
  const double count = std::ceil(double(value_of(length / max_segment_length)) - 1e-9);
  // Before the conversion to int (undefined beyond its range).
  check_at_most(count, double(limits::max_segments), "length / max_segment_length (segments)");
  const double d = 7.6e-3, area = kelp::pi * d * d / 4.0;
  TetherParameters<Scalar> p;
  p.length = length;
  p.segments = static_cast<int>(count);
  if (p.segments < 1) p.segments = 1;
  // TetherModel's rule (validate(const TetherParameters&)), so that the preset never gives a
  // line the model refuses.
  check_at_least(p.length / Scalar(p.segments), limits::min_segment_length,
                 "rov_tether: length / segments (the segment length)");
  p.diameter = Scalar(d);
  p.mass_per_length = Scalar(1000.0 * area);
  p.axial_stiffness = Scalar(6.437e7 * area);
  p.normal_drag = Scalar(1.2);
  p.tangential_drag = Scalar(0.01);
  p.internal_damping = Scalar(100);
  p.normal_added_mass = Scalar(1);
  p.tangential_added_mass = Scalar(0);
  // Blue Robotics, "Fathom ROV Tether (R2)" documentation: "350+ lb breaking strength",
  // 350 lbf × 4.44822 N/lbf = 1557 N.
  p.breaking_strength = Scalar(1557);
  return p;
}

/// \brief The lumped-mass equivalent of the paper's Gazebo tether of `length` [m]: one node per
/// bead, 0.5 m apart.
///
/// Each bead (a sphere of radius 0.01 m and mass 0.00429 kg, neutrally buoyant in seawater) becomes
/// 0.5 m of line with the same mass and displaced volume: μ = 0.00858 kg/m and an equivalent
/// diameter √(4 V/(π · 0.5 m)) = 3.27 mm. The sphere's drag (C_D ≈ 0.47 on π r², Hoerner 1965,
/// Fluid-Dynamic Drag, for a sphere below the drag crisis) spread over the segment's projected
/// area d·l gives Cdn = 0.09; a sphere has no tangential friction to speak of (Cdt = 0) and an
/// added-mass coefficient of ½ in every direction (Can = Cat = 0.5). The ball joints transmit no
/// bending moment (EI = 0) and the links do not stretch: EA = 1e5 N keeps the stretch under the
/// line's own loads below 1e-6 (the joints' ±1.5 rad limits and 0.05 damping have no lumped-mass
/// counterpart and are left out). `length` is rounded to whole beads (at least one segment).
/// \throws kelp::invalid_argument for a length not finite in (0, 1e5] m.
/// \tparam Scalar double or float.
/// \param length the wanted length [m], in (0, 1e5]; rounded to a multiple of 0.5 m.
/// \return the parameters, with `length` the rounded one.
template <typename Scalar>
TetherParameters<Scalar> bead_chain(Scalar length) {
  check_positive(length, "length");
  check_at_most(length, limits::max_length, "length");
  const double spacing = 0.5, radius = 0.01, bead_mass = 0.00429;
  const double volume = 4.0 / 3.0 * kelp::pi * radius * radius * radius;
  const double d = std::sqrt(4.0 * volume / (kelp::pi * spacing));
  TetherParameters<Scalar> p;
  p.segments = static_cast<int>(std::lround(double(value_of(length)) / spacing));
  if (p.segments < 1) p.segments = 1;
  p.length = Scalar(spacing * p.segments);
  p.diameter = Scalar(d);
  p.mass_per_length = Scalar(bead_mass / spacing);
  p.axial_stiffness = Scalar(1e5);
  p.normal_drag = Scalar(0.47 * kelp::pi * radius * radius / (d * spacing));
  p.tangential_drag = Scalar(0);
  p.normal_added_mass = Scalar(0.5);
  p.tangential_added_mass = Scalar(0.5);
  p.internal_damping = Scalar(0);
  return p;
}

}  // namespace kelp::tether::presets
