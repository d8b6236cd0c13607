/// \file
/// \brief The 6-DOF state of a rigid marine vehicle, shared by vehicle dynamics and by the
/// system layer that attaches tethers to vehicles.
#pragma once

#include "kelp/core/rotation.hpp"
#include "kelp/core/types.hpp"

namespace kelp::vehicle {

/// \brief Vehicle state: position and attitude in NED, generalized velocity in body axes.
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
struct VehicleState {
  /// Position of the body-frame origin (CO) in NED [m].
  Vector3<Scalar> position = Vector3<Scalar>::Zero();
  /// Unit quaternion rotating body vectors into NED (Eigen's: built as (w, x, y, z), stored in
  /// `coeffs()` order x, y, z, w).
  Quaternion<Scalar> attitude = Quaternion<Scalar>::Identity();
  /// ν = (u, v, w, p, q, r): body-frame linear [m/s] and angular [rad/s] velocity.
  Vector6<Scalar> nu = Vector6<Scalar>::Zero();
  /// Simulation time [s] of this state (a double for every Scalar: one clock, which a float
  /// model does not round away). Every step advances it by its dt on success and samples the
  /// environment at it.
  double time = 0.0;

  /// \brief Rotation matrix body → NED.
  /// \return R with v_NED = R v_body.
  Matrix3<Scalar> rotation() const { return attitude.toRotationMatrix(); }

  /// \brief NED position [m] of a point given in body coordinates `r_body` [m] relative to the CO.
  /// \param r_body the point, body frame [m]. \return its position, NED [m].
  template <typename Derived>
  Vector3<Scalar> point_position(const Eigen::MatrixBase<Derived>& r_body) const {
    return position + attitude * Vector3<Scalar>(r_body);
  }

  /// \brief NED velocity [m/s] of a body-fixed point `r_body`: R (v + ω × r).
  /// \param r_body the point, body frame [m]. \return its velocity, NED [m/s].
  template <typename Derived>
  Vector3<Scalar> point_velocity(const Eigen::MatrixBase<Derived>& r_body) const {
    const Vector3<Scalar> r(r_body);
    const Vector3<Scalar> v = nu.template head<3>() + nu.template tail<3>().cross(r);
    return attitude * v;
  }
};

using VehicleStated = VehicleState<double>;  ///< \brief A double-precision vehicle state.
using VehicleStatef = VehicleState<float>;   ///< \brief A single-precision vehicle state.

/// \brief What the caller gives a vehicle for one step: wrenches held over the step
/// (zero-order hold), body axes, about the CO. Built from its fields in order (`{tau}`,
/// `{tau, tau_ext}`), each zero by default.
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
struct VehicleInputs {
  /// τ: control wrench (e.g. `ThrusterAllocation::wrench` of the thrust) [N, N m].
  Vector6<Scalar> tau = Vector6<Scalar>::Zero();
  /// τ_ext: every other external wrench (e.g. the tether's) [N, N m].
  Vector6<Scalar> tau_ext = Vector6<Scalar>::Zero();

  /// \brief Zero wrenches.
  VehicleInputs() = default;
  /// \brief The wrenches τ and τ_ext [N, N m] (a constructor rather than an aggregate, so that
  /// `{tau}` does not trip -Wmissing-field-initializers in users' builds).
  /// \param tau_ the control wrench τ, body axes about the CO [N, N m].
  /// \param tau_ext_ every other external wrench τ_ext, likewise.
  VehicleInputs(const Vector6<Scalar>& tau_,  // NOLINT(google-explicit-constructor)
                const Vector6<Scalar>& tau_ext_ = Vector6<Scalar>::Zero())
      : tau(tau_), tau_ext(tau_ext_) {}
};

using VehicleInputsd = VehicleInputs<double>;  ///< \brief Double-precision vehicle inputs.
using VehicleInputsf = VehicleInputs<float>;   ///< \brief Single-precision vehicle inputs.

}  // namespace kelp::vehicle
