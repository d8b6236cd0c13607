/// \file
/// \brief The navigation estimate a vehicle's controllers see (what a vehicle knows of itself):
/// produced by kelp::nav (NavigationFilter, or navigation_of for a perfect one), consumed by
/// kelp::control. Everything here is a template on the scalar, so including it instantiates
/// nothing.
#pragma once

#include "kelp/core/types.hpp"
#include "kelp/vehicle/state.hpp"

namespace kelp::nav {

/// \brief What a vehicle knows of itself.
/// \tparam Scalar double or float.
template <typename Scalar>
struct NavigationT {
  Vector3<Scalar> position = Vector3<Scalar>::Zero();            ///< NED [m]
  Quaternion<Scalar> attitude = Quaternion<Scalar>::Identity();  ///< body → NED
  Vector6<Scalar> nu = Vector6<Scalar>::Zero();  ///< body velocity over ground [m/s, rad/s]
};

/// \brief The estimate in double precision (what the controllers take by default).
using Navigation = NavigationT<double>;

/// \brief A perfect navigation solution from a simulated state.
/// \tparam Scalar double or float.
/// \param x The simulated (true) vehicle state.
/// \return Its position, attitude and body velocity, without error.
template <typename Scalar>
NavigationT<Scalar> navigation_of(const vehicle::VehicleState<Scalar>& x) {
  return {x.position, x.attitude, x.nu};
}

}  // namespace kelp::nav
