/// \file
/// \brief The environment facade: one object that vehicles and tether nodes query for the water
/// current, the wave orbital kinematics, the free-surface elevation and the wind.
///
/// Frames and signs: world NED (x north, y east, z down, mean sea surface at z = 0). The surface
/// elevation ζ is positive UP, so the free surface lies at NED z = −ζ. Units SI.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <limits>

#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"

namespace kelp {
namespace environment {

/// \brief Everything the environment knows at one point and time.
/// \tparam Scalar double, float or an automatic-differentiation type.
template <typename Scalar>
struct EnvironmentSample {
  /// Water current velocity, NED [m/s]. Above the free surface the value at the surface is
  /// returned, so a hull reference point slightly above the waterline still sees the current.
  Vector3<Scalar> current = Vector3<Scalar>::Zero();
  /// Wave orbital velocity, NED [m/s] (zero above the free surface and in a calm sea).
  Vector3<Scalar> wave_velocity = Vector3<Scalar>::Zero();
  /// Wave orbital acceleration, NED [m/s²].
  Vector3<Scalar> wave_acceleration = Vector3<Scalar>::Zero();
  /// Free-surface elevation ζ above the mean level at the point's (x, y) [m], positive UP.
  Scalar surface_elevation = Scalar(0);
  /// Wind velocity at 10 m above the sea (the direction the air moves towards), NED [m/s].
  Vector3<Scalar> wind = Vector3<Scalar>::Zero();
};

/// \brief The sea a simulation runs in: fluid constants, seabed, current, waves and wind.
///
/// A default-constructed environment is still water (`calm()`): seawater of 1025 kg/m³, air of
/// 1.225 kg/m³, g = kelp::standard_gravity, no seabed, no current, no waves, no wind.
/// All queries are `const` and allocate nothing.
/// \tparam Scalar double, float or an automatic-differentiation type.
template <typename Scalar>
class Environment {
 public:
  /// \brief Still water (same as `calm()`).
  Environment() = default;

  /// \brief Still water: no current, no waves, no wind, seawater, standard gravity, no seabed.
  static Environment calm() { return Environment(); }

  /// \brief Water density ρ [kg/m³].
  Scalar water_density() const { return water_density_; }
  /// \brief Air density ρ_air [kg/m³].
  Scalar air_density() const { return air_density_; }
  /// \brief Gravitational acceleration g [m/s²].
  Scalar gravity() const { return gravity_; }
  /// \brief NED z of a flat seabed [m] (> 0); +infinity when there is none.
  Scalar seabed_depth() const { return seabed_depth_; }

  /// \brief Sets the water density [kg/m³] (> 0). \throws kelp::invalid_argument naming
  /// `water_density`.
  Environment& set_water_density(Scalar rho) {
    check_positive(rho, "water_density");
    water_density_ = rho;
    return *this;
  }
  /// \brief Sets the air density [kg/m³] (> 0). \throws kelp::invalid_argument naming
  /// `air_density`.
  Environment& set_air_density(Scalar rho) {
    check_positive(rho, "air_density");
    air_density_ = rho;
    return *this;
  }
  /// \brief Sets the gravitational acceleration [m/s²] (> 0). \throws kelp::invalid_argument
  /// naming `gravity`.
  Environment& set_gravity(Scalar g) {
    check_positive(g, "gravity");
    gravity_ = g;
    return *this;
  }
  /// \brief Sets the NED z of a flat seabed [m] (> 0, or +infinity for none).
  /// \throws kelp::invalid_argument naming `seabed_depth`.
  Environment& set_seabed_depth(Scalar depth) {
    KELP_CHECK(!std::isnan(value_of(depth)) && value_of(depth) > 0.0,
               "seabed_depth must be > 0 (or +infinity for no seabed)");
    seabed_depth_ = depth;
    return *this;
  }
  /// \brief Sets a constant, depth-uniform current velocity, NED [m/s].
  /// \throws kelp::invalid_argument naming `current` when not finite.
  template <typename Derived>
  Environment& set_current(const Eigen::MatrixBase<Derived>& v_ned) {
    check_all_finite(v_ned, "current");
    current_ = v_ned.template cast<Scalar>();
    return *this;
  }

  /// \brief Everything at NED point `p_ned` and time `t` [s].
  EnvironmentSample<Scalar> sample(const Vector3<Scalar>& p_ned, Scalar t) const {
    (void)p_ned;
    (void)t;
    EnvironmentSample<Scalar> s;
    s.current = current_;
    return s;
  }

  /// \brief Free-surface elevation ζ(x, y, t) [m], positive up.
  Scalar surface_elevation(Scalar x, Scalar y, Scalar t) const {
    (void)x;
    (void)y;
    (void)t;
    return Scalar(0);
  }

  /// \brief Water velocity and acceleration at many NED points at once (e.g. all tether nodes);
  /// no heap allocation.
  ///
  /// `velocity.col(i)` = current + wave orbital velocity at `points.col(i)`;
  /// `acceleration.col(i)` = wave orbital acceleration there (no wave part above the free
  /// surface; the current there is the surface current). \param[in] points 3×n NED positions [m]
  /// \param[in] t time [s] \param[out] velocity 3×n [m/s] \param[out] acceleration 3×n [m/s²]
  void sample_water(const Eigen::Ref<const Matrix3X<Scalar>>& points, Scalar t,
                    Eigen::Ref<Matrix3X<Scalar>> velocity,
                    Eigen::Ref<Matrix3X<Scalar>> acceleration) const {
    (void)t;
    KELP_CHECK(velocity.cols() == points.cols() && acceleration.cols() == points.cols(),
               "sample_water: velocity and acceleration must have as many columns as points");
    for (Eigen::Index i = 0; i < points.cols(); ++i) velocity.col(i) = current_;
    acceleration.setZero();
  }

 private:
  Scalar water_density_ = Scalar(kelp::seawater_density);
  Scalar air_density_ = Scalar(kelp::air_density);
  Scalar gravity_ = Scalar(kelp::standard_gravity);
  Scalar seabed_depth_ = Scalar(std::numeric_limits<double>::infinity());
  Vector3<Scalar> current_ = Vector3<Scalar>::Zero();
};

/// \brief Double-precision environment.
using Environmentd = Environment<double>;
/// \brief Single-precision environment.
using Environmentf = Environment<float>;

}  // namespace environment
}  // namespace kelp
