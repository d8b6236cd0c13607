// Bad user input is rejected with kelp::invalid_argument naming the field
// (kelp/vehicle/model.hpp, rigid_body.hpp, damping.hpp, thrusters.hpp).
#include <Eigen/Eigenvalues>
#include <catch2/catch.hpp>

#include <functional>
#include <limits>
#include <random>

#include "kelp/vehicle/integrators.hpp"
#include "kelp/vehicle/model.hpp"
#include "kelp/vehicle/presets.hpp"
#include "kelp/vehicle/thrusters.hpp"
#include "support/non_finite.hpp"

namespace kv = kelp::vehicle;
using P = kv::VehicleParameters<double>;

namespace {

void expect_rejected(const std::function<void(P&)>& spoil, const char* field) {
  P p = kv::bluerov2_heavy<double>().parameters;
  spoil(p);
  INFO("field " << field);
  CHECK_THROWS_AS(kv::VehicleModel<double>(p), kelp::invalid_argument);
  CHECK_THROWS_WITH(kv::VehicleModel<double>(p), Catch::Contains(field));
}

using kelp_test::kInf;
using kelp_test::kNan;

}  // namespace

TEST_CASE("presets are valid", "[vehicle][parameters]") {
  CHECK_NOTHROW(kv::VehicleModel<double>(kv::bluerov2_heavy<double>().parameters));
  CHECK_NOTHROW(kv::VehicleModel<double>(kv::blueboat<double>().parameters));
  CHECK_NOTHROW(kv::VehicleModel<float>(kv::bluerov2_heavy<float>().parameters));
  CHECK_NOTHROW(kv::VehicleModel<float>(kv::blueboat<float>().parameters));
  CHECK_NOTHROW(kv::validate(kv::bluerov2_heavy<double>().pwm));
  CHECK_NOTHROW(kv::validate(kv::blueboat<double>().pwm));
}

TEST_CASE("bad vehicle parameters name the field", "[vehicle][parameters]") {
  expect_rejected([](P& p) { p.mass = -1; }, "mass");
  expect_rejected([](P& p) { p.mass = 0; }, "mass");
  expect_rejected([](P& p) { p.mass = kNan; }, "mass");
  expect_rejected([](P& p) { p.inertia(1, 1) = -0.1; }, "inertia");
  expect_rejected([](P& p) { p.inertia(0, 1) = 0.5; }, "inertia");  // not symmetric
  expect_rejected(
      [](P& p) {  // symmetric but indefinite
        p.inertia(0, 1) = p.inertia(1, 0) = 1.0;
      },
      "inertia");
  expect_rejected([](P& p) { p.inertia(2, 2) = kInf; }, "inertia");
  expect_rejected([](P& p) { p.r_g(1) = kNan; }, "r_g");
  expect_rejected([](P& p) { p.r_b(2) = -kInf; }, "r_b");
  expect_rejected([](P& p) { p.displaced_volume = -0.01; }, "displaced_volume");
  expect_rejected([](P& p) { p.density = kNan; }, "density");
  expect_rejected([](P& p) { p.gravity = 0; }, "gravity");
  expect_rejected([](P& p) { p.added_mass(3, 3) = -1; }, "added_mass");
  expect_rejected([](P& p) { p.added_mass(0, 5) = p.added_mass(5, 0) = 10; }, "added_mass");
  expect_rejected([](P& p) { p.added_mass(0, 1) = 1; }, "added_mass");
  expect_rejected([](P& p) { p.added_mass(4, 4) = kNan; }, "added_mass");
  expect_rejected([](P& p) { p.damping.linear(0, 0) = kInf; }, "linear_damping");
  expect_rejected([](P& p) { p.damping.linear(0, 0) = -2; }, "linear_damping");
  expect_rejected([](P& p) { p.damping.quadratic(5) = -1; }, "quadratic_damping");
  expect_rejected([](P& p) { p.damping.quadratic(5) = kNan; }, "quadratic_damping");
  expect_rejected(
      [](P& p) {
        p.hydrostatics = kv::Hydrostatics::surface;
        p.waterplane_area = 0;
      },
      "waterplane_area");
  expect_rejected(
      [](P& p) {
        p.hydrostatics = kv::Hydrostatics::surface;
        p.waterplane_area = 0.2;
        p.gm_transverse = kNan;
      },
      "gm_transverse");
}

