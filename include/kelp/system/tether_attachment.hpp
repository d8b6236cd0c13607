/// \file
/// \brief Attaching the ends of a lumped-mass tether to points on vehicles: the end motion from a
/// vehicle state, and the tether force turned into a body-frame wrench the vehicle dynamics can
/// take. `vehicle` and `tether` do not include each other; they meet here, in `system/`.
///
/// Frames: world NED; body x forward, y starboard, z down. A point r_b fixed in the body moves
/// with p = p_CO + R r_b, ṗ = R (v + ω × r_b) (Fossen 2021, eq. 2.106 form).
#pragma once

#include <Eigen/Core>

#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/tether/lumped_mass.hpp"
#include "kelp/vehicle/integrators.hpp"
#include "kelp/vehicle/state.hpp"

namespace kelp::system {

namespace detail {
/// attachment_motion without the checks (the system's own, already checked, states).
template <typename Scalar, typename Derived>
tether::EndMotion<Scalar> motion_of_point(const vehicle::VehicleState<Scalar>& vehicle,
                                          const Eigen::MatrixBase<Derived>& r_body) {
  tether::EndMotion<Scalar> m;
  m.position = vehicle.point_position(r_body);
  m.velocity = vehicle.point_velocity(r_body);
  return m;
}

/// attachment_wrench without the checks (RK4 stages, whose attitude is not exactly unit).
template <typename Scalar, typename D1, typename D2>
Vector6<Scalar> wrench_of_force(const vehicle::VehicleState<Scalar>& vehicle,
                                const Eigen::MatrixBase<D1>& r_body,
                                const Eigen::MatrixBase<D2>& force_ned) {
  const Vector3<Scalar> f_body = vehicle.attitude.conjugate() * Vector3<Scalar>(force_ned);
  Vector6<Scalar> tau;
  tau.template head<3>() = f_body;
  tau.template tail<3>() = Vector3<Scalar>(r_body).cross(f_body);
  return tau;
}
}  // namespace detail

/// \brief NED motion of the body-fixed point `r_body` [m] of a vehicle, as a tether end motion:
/// position p_CO + R r_b, velocity R (v + ω × r_b). The acceleration is left zero: a VehicleState
/// carries no ν̇ (pass one through `EndMotion::acceleration` if the caller has it).
/// \tparam Scalar double or float. \param[in] vehicle state \param[in] r_body point, body frame [m]
/// \throws kelp::invalid_argument for a non-finite r_body or vehicle state, or a non-unit attitude.
/// \return the point's position [m] and velocity [m/s], NED; acceleration zero.
template <typename Scalar, typename Derived>
tether::EndMotion<Scalar> attachment_motion(const vehicle::VehicleState<Scalar>& vehicle,
                                            const Eigen::MatrixBase<Derived>& r_body) {
  ::kelp::vehicle::detail::check_state(vehicle);
  check_all_finite(r_body, "r_body");
  return detail::motion_of_point(vehicle, r_body);
}

/// \brief Body-frame generalized force τ = (Rᵀ f, r_b × Rᵀ f) on a vehicle from an NED force
/// `force_ned` [N] applied at the body-fixed point `r_body` [m] (Fossen 2021, eq. 2.122 form:
/// moment about the CO). Add it to the vehicle's τ.
/// \throws kelp::invalid_argument for a non-finite r_body, force or vehicle state, or a non-unit
/// attitude.
/// \param[in] vehicle the vehicle's state. \param[in] r_body the point, body frame [m].
/// \param[in] force_ned the force on the vehicle at that point, NED [N].
/// \return τ [N, N m], body axes, moment about the CO.
template <typename Scalar, typename D1, typename D2>
Vector6<Scalar> attachment_wrench(const vehicle::VehicleState<Scalar>& vehicle,
                                  const Eigen::MatrixBase<D1>& r_body,
                                  const Eigen::MatrixBase<D2>& force_ned) {
  ::kelp::vehicle::detail::check_state(vehicle);
  check_all_finite(r_body, "r_body");
  check_all_finite(force_ned, "force_ned");
  return detail::wrench_of_force(vehicle, r_body, force_ned);
}

/// \brief Boundary of a tether whose start end is at `r_start_body` on `start` (e.g. the ASV) and
/// whose far end is at `r_end_body` on `end` (e.g. the AUV).
/// \param[in] start the start end's vehicle state. \param[in] r_start_body its attachment point,
/// body frame [m]. \param[in] end the far end's vehicle state. \param[in] r_end_body its
/// attachment point, body frame [m].
/// \return both ends' motions (NED positions [m] and velocities [m/s]), as attachment_motion.
/// \throws kelp::invalid_argument as attachment_motion.
template <typename Scalar, typename D1, typename D2>
tether::TetherBoundary<Scalar> tether_boundary(const vehicle::VehicleState<Scalar>& start,
                                               const Eigen::MatrixBase<D1>& r_start_body,
                                               const vehicle::VehicleState<Scalar>& end,
                                               const Eigen::MatrixBase<D2>& r_end_body) {
  tether::TetherBoundary<Scalar> b;
  b.start = attachment_motion(start, r_start_body);
  b.end = attachment_motion(end, r_end_body);
  return b;
}

}  // namespace kelp::system
