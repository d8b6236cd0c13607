// Damping (kelp/vehicle/damping.hpp) and restoring (kelp/vehicle/restoring.hpp): dissipation at
// every speed, hand-computed restoring vectors, neutral / heavy / righting behaviour, agreement of
// the Euler and rotation-matrix forms and the quaternion form at 90° pitch.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "kelp/core/rotation.hpp"
#include "kelp/vehicle/damping.hpp"
#include "kelp/vehicle/integrators.hpp"
#include "kelp/vehicle/model.hpp"
#include "kelp/vehicle/presets.hpp"
#include "kelp/vehicle/restoring.hpp"

using kelp::Matrix3;
using kelp::Matrix6;
using kelp::Vector3;
using kelp::Vector6;
namespace kv = kelp::vehicle;

TEMPLATE_TEST_CASE("nu^T D(nu) nu > 0 for nu != 0, including sub-unit speeds", "[vehicle][damping]",
                   double, float) {
  using S = TestType;
  // BlueROV2 Heavy has zero linear damping in sway, roll and yaw: only the quadratic terms
  // dissipate there, which is where a ν² (instead of |ν|ν) bug would show at sub-unit speeds.
  const auto d = kv::bluerov2_heavy<S>().parameters.damping;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (double scale : {1e-3, 1e-2, 0.1, 0.5, 1.0, 3.0}) {
    for (int k = 0; k < 100; ++k) {
      Vector6<S> nu;
      for (int i = 0; i < 6; ++i) nu(i) = S(scale * u(rng));
      const Matrix6<S> D = kv::damping_matrix(d, nu);
      CHECK(nu.dot(D * nu) > S(0));
      CHECK(nu.dot(kv::damping_force(d, nu)) > S(0));
      CHECK((kv::damping_force(d, nu) - D * nu).norm() <= S(1e-5) * (D * nu).norm());
    }
    // Pure sway, roll or yaw (no linear term) still dissipates.
    for (int i : {1, 3, 5}) {
      Vector6<S> nu = Vector6<S>::Zero();
      nu(i) = S(-0.5 * scale);
      CHECK(nu.dot(kv::damping_force(d, nu)) > S(0));
    }
  }
}

TEST_CASE("damping force has the hand-computed value", "[vehicle][damping]") {
  // BlueROV2 Heavy surge: 13.7 u + 141 u|u| at u = -0.5: -6.85 - 35.25 = -42.1 N.
  const auto d = kv::bluerov2_heavy<double>().parameters.damping;
  Vector6<double> nu = Vector6<double>::Zero();
  nu(0) = -0.5;
  CHECK(kv::damping_force(d, nu)(0) == Approx(-42.1));
  CHECK(kv::damping_matrix(d, nu)(0, 0) == Approx(13.7 + 141 * 0.5));
}

TEST_CASE("restoring vector has hand-computed values", "[vehicle][restoring]") {
  // W = 100 N, B = 90 N, r_g = (0, 0, 0.05), r_b = (0, 0, -0.01).
  // (a) Pitched nose up θ = 30°: gravity along body is Rᵀ e_z = (-sin θ, 0, cos θ), so
  //     g = -(f_g + f_b) = (W - B)(sin θ, 0, -cos θ) = (5, 0, -8.660254) and the pitch component
  //     -(r_g × W d + r_b × (-B) d)_y = (z_g W - z_b B) sin θ = (5 + 0.9) · 0.5 = 2.95 N m.
  // (b) Rolled φ = 90°: d = (0, 1, 0): g = (0, -10, 0, 5.9, 0, 0) by the same cross products.
  const double W = 100, B = 90;
  const Vector3<double> rg(0, 0, 0.05), rb(0, 0, -0.01);
  const double pi = kelp::pi;
  Vector6<double> a, b;
  a << 5, 0, -8.660254037844387, 0, 2.95, 0;
  b << 0, -10, 0, 5.9, 0, 0;
  const Vector6<double> ga =
      kv::restoring_force(W, B, rg, rb, kelp::rotation_zyx(0.0, pi / 6, 0.7));
  const Vector6<double> gb =
      kv::restoring_force(W, B, rg, rb, kelp::rotation_zyx(pi / 2, 0.0, -1.2));
  CHECK((ga - a).norm() < 1e-12);
  CHECK((gb - b).norm() < 1e-12);
  CHECK((kv::restoring_force_euler(W, B, rg, rb, 0.0, pi / 6) - a).norm() < 1e-12);
  CHECK((kv::restoring_force_euler(W, B, rg, rb, pi / 2, 0.0) - b).norm() < 1e-12);
  // The moments right the vehicle: -g opposes the tilt.
  CHECK(-ga(4) < 0);
  CHECK(-gb(3) < 0);
}

