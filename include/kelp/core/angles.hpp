/// \file
/// \brief Angle wrapping and the heading of an attitude: the one copy every physics header uses.
///
/// Two wraps to (−π, π], which agree except in the last bits (they are not interchangeable where
/// outputs must stay bit for bit what they were):
/// - `wrap_angle`: fmod(a + π, 2π) − π, the controllers' and the navigation filter's convention
///   (kelp::control::wrap_angle is this function). The sum a + π rounds, so e.g. 1e-20 wraps to
///   0, and 0.1 to 0.1 within an ulp of π.
/// - `wrap_angle_exact`: std::remainder, exact (a − 2πk with no rounding beyond that of the
///   constant 2π), the convention of the tether's winding angle (kelp/tether/winding.hpp).
#pragma once

#include <cmath>

#include "kelp/core/constants.hpp"
#include "kelp/core/rotation.hpp"
#include "kelp/core/types.hpp"

namespace kelp {

/// \brief Angle `a` [rad] wrapped to (−π, π] exactly: a − 2πk by std::remainder, then −π moved
/// to π (see the file comment for how it differs from wrap_angle). NaN and ±∞ give NaN.
/// \tparam Scalar float or double.
/// \param a any angle [rad].
/// \return the angle in (−π, π] [rad]; never throws.
template <typename Scalar>
Scalar wrap_angle_exact(Scalar a) {
  using std::remainder;
  const Scalar two_pi = Scalar(2.0 * kelp::pi);
  a = remainder(a, two_pi);
  return a <= -Scalar(kelp::pi) ? a + two_pi : a;
}

/// \brief Angle `a` [rad] wrapped to (−π, π] as fmod(a + π, 2π) − π (the controllers'
/// convention; see the file comment for how it differs from wrap_angle_exact). NaN and ±∞ give
/// NaN.
/// \tparam Scalar float or double.
/// \param a any angle [rad].
/// \return the angle in (−π, π] [rad]; never throws.
template <typename Scalar>
Scalar wrap_angle(Scalar a) {
  using std::fmod;
  const Scalar half_turn = Scalar(kelp::pi), two_pi = Scalar(2.0 * kelp::pi);
  a = fmod(a + half_turn, two_pi);
  if (a <= Scalar(0)) a += two_pi;
  return a - half_turn;
}

/// \brief Heading ψ [rad] of an attitude (body → NED): the yaw of its ZYX Euler angles
/// (euler_from_quaternion(q).z()), in [−π, π].
/// \tparam Scalar float, double or ceres::Jet.
/// \param q a unit quaternion rotating body vectors into NED.
/// \return ψ [rad], positive clockwise seen from above (north 0, east π/2).
template <typename Scalar>
Scalar heading_of(const Quaternion<Scalar>& q) {
  return euler_from_quaternion(q).z();
}

}  // namespace kelp
