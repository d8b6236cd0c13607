/// \file
/// \brief kelp's frames (world NED, body FRD) to ROS's (world ENU, body FLU): the one place
/// where positions, attitudes, velocities and forces change convention on their way to ROS 2.
///
/// ROS's conventions are REP 103 ("Standard Units of Measure and Coordinate Conventions": world
/// x east, y north, z up; body x forward, y left, z up) and REP 105 (a fixed world frame).
/// kelp's are Fossen's (2021, §2.1): world x north, y east, z down; body x forward, y starboard,
/// z down. Both changes are proper rotations by π:
///   - world: R_EN = [[0, 1, 0], [1, 0, 0], [0, 0, −1]] (swap x and y, negate z), a half turn
///     about the axis (1, 1, 0)/√2, quaternion (w, x, y, z) = (0, 1/√2, 1/√2, 0);
///   - body: R_FLU←FRD = diag(1, −1, −1), a half turn about x, quaternion (0, 1, 0, 0).
/// An attitude q (body FRD → NED) becomes q_ROS = q_EN ⊗ q ⊗ q_FRD←FLU (body FLU → ENU), so a
/// vehicle heading north (kelp yaw 0) has ROS yaw +π/2, and ROS yaw = π/2 − kelp yaw.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "kelp/sim/export.hpp"

namespace kelp {
namespace ros2 {

/// \brief A world vector (position [m], velocity, force [N]) from NED to ENU: (y, x, −z).
/// \param v the vector in NED (x north, y east, z down) \return it in ENU (x east, y north, z up)
inline Eigen::Vector3d ned_to_enu(const Eigen::Vector3d& v) { return {v.y(), v.x(), -v.z()}; }

/// \brief A body vector (velocity, angular velocity, force, moment, acceleration) from FRD
/// (x forward, y starboard, z down) to FLU (x forward, y left, z up): (x, −y, −z).
/// \param v the vector in FRD body axes \return it in FLU body axes
inline Eigen::Vector3d frd_to_flu(const Eigen::Vector3d& v) { return {v.x(), -v.y(), -v.z()}; }

/// \brief An attitude from kelp's (body FRD → NED) to ROS's (body FLU → ENU):
/// q_EN ⊗ q ⊗ q_FRD←FLU, with the sign chosen so that w ≥ 0 (the same rotation either way; one
/// sign keeps bags and live topics identical).
/// \param[in] q unit quaternion rotating FRD body vectors into NED (vehicle::VehicleState).
/// \return the unit quaternion rotating FLU body vectors into ENU, w ≥ 0
KELP_SIM_API Eigen::Quaterniond ned_frd_to_enu_flu(const Eigen::Quaterniond& q);

}  // namespace ros2
}  // namespace kelp