TEMPLATE_TEST_CASE("restoring: neutral buoyancy with r_g = r_b gives zero at any attitude",
                   "[vehicle][restoring]", double, float) {
  using S = TestType;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> ang(-3.1, 3.1);
  const Vector3<S> r(S(0.01), S(-0.02), S(0.03));
  for (int k = 0; k < 100; ++k) {
    const kelp::Quaternion<S> q =
        kelp::quaternion_from_euler(S(ang(rng)), S(ang(rng) / 2), S(ang(rng)));
    const Vector6<S> g = kv::restoring_force(S(120), S(120), r, r, q.toRotationMatrix());
    CHECK(g.norm() <= S(1e-4));
  }
}

TEMPLATE_TEST_CASE("restoring: Euler and quaternion forms agree away from the singularity",
                   "[vehicle][restoring]", double, float) {
  using S = TestType;
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> ang(-3.1, 3.1), pitch(-1.4, 1.4);
  const Vector3<S> rg(S(0.02), S(0.01), S(0.04)), rb(S(-0.01), S(0.0), S(-0.02));
  for (int k = 0; k < 200; ++k) {
    const S phi = S(ang(rng)), theta = S(pitch(rng)), psi = S(ang(rng));
    const auto q = kelp::quaternion_from_euler(phi, theta, psi);
    const Vector6<S> gq = kv::restoring_force(S(130), S(125), rg, rb, q.toRotationMatrix());
    const Vector6<S> ge = kv::restoring_force_euler(S(130), S(125), rg, rb, phi, theta);
    CHECK((gq - ge).norm() <= S(1e-4) * S(130));
  }
}

TEST_CASE("restoring: the quaternion form is fine at 90 degrees pitch", "[vehicle][restoring]") {
  // Nose straight up (θ = 90°): body x points to -z (up), so gravity along body is (-1, 0, 0):
  // g = (W - B, 0, 0, 0, z_g W - z_b B, 0) whatever the roll and yaw (a gimbal-locked case).
  const double W = 100, B = 90;
  const Vector3<double> rg(0, 0, 0.05), rb(0, 0, -0.01);
  for (double phi : {0.0, 0.3, -1.0}) {
    const auto q = kelp::quaternion_from_euler(phi, kelp::pi / 2, 0.2);
    const Vector6<double> g = kv::restoring_force(W, B, rg, rb, q.toRotationMatrix());
    CHECK(g.allFinite());
    Vector6<double> expected;
    // Rolling about the vertical body x axis at θ = 90° is a yaw in NED, so the expected vector
    // does not depend on φ.
    expected << 10, 0, 0, 0, 5.9, 0;
    CHECK((g - expected).norm() < 1e-12);
  }
}

TEMPLATE_TEST_CASE("a heavy vehicle sinks, a buoyant one rises", "[vehicle][restoring]", double,
                   float) {
  using S = TestType;
  auto p = kv::bluerov2_heavy<S>().parameters;
  p.hydrostatics = kv::Hydrostatics::submerged;  // deep water: the test starts at z = 0
  const S neutral_volume = p.mass / p.density;
  for (double factor : {0.98, 1.02}) {
    p.displaced_volume = S(factor) * neutral_volume;
    const kv::VehicleModel<S> model(p);
    kv::VehicleWorkspace<S> ws;
    kv::VehicleState<S> x;
    const Vector6<S> zero = Vector6<S>::Zero();
    const Vector6<S> a = kv::forward_dynamics(model, ws, x, zero, zero);
    // Initial acceleration (W - B)/(m + A_33) downward (NED +z) for a heavy vehicle.
    const S expected = (model.weight() - model.buoyancy()) / (p.mass + p.added_mass(2, 2));
    CHECK(a(2) == Approx(expected).epsilon(1e-4));
    for (int k = 0; k < 500; ++k) kv::step_rk4(model, ws, x, {zero, zero}, S(0.01));
    if (factor < 1)
      CHECK(x.position(2) > S(0.05));
    else
      CHECK(x.position(2) < S(-0.05));
  }
}

