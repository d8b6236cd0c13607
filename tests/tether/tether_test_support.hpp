// Shared helpers of the tether tests: minimal environments satisfying the duck-typed interface
// of kelp::environment::Environment, and the benchmark line (docs/equations.md, section 4).
#pragma once

#include <Eigen/Core>
#include <cstring>
#include <limits>

#include "kelp/core/constants.hpp"
#include "kelp/core/types.hpp"
#include "kelp/tether/lumped_mass.hpp"

namespace kelp_test {

/// True when two matrices have the same shape and the same bits (NaN equal to itself, -0 not
/// equal to +0): the check for results that must be reproduced exactly.
template <typename M>
bool same_bits(const M& a, const M& b) {
  using S = typename M::Scalar;
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         (a.size() == 0 || std::memcmp(a.data(), b.data(), sizeof(S) * std::size_t(a.size())) == 0);
}

/// A fluid-free world (vacuum) with gravity g: no buoyancy, drag or added mass. Water density 0
/// is something kelp::environment::Environment refuses, hence this test type.
template <typename Scalar>
struct Vacuum {
  Scalar g = Scalar(kelp::standard_gravity);
  Scalar water_density() const { return Scalar(0); }
  Scalar gravity() const { return g; }
  Scalar seabed_depth() const { return Scalar(std::numeric_limits<double>::infinity()); }
  Scalar surface_elevation(Scalar, Scalar, double) const { return Scalar(0); }
  void sample_water(const Eigen::Ref<const kelp::Matrix3X<Scalar>>&, double,
                    Eigen::Ref<kelp::Matrix3X<Scalar>> velocity,
                    Eigen::Ref<kelp::Matrix3X<Scalar>> acceleration) const {
    velocity.setZero();
    acceleration.setZero();
  }
};

/// Still water with a uniform current, a uniform water acceleration, a flat surface at
/// NED z = surface_z and an optional seabed: a test double with every knob the tether reads.
template <typename Scalar>
struct TestWater {
  Scalar rho = Scalar(kelp::seawater_density);
  Scalar g = Scalar(kelp::standard_gravity);
  Scalar bed = Scalar(std::numeric_limits<double>::infinity());
  Scalar surface_z = Scalar(0);
  kelp::Vector3<Scalar> current = kelp::Vector3<Scalar>::Zero();
  kelp::Vector3<Scalar> accel = kelp::Vector3<Scalar>::Zero();
  Scalar water_density() const { return rho; }
  Scalar gravity() const { return g; }
  Scalar seabed_depth() const { return bed; }
  Scalar surface_elevation(Scalar, Scalar, double) const { return -surface_z; }
  void sample_water(const Eigen::Ref<const kelp::Matrix3X<Scalar>>& points, double,
                    Eigen::Ref<kelp::Matrix3X<Scalar>> velocity,
                    Eigen::Ref<kelp::Matrix3X<Scalar>> acceleration) const {
    for (Eigen::Index i = 0; i < points.cols(); ++i) {
      velocity.col(i) = current;
      acceleration.col(i) = accel;
    }
  }
};

/// The benchmark line (docs/equations.md, section 4): 20 m, d 8 mm, 0.07 kg/m, EA 1e5 N,
/// Cdn 1.2, Cdt 0.008, Can 1 (kelp's TetherParameters defaults) with N segments.
template <typename Scalar>
kelp::tether::TetherParameters<Scalar> benchmark_line(int segments) {
  kelp::tether::TetherParameters<Scalar> p;
  p.segments = segments;
  return p;
}

}  // namespace kelp_test
