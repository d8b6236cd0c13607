/// \file
/// \brief What a vehicle senses of the sea at its own position: water velocity and acceleration
/// (current with its depth profile and time variation, plus wave orbital motion), the free
/// surface (elevation and slope) and the wind, sampled from an environment at a time t.
///
/// Frames: NED (x north, y east, z down); the elevation ζ is positive UP, so the free surface lies
/// at NED z = −ζ. Units SI. Time is a `double` for every Scalar (one clock).
#pragma once

#include <Eigen/Core>
#include <type_traits>
#include <utility>

#include "kelp/core/constants.hpp"
#include "kelp/core/types.hpp"
#include "kelp/vehicle/state.hpp"

namespace kelp::vehicle {

/// \brief What a vehicle senses of its surroundings at one instant, NED.
/// A default-constructed value is still water with no wind and a flat surface at z = 0.
/// \tparam Scalar double, float or ceres::Jet.
template <typename Scalar>
struct Surroundings {
  /// Current + wave orbital velocity at the vehicle's CO, NED [m/s].
  Vector3<Scalar> water_velocity = Vector3<Scalar>::Zero();
  /// Water acceleration at the CO: the waves' material acceleration ∂v/∂t + (v·∇)v, NED [m/s²].
  Vector3<Scalar> water_acceleration = Vector3<Scalar>::Zero();
  /// ζ at the CO's (x, y) [m], positive up; the surface is at NED z = −ζ.
  Scalar surface_elevation = Scalar(0);
  /// (∂ζ/∂x, ∂ζ/∂y) [-] at the CO's (x, y): rise of the surface per metre north and east.
  Eigen::Matrix<Scalar, 2, 1> surface_slope = Eigen::Matrix<Scalar, 2, 1>::Zero();
  /// Wind (air motion) at 10 m above the sea, or the environment's reference height, NED [m/s].
  Vector3<Scalar> wind_velocity = Vector3<Scalar>::Zero();
  /// Air density ρ_air [kg/m³] of the environment (one air, as there is one water): the wind
  /// load reads it. Default: kelp::air_density (1.225 kg/m³, ISA sea level).
  Scalar air_density = Scalar(kelp::air_density);
};

namespace detail {

template <typename Sample, typename = void>
struct has_velocity_gradient : std::false_type {};
template <typename Sample>
struct has_velocity_gradient<
    Sample, std::void_t<decltype(std::declval<const Sample&>().wave_velocity_gradient)>>
    : std::true_type {};

/// The water's material acceleration Dv/Dt = ∂v/∂t + (v·∇)v of the waves in an environment
/// sample (∂v/∂t alone when the sample has no velocity gradient). The current's advection of the
/// wave field is left out: the waves are defined in the earth frame.
template <typename Scalar, typename Sample>
Vector3<Scalar> material_acceleration(const Sample& e) {
  if constexpr (has_velocity_gradient<Sample>::value)
    return e.wave_acceleration + e.wave_velocity_gradient * e.wave_velocity;
  else
    return e.wave_acceleration;
}

template <typename Env, typename P, typename = void>
struct has_windless_sample : std::false_type {};
template <typename Env, typename P>
struct has_windless_sample<
    Env, P,
    std::void_t<decltype(std::declval<const Env&>().sample(std::declval<const P&>(), 0.0, false))>>
    : std::true_type {};

template <typename Env, typename = void>
struct has_air_density : std::false_type {};
template <typename Env>
struct has_air_density<Env, std::void_t<decltype(std::declval<const Env&>().air_density())>>
    : std::true_type {};

template <typename Sample, typename = void>
struct has_surface_slope : std::false_type {};
template <typename Sample>
struct has_surface_slope<Sample, std::void_t<decltype(std::declval<const Sample&>().surface_slope)>>
    : std::true_type {};

template <typename Env, typename P, typename = void>
struct has_unchecked_sample : std::false_type {};
template <typename Env, typename P>
struct has_unchecked_sample<Env, P,
                            std::void_t<decltype(std::declval<const Env&>().sample_unchecked(
                                std::declval<const P&>(), 0.0, false))>> : std::true_type {};

/// env.sample(p, t), told to skip the wind when it can be (`sample(p, t, false)`), without the
/// check of the point when the environment has one to skip (`sample_unchecked(p, t, wind)`, as
/// Environment has): a stage state that has blown up to NaN must end the step as its
/// numerical_error, not as an invalid_argument from the environment.
template <typename Env, typename P>
auto sample(const Env& env, const P& p, double t, bool wind) {
  if constexpr (has_unchecked_sample<Env, P>::value)
    return env.sample_unchecked(p, t, wind);
  else if constexpr (has_windless_sample<Env, P>::value)
    return env.sample(p, t, wind);
  else
    return env.sample(p, t);
}

/// The surroundings at the CO, with or without the slope and the wind.
template <typename Scalar, typename Env>
Surroundings<Scalar> sample_surroundings(const Env& env, const VehicleState<Scalar>& x, double t,
                                         bool slope, bool wind) {
  Surroundings<Scalar> s;
  const auto e = detail::sample(env, x.position, t, wind);
  s.water_velocity = e.current + e.wave_velocity;
  s.water_acceleration = detail::material_acceleration<Scalar>(e);
  s.surface_elevation = e.surface_elevation;
  if (slope) {
    // From the sample when it carries the slope (Environment's does, from the same sines).
    if constexpr (has_surface_slope<std::decay_t<decltype(e)>>::value)
      s.surface_slope = e.surface_slope;
    else
      s.surface_slope = env.surface_slope(x.position(0), x.position(1), t);
  }
  if (wind) s.wind_velocity = e.wind;
  if constexpr (has_air_density<Env>::value) s.air_density = Scalar(env.air_density());
  return s;
}

}  // namespace detail

/// \brief Samples `env` at the vehicle's CO at time t (no allocation): `env.sample(p, t)` gives
/// current, wave orbital velocity and acceleration, elevation and wind, and the slope when its
/// sample has a `surface_slope` (else `env.surface_slope(x, y, t)` gives it), and the air
/// density when `env.air_density()` exists (else kelp::air_density). `Env` is
/// `kelp::environment::Environment` or any type with those two queries. The water acceleration is
/// the material one, ∂v/∂t + (v·∇)v, when the sample carries the wave velocity gradient (as
/// Environment's does). The steps call it at every stage, so the position is not checked here
/// (Environment::sample_unchecked when the environment has it): a NaN position gives NaN
/// surroundings, which forward_dynamics() refuses and a step reports as numerical_error.
/// \param[in] env environment \param[in] x vehicle state (its CO position is used)
/// \param[in] t time [s]
/// \return Water velocity and material acceleration (NED), surface elevation and slope, wind
/// and air density at the CO.
template <typename Scalar, typename Env>
Surroundings<Scalar> surroundings(const Env& env, const VehicleState<Scalar>& x, double t) {
  return detail::sample_surroundings(env, x, t, true, true);
}

/// \brief Replaces the water velocity and acceleration of `s` by those at depth `z` [m, NED]
/// under the vehicle's CO (x, y), keeping the surface and the wind.
/// \param[in] env environment \param[in] x vehicle state (its CO's north and east are used)
/// \param[in] t time [s] \param[in] z NED depth of the sample [m]
/// \param[in,out] s surroundings whose water velocity and acceleration are replaced
template <typename Scalar, typename Env>
void resample_water(const Env& env, const VehicleState<Scalar>& x, double t, const Scalar& z,
                    Surroundings<Scalar>& s) {
  const auto e = detail::sample(env, Vector3<Scalar>(x.position(0), x.position(1), z), t, false);
  s.water_velocity = e.current + e.wave_velocity;
  s.water_acceleration = detail::material_acceleration<Scalar>(e);
}

}  // namespace kelp::vehicle