TEMPLATE_TEST_CASE("a pitched vehicle with r_b above r_g rights itself", "[vehicle][restoring]",
                   double, float) {
  using S = TestType;
  auto p = kv::bluerov2_heavy<S>().parameters;
  p.hydrostatics = kv::Hydrostatics::submerged;  // deep water: the test starts at z = 0
  p.displaced_volume = p.mass / p.density;       // neutral, so that only the righting moment acts
  const kv::VehicleModel<S> model(p);
  kv::VehicleWorkspace<S> ws;
  for (double theta0 : {0.4, -0.4, 1.2}) {
    kv::VehicleState<S> x;
    x.attitude = kelp::quaternion_from_euler(S(0.2), S(theta0), S(0.5));
    const Vector6<S> zero = Vector6<S>::Zero();
    const Vector6<S> a = kv::forward_dynamics(model, ws, x, zero, zero);
    CHECK(a(4) * S(theta0) < S(0));  // the pitch acceleration opposes the pitch
    for (int k = 0; k < 3000; ++k) kv::step_rk4(model, ws, x, {zero, zero}, S(0.01));
    const Vector3<S> e = kelp::euler_from_quaternion(x.attitude);
    // Roll has no linear damping (von Benzon 2022), so its quadratic-only decay is slow (∝ 1/t).
    CHECK(std::abs(e(0)) < S(0.02));
    CHECK(std::abs(e(1)) < S(0.01));
  }
}

TEST_CASE("surface restoring: heave stiffness and righting moments", "[vehicle][restoring]") {
  // Independent values: ρ g A_wp z = 1025 · 9.80665 · 0.19 · 0.05 = 95.4923 N (pushes up, so g_z >
  // 0); roll righting ρ g ∇ GM_T sin φ cos φ (the gradient of ½ ρ g ∇ GM_T sin²φ) with ∇ = 15/1025
  // m³: 15 · 9.80665 · 2.0 · sin 0.1 cos 0.1 = 29.22421 N m, Fossen's linear ρ g ∇ GM_T φ to first
  // order (Fossen 2021, §4.2). Calm water (ζ = 0, no slope), no hull-depth bound.
  const auto p = kv::blueboat<double>().parameters;
  const Eigen::Vector2d flat = Eigen::Vector2d::Zero();
  const auto g = [&](double z, const Matrix3<double>& R) {
    return kv::restoring_force_surface_following(p.density, p.gravity, p.displaced_volume,
                                                 p.waterplane_area, p.gm_transverse,
                                                 p.gm_longitudinal, 0.0, z, 0.0, flat, R);
  };
  const Vector6<double> gz = g(0.05, Matrix3<double>::Identity());
  CHECK(gz(2) == Approx(95.4923).epsilon(1e-5));
  CHECK(gz.norm() == Approx(gz(2)));
  const Vector6<double> gr = g(0.0, kelp::rotation_zyx(0.1, 0.0, 0.3));
  CHECK(gr(3) == Approx(15 * 9.80665 * 2.0 * std::sin(0.1) * std::cos(0.1)).epsilon(1e-12));
  CHECK(gr(3) == Approx(29.22421).epsilon(1e-6));
  const Vector6<double> gp = g(0.0, kelp::rotation_zyx(0.0, 0.1, 0.0));
  CHECK(gp(4) == Approx(15 * 9.80665 * 1.3 * std::sin(0.1) * std::cos(0.1)).epsilon(1e-12));
  // Small angles: Fossen's linear righting moment.
  const Vector6<double> gs = g(0.0, kelp::rotation_zyx(1e-4, 0.0, 0.0));
  CHECK(gs(3) == Approx(15 * 9.80665 * 2.0 * 1e-4).epsilon(1e-7));
}
