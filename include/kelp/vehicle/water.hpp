/// \file
/// \brief One water for vehicles and environment: the check that a vehicle model's water density
/// and gravity are the environment's.
///
/// The environment (`kelp::environment::Environment`) is the single source of truth for the water.
/// A vehicle model keeps its own ρ and g (its restoring forces g(η) and buoyancy B = ρ g ∇ need
/// them at every evaluation, and a model can be built and tested without an environment), so
/// whatever combines a vehicle with an environment calls `check_same_water(model, env)` once: a
/// vehicle built for seawater in a freshwater environment is refused with an error naming both
/// densities, never simulated silently in the wrong water. Build vehicles from the environment:
/// \code
///   const auto rov = kv::bluerov2_heavy<double>(env.water_density(), env.gravity());
///   const kv::VehicleModeld model(rov.parameters);
///   kv::check_same_water(model, env);  // passes
/// \endcode
/// The system layer calls it when it assembles vehicles and an environment.
#pragma once

#include <string>

#include "kelp/core/scalar.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/vehicle/model.hpp"

namespace kelp::vehicle {

/// \brief Throws `kelp::invalid_argument` unless the vehicle parameters' `density` and `gravity`
/// are the environment's `water_density()` and `gravity()` (to 1e-6 relative).
/// \param[in] parameters the vehicle's parameters \param[in] env the environment
/// \param[in] name the vehicle's name for the message
template <typename Scalar, typename EnvScalar>
void check_same_water(const VehicleParameters<Scalar>& parameters,
                      const environment::Environment<EnvScalar>& env,
                      const std::string& name = "vehicle") {
  environment::check_same_water(value_of(parameters.density), value_of(parameters.gravity), env,
                                name);
}

/// \brief Throws `kelp::invalid_argument` unless the vehicle model was built for the
/// environment's water (density and gravity, to 1e-6 relative); the message names both values.
/// \param[in] model the vehicle model \param[in] env the environment
/// \param[in] name the vehicle's name for the message
template <typename Scalar, typename EnvScalar>
void check_same_water(const VehicleModel<Scalar>& model,
                      const environment::Environment<EnvScalar>& env,
                      const std::string& name = "vehicle") {
  check_same_water(model.parameters(), env, name);
}

}  // namespace kelp::vehicle
