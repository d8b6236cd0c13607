// A custom environment for kelp's tether (docs/custom-environment.md): still seawater in a deep
// tank with one regular wave written out by hand, elevation A cos(k x − ω t), travelling north.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <limits>

#include "kelp/core/constants.hpp"
#include "kelp/core/types.hpp"

template <typename Scalar>
struct WaveTank {
  double amplitude = 0.25;  // A [m]
  double period = 4.0;      // T [s]

  double omega() const { return 2.0 * kelp::pi / period; }
  double k() const { return omega() * omega() / kelp::standard_gravity; }  // deep water

  // The fluid and the bottom.
  Scalar water_density() const { return Scalar(kelp::seawater_density); }
  Scalar gravity() const { return Scalar(kelp::standard_gravity); }
  Scalar seabed_depth() const { return Scalar(std::numeric_limits<double>::infinity()); }

  // Free-surface elevation ζ(x, y, t) [m], positive up (the surface is at NED z = −ζ).
  Scalar surface_elevation(const Scalar& x, const Scalar& /*y*/, double t) const {
    using std::cos;
    return Scalar(amplitude) * cos(Scalar(k()) * x - Scalar(omega() * t));
  }

  // Water velocity and acceleration (NED) at the columns of `points`: the four-argument query
  // every environment has.
  void sample_water(const Eigen::Ref<const kelp::Matrix3X<Scalar>>& points, double t,
                    Eigen::Ref<kelp::Matrix3X<Scalar>> velocity,
                    Eigen::Ref<kelp::Matrix3X<Scalar>> acceleration) const {
    using std::cos;
    using std::exp;
    using std::sin;
    const Scalar a(amplitude), w(omega()), kk(k());
    for (Eigen::Index i = 0; i < points.cols(); ++i) {
      const Scalar th = kk * points(0, i) - Scalar(omega() * t);
      const Scalar zeta = a * cos(th);
      if (points(2, i) < -zeta) {  // above the free surface: no water
        velocity.col(i).setZero();
        acceleration.col(i).setZero();
        continue;
      }
      // Linear theory below the mean level; the mean level's above it (kelp's default).
      const Scalar z = points(2, i) < Scalar(0) ? Scalar(0) : Scalar(points(2, i));
      const Scalar e = exp(-kk * z);
      velocity.col(i) << a * w * e * cos(th), Scalar(0), -a * w * e * sin(th);
      acceleration.col(i) << a * w * w * e * sin(th), Scalar(0), a * w * w * e * cos(th);
    }
  }

  // The same with the elevation above each point: optional, it saves the tether one
  // surface_elevation call per node. Exactly this signature (const, these types).
  void sample_water(const Eigen::Ref<const kelp::Matrix3X<Scalar>>& points, double t,
                    Eigen::Ref<kelp::Matrix3X<Scalar>> velocity,
                    Eigen::Ref<kelp::Matrix3X<Scalar>> acceleration,
                    Eigen::Ref<kelp::VectorX<Scalar>> elevation) const {
    sample_water(points, t, velocity, acceleration);
    for (Eigen::Index i = 0; i < points.cols(); ++i)
      elevation(i) = surface_elevation(points(0, i), points(1, i), t);
  }
};
