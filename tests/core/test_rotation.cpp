// Properties of kelp/core/rotation.hpp: skew() is the cross product, the zyx rotation matrix agrees
// with the quaternion built from the same angles, and the kinematic maps agree with each other.
#include <catch2/catch.hpp>
#include <random>

#include "kelp/core/rotation.hpp"

using kelp::Matrix3;
using kelp::Vector3;

TEMPLATE_TEST_CASE("skew(a) b equals a x b and skew is antisymmetric", "[core]", double, float) {
  using S = TestType;
  std::mt19937 rng(7);
  std::uniform_real_distribution<S> u(-2, 2);
  for (int k = 0; k < 100; ++k) {
    const Vector3<S> a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
    const Matrix3<S> Sa = kelp::skew(a);
    CHECK((Sa * b - a.cross(b)).norm() <= S(1e-5));
    CHECK((Sa + Sa.transpose()).norm() == S(0));
  }
}

TEST_CASE("rotation_zyx matches the quaternion and round-trips Euler angles", "[core]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> ang(-3.0, 3.0), pitch(-1.5, 1.5);
  for (int k = 0; k < 200; ++k) {
    const double phi = ang(rng), theta = pitch(rng), psi = ang(rng);
    const Matrix3<double> R = kelp::rotation_zyx(phi, theta, psi);
    const auto q = kelp::quaternion_from_euler(phi, theta, psi);
    CHECK((R - q.toRotationMatrix()).norm() < 1e-12);
    CHECK((R.transpose() * R - Matrix3<double>::Identity()).norm() < 1e-12);
    CHECK(R.determinant() == Approx(1.0).epsilon(1e-12));
    const Vector3<double> e = kelp::euler_from_quaternion(q);
    CHECK(e(0) == Approx(phi).margin(1e-9));
    CHECK(e(1) == Approx(theta).margin(1e-9));
    CHECK(e(2) == Approx(psi).margin(1e-9));
  }
}

TEST_CASE("Euler-rate and quaternion-rate kinematics describe the same motion", "[core]") {
  // Integrate the attitude of a body spinning with a constant ω both ways (small steps, RK-free
  // Euler with renormalisation is enough at dt = 1e-5 over 0.2 s) and compare the final rotations.
  const Vector3<double> w(0.3, -0.2, 0.5);
  double phi = 0.1, theta = -0.2, psi = 0.3;
  auto q = kelp::quaternion_from_euler(phi, theta, psi);
  const double dt = 1e-5;
  for (int k = 0; k < 20000; ++k) {
    const Vector3<double> de = kelp::euler_rate_matrix(phi, theta) * w;
    phi += dt * de(0);
    theta += dt * de(1);
    psi += dt * de(2);
    const auto dq = kelp::quaternion_rate(q, w);
    q.coeffs() += dt * dq;  // (ẋ, ẏ, ż, ẇ): Eigen's coeffs() order
    q.normalize();
  }
  CHECK((kelp::rotation_zyx(phi, theta, psi) - q.toRotationMatrix()).norm() < 1e-4);
}

TEST_CASE("kinematics_euler: a yawed body moving forward moves along its heading", "[core]") {
  const double psi = 0.5;
  const auto J = kelp::kinematics_euler(0.0, 0.0, psi);
  kelp::Vector6<double> nu;
  nu << 2.0, 0, 0, 0, 0, 0.1;
  const kelp::Vector6<double> eta_dot = J * nu;
  CHECK(eta_dot(0) == Approx(2.0 * std::cos(psi)));
  CHECK(eta_dot(1) == Approx(2.0 * std::sin(psi)));
  CHECK(eta_dot(5) == Approx(0.1));
}
