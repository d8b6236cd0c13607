/// \file
/// \brief `WaveStretching`: how the wave field (kelp/environment/waves.hpp) takes its orbital
/// kinematics near the free surface. A header of its own, with no includes, so that a scenario
/// (kelp/sim/scenario.hpp) can name the choice without the wave field.
#pragma once

namespace kelp {
namespace environment {

/// \brief How the orbital kinematics are taken near the free surface, where linear theory (valid
/// up to the mean level z = 0) says nothing (DNV-RP-C205 (2010) lists these methods with its wave
/// kinematics).
enum class WaveStretching {
  /// Vertical extrapolation (the default, and kelp's only method before regular waves came):
  /// below the mean level the linear profiles at the point's depth z; between the mean level and
  /// a crest (−ζ ≤ z < 0) those at z = 0. One pass over the components.
  vertical,
  /// Wheeler stretching (J. D. Wheeler 1970, "Method for calculating forces produced by
  /// irregular waves", Journal of Petroleum Technology 22(3), 359–367): the wetted column from
  /// the instantaneous surface z = −ζ down to the seabed z = h is mapped linearly onto the mean
  /// column [0, h], z' = (z + ζ) h / (h + ζ) (deep water: z' = z + ζ), and the linear profiles
  /// are taken at z'. At the free surface z' = 0: the kinematics there equal linear theory's at
  /// the mean level, under a crest and under a trough alike; at the seabed z' = h. Below the
  /// mean level it changes them too: under a crest (ζ > 0) a point reads the profile of a deeper
  /// point (smaller kinematics than linear theory's at z), under a trough that of a shallower
  /// one (larger). The elevation at each point is summed first (a second pass of the kernel):
  /// a query costs about 1.7 times the vertical method's (41 points of the moderate sea's 64
  /// components: 6.2 → 10.5 µs). The velocity gradient of a single-point query is linear
  /// theory's at z' (the terms from the stretching itself, O(k ζ) smaller, are left out).
  wheeler,
};

}  // namespace environment
}  // namespace kelp
