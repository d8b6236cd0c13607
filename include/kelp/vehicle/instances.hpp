/// \file
/// \brief KELP_VEHICLE_INSTANCES(prefix): the double-precision vehicle code that costs most to
/// compile (a model's validation and mass-matrix factorisation, the thruster allocation's
/// pseudo-inverse, the RK4 steps), listed once for explicit instantiation. A program that
/// compiles `KELP_VEHICLE_INSTANCES(template)` in one translation unit and
/// `KELP_VEHICLE_INSTANCES(extern template)` in the others compiles this code once (Pinocchio's
/// explicit-instantiation pattern). kelp::sim does so for its consumers
/// (kelp/sim/instantiation.hpp); a header-only program needs neither.
#pragma once

#include <Eigen/Core>

#include "kelp/environment/environment.hpp"
#include "kelp/vehicle/integrators.hpp"
#include "kelp/vehicle/model.hpp"
#include "kelp/vehicle/thrusters.hpp"

/// \brief Declares (`extern template`) or defines (`template`) the double-precision instances of
/// `validate(VehicleParameters)`, the VehicleModel constructor, the thruster allocation's
/// pseudo-inverse and `step_rk4` (in a uniform current, in still water, in an Environment).
/// \param prefix `template` or `extern template`, optionally followed by an export attribute.
#define KELP_VEHICLE_INSTANCES(prefix)                                                             \
  prefix void kelp::vehicle::validate<double>(const kelp::vehicle::VehicleParameters<double>&);    \
  prefix kelp::vehicle::VehicleModel<double>::VehicleModel(                                        \
      const kelp::vehicle::VehicleParameters<double>&);                                            \
  prefix Eigen::Index kelp::vehicle::detail::pseudo_inverse<double>(                               \
      const Eigen::Matrix<double, 6, Eigen::Dynamic>&, Eigen::Matrix<double, Eigen::Dynamic, 6>&); \
  prefix void kelp::vehicle::step_rk4<double, Eigen::Matrix<double, 3, 1>>(                        \
      const kelp::vehicle::VehicleModel<double>&, kelp::vehicle::VehicleWorkspace<double>&,        \
      kelp::vehicle::VehicleState<double>&, const kelp::vehicle::VehicleInputs<double>&, double,   \
      const Eigen::MatrixBase<Eigen::Matrix<double, 3, 1>>&);                                      \
  prefix void kelp::vehicle::step_rk4<double>(                                                     \
      const kelp::vehicle::VehicleModel<double>&, kelp::vehicle::VehicleWorkspace<double>&,        \
      kelp::vehicle::VehicleState<double>&, const kelp::vehicle::VehicleInputs<double>&, double);  \
  prefix void kelp::vehicle::step_rk4<double, kelp::environment::Environment<double>>(             \
      const kelp::vehicle::VehicleModel<double>&, kelp::vehicle::VehicleWorkspace<double>&,        \
      const kelp::environment::Environment<double>&, kelp::vehicle::VehicleState<double>&,         \
      const kelp::vehicle::VehicleInputs<double>&, double);