TEST_CASE("definiteness checks agree with the eigenvalues", "[vehicle][parameters]") {
  using M6 = Eigen::Matrix<double, 6, 6>;
  const auto accepted = [](const M6& m, bool semi) {
    try {
      kv::check_symmetric_definite(m, "m", semi);
      return true;
    } catch (const kelp::invalid_argument& e) {
      CHECK_THAT(e.what(), Catch::Contains("m must be positive"));
      return false;
    }
  };
  // Q diag(λ) Qᵀ with a random orthogonal Q and chosen eigenvalues (scale 1).
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto with_eigenvalues = [&](const Eigen::Matrix<double, 6, 1>& lambda) {
    M6 a;
    for (int i = 0; i < 36; ++i) a(i) = u(rng);
    const Eigen::HouseholderQR<M6> qr(a);
    const M6 q = qr.householderQ();
    const M6 m = q * lambda.asDiagonal() * q.transpose();
    return M6(0.5 * (m + m.transpose()));
  };
  Eigen::Matrix<double, 6, 1> l;
  for (int trial = 0; trial < 200; ++trial) {
    l << 1.0, u(rng), u(rng), u(rng), u(rng), u(rng);
    const double lowest = l.minCoeff();
    if (std::abs(lowest) < 1e-6) continue;  // verdicts compared away from the thresholds
    const M6 m = with_eigenvalues(l);
    INFO("lowest eigenvalue " << lowest);
    CHECK(accepted(m, false) == (lowest > 0));
    CHECK(accepted(m, true) == (lowest > 0));
  }
  // The thresholds: semi-definite accepts λ_min down to −1e-12 of the largest entry, definite
  // needs λ_min > 0.
  l << 1.0, 0.5, 0.2, 0.1, 0.05, 0.0;
  CHECK(accepted(with_eigenvalues(l), true));  // singular: semi-definite
  CHECK_FALSE(accepted(with_eigenvalues(l), false));
  l(5) = -1e-14;
  CHECK(accepted(with_eigenvalues(l), true));  // within rounding of singular
  l(5) = -1e-9;
  CHECK_FALSE(accepted(with_eigenvalues(l), true));
  l(5) = 1e-9;
  CHECK(accepted(with_eigenvalues(l), false));
  CHECK(accepted(M6::Zero(), true));  // no added mass at all
  CHECK_FALSE(accepted(M6::Zero(), false));
  // A 3x3 inertia with one negative principal moment hidden by rotation.
  Eigen::Matrix3d inertia = Eigen::Vector3d(0.3, 0.4, -0.01).asDiagonal();
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
  inertia = r * inertia * r.transpose();
  inertia = 0.5 * (inertia + inertia.transpose()).eval();
  CHECK(inertia.diagonal().minCoeff() > 0);  // positive diagonal, yet indefinite
  CHECK_THROWS_WITH(kv::check_symmetric_definite(inertia, "inertia", false),
                    Catch::Contains("inertia must be positive definite"));
}

TEST_CASE("bad thruster layouts name the field", "[vehicle][parameters]") {
  kelp::Matrix3X<double> r(3, 2), d(3, 2);
  r << 0, 0, 0.1, -0.1, 0, 0;
  d << 1, 1, 0, 0, 0, 0;
  CHECK_NOTHROW(kv::ThrusterAllocation<double>(r, d));
  kelp::Matrix3X<double> d0 = d;
  d0.col(1).setZero();
  CHECK_THROWS_WITH(kv::ThrusterAllocation<double>(r, d0), Catch::Contains("thruster_directions"));
  kelp::Matrix3X<double> rn = r;
  rn(0, 0) = kNan;
  CHECK_THROWS_WITH(kv::ThrusterAllocation<double>(rn, d), Catch::Contains("thruster_positions"));
  kelp::Matrix3X<double> d3(3, 3);
  d3.setOnes();
  CHECK_THROWS_WITH(kv::ThrusterAllocation<double>(r, d3), Catch::Contains("thruster_directions"));
  // A 2-row position matrix is refused before anything is copied out of it.
  const Eigen::MatrixXd r2 = Eigen::MatrixXd::Zero(2, 2);
  CHECK_THROWS_WITH(kv::ThrusterAllocation<double>(r2, d), Catch::Contains("thruster_positions"));
}

TEST_CASE("NaN thruster commands, forces and PWM are refused, not passed through",
          "[vehicle][parameters]") {
  CHECK_THROWS_WITH(kv::t200_thrust(kNan), Catch::Contains("thruster command"));
  CHECK_THROWS_WITH(kv::t200_command(kNan), Catch::Contains("thruster force"));
  CHECK_THROWS_WITH(kv::command_from_pwm(kNan), Catch::Contains("pwm"));
  CHECK_THROWS_WITH(kv::pwm_from_command(kNan), Catch::Contains("thruster command"));
  CHECK(kv::t200_thrust(2.0) == kv::t200_thrust(1.0));  // out-of-range commands still saturate
}

TEST_CASE("thruster force vectors of the wrong size are refused", "[vehicle][parameters]") {
  kelp::Matrix3X<double> r(3, 2), d(3, 2);
  r << 0, 0, 0.1, -0.1, 0, 0;
  d << 1, 1, 0, 0, 0, 0;
  const kv::ThrusterAllocation<double> alloc(r, d);
  Eigen::VectorXd three(3);
  three.setOnes();
  CHECK_THROWS_WITH(alloc.wrench(three), Catch::Contains("one entry per thruster"));
  CHECK_THROWS_WITH(alloc.distribute(kelp::Vector6<double>::Ones(), three),
                    Catch::Contains("one entry per thruster"));
  CHECK(three.size() == 3);  // not silently resized
}

TEST_CASE("steps refuse a non-unit attitude or a non-finite state, leaving it unchanged",
          "[vehicle][parameters]") {
  const auto rov = kv::bluerov2_heavy<double>();
  const kv::VehicleModeld model(rov.parameters);
  kv::VehicleWorkspaced ws;
  const kelp::Vector6<double> tau = kelp::Vector6<double>::Zero();
  kv::VehicleStated zero_q;
  zero_q.attitude.coeffs().setZero();
  const kv::VehicleStated before = zero_q;
  CHECK_THROWS_WITH(kv::step_rk4(model, ws, zero_q, {tau, tau}, 1e-3), Catch::Contains("attitude"));
  CHECK_THROWS_WITH(kv::step_symplectic_euler(model, ws, zero_q, {tau, tau}, 1e-3),
                    Catch::Contains("attitude"));
  CHECK(zero_q.attitude.coeffs() == before.attitude.coeffs());
  kv::VehicleStated nan_nu;
  nan_nu.nu(2) = kNan;
  CHECK_THROWS_WITH(kv::step_rk4(model, ws, nan_nu, {tau, tau}, 1e-3), Catch::Contains("state.nu"));
  kv::VehicleStated ok;
  CHECK_NOTHROW(kv::step_rk4(model, ws, ok, {tau, tau}, 1e-3));
}
