/// \file
/// \brief TEMPORARY STAND-IN for the T200 model of branch wip-t200 (deleted when it is merged):
/// only the signatures t200_thrust(u, V), t200_current(u, V), t200_command(F, V) matter here.
#pragma once

#include <cmath>

#include "kelp/core/scalar.hpp"
#include "kelp/vehicle/thrusters.hpp"

namespace kelp::vehicle {

/// \brief Stand-in: thrust [N] of command u at supply voltage V.
template <typename Scalar>
Scalar t200_thrust(const Scalar& u, const Scalar& voltage) {
  using std::pow;
  const Scalar f = t200_thrust(u) * pow(voltage / Scalar(16), Scalar(1.2));
  return value_of(u) < 0 ? Scalar(0.78) * f : f;
}

/// \brief Stand-in: current [A] of command u at supply voltage V.
template <typename Scalar>
Scalar t200_current(const Scalar& u, const Scalar& voltage) {
  using std::abs;
  using std::pow;
  Scalar a = abs(u);
  if (value_of(a) > 1.0) a = Scalar(1);
  return Scalar(24) * pow(a, Scalar(2.5)) * pow(voltage / Scalar(16), Scalar(2));
}

/// \brief Stand-in: inverse of t200_thrust(u, V).
template <typename Scalar>
Scalar t200_command(const Scalar& force, const Scalar& voltage) {
  using std::pow;
  const Scalar s = pow(voltage / Scalar(16), Scalar(1.2));
  return t200_command(Scalar(value_of(force) < 0 ? force / (Scalar(0.78) * s) : force / s));
}

}  // namespace kelp::vehicle
