/// \file
/// \brief Between kelp::control's controllers and a vehicle's propulsion, for the pair's closed
/// loop and a fleet's run: the commands and the voltage. Private to the kelp::sim library.
#pragma once

#include <Eigen/Core>

#include "kelp/control/controllers.hpp"
#include "kelp/vehicle/propulsion.hpp"

namespace kelp {
namespace sim {

/// \brief The vehicle's thruster commands u (PropulsionModel's) of a controller's ESC commands
/// (kelp::control's thruster chain: u_esc = u · esc_scale, the scales of the PWM mapping).
void vehicle_commands(const kelp::vehicle::PropulsionModeld& pm,
                      const Eigen::Ref<const Eigen::VectorXd>& esc,
                      kelp::vehicle::ThrusterVector<double>& u);

/// \brief The supply voltage a controller's thrust inverse uses: the battery's last measured
/// terminal voltage, or its open-circuit voltage before the first step.
double controller_voltage(const kelp::vehicle::PropulsionModeld& pm,
                          const kelp::vehicle::PropulsionStated& x);

}  // namespace sim
}  // namespace kelp

// The controllers in double precision, instantiated once in the library (closed_loop.cpp) and
// used by the pair's closed loop and a fleet's run.
extern template class kelp::control::AuvControllerT<double>;
extern template class kelp::control::AsvControllerT<double>;
