// Mass matrices and Coriolis matrices (kelp/vehicle/rigid_body.hpp, added_mass.hpp, coriolis.hpp):
// symmetry and definiteness, the parallel-axis structure of M_RB, skew-symmetry and the zero-power
// property of C(ν), and a hand-computed value of m2c.
#include <Eigen/Eigenvalues>
#include <catch2/catch.hpp>
#include <random>

#include "kelp/vehicle/added_mass.hpp"
#include "kelp/vehicle/coriolis.hpp"
#include "kelp/vehicle/model.hpp"
#include "kelp/vehicle/presets.hpp"
#include "kelp/vehicle/rigid_body.hpp"

using kelp::Matrix3;
using kelp::Matrix6;
using kelp::Vector3;
using kelp::Vector6;
namespace kv = kelp::vehicle;

namespace {

template <typename S>
bool symmetric_positive_definite(const Matrix6<S>& M) {
  const Eigen::Matrix<double, 6, 6> Md = M.template cast<double>();
  if ((Md - Md.transpose()).norm() > 1e-6 * Md.norm()) return false;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(Md);
  return eig.eigenvalues().minCoeff() > 0.0;
}

// A random symmetric positive definite full 6x6 matrix A Aᵀ + 0.1 I (an "added mass" with every
// coupling term present).
template <typename S>
Matrix6<S> random_spd(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Matrix<double, 6, 6> A;
  for (int i = 0; i < 36; ++i) A(i) = u(rng);
  Eigen::Matrix<double, 6, 6> M = A * A.transpose() + 0.1 * Eigen::Matrix<double, 6, 6>::Identity();
  return M.cast<S>();
}

}  // namespace

TEMPLATE_TEST_CASE("M_RB and M = M_RB + M_A are symmetric positive definite", "[vehicle][mass]",
                   double, float) {
  using S = TestType;
  const auto preset = kv::bluerov2_heavy<S>();
  const kv::VehicleModel<S> model(preset.parameters);
  CHECK(symmetric_positive_definite(model.rigid_body_mass()));
  CHECK(symmetric_positive_definite(model.mass_matrix()));

  // An off-centre CG and a full inertia tensor.
  Matrix3<S> I;
  I << S(0.3), S(-0.02), S(0.01), S(-0.02), S(0.4), S(0.03), S(0.01), S(0.03), S(0.5);
  const Vector3<S> rg(S(0.05), S(-0.03), S(0.1));
  const Matrix6<S> M = kv::rigid_body_mass_matrix(S(12), I, rg);
  CHECK(symmetric_positive_definite(M));
}

TEST_CASE("M_RB has the parallel-axis structure of Fossen's H^T M_CG H", "[vehicle][mass]") {
  // Independent expectation: top-left m I; top-right -m S(r_g), i.e. M(0,4) = m z_g,
  // M(1,3) = -m z_g, M(0,5) = -m y_g, M(2,3) = m y_g, M(1,5) = m x_g, M(2,4) = -m x_g; bottom-right
  // is the inertia about the CO by the parallel-axis theorem I_g + m (|r|² I - r rᵀ).
  const double m = 10.0;
  Matrix3<double> I;
  I << 0.3, 0.01, 0.0, 0.01, 0.4, 0.0, 0.0, 0.0, 0.5;
  const Vector3<double> r(0.1, -0.2, 0.3);
  const Matrix6<double> M = kv::rigid_body_mass_matrix(m, I, r);
  CHECK((M.topLeftCorner<3, 3>() - m * Matrix3<double>::Identity()).norm() < 1e-14);
  CHECK(M(0, 4) == Approx(m * 0.3));
  CHECK(M(1, 3) == Approx(-m * 0.3));
  CHECK(M(0, 5) == Approx(-m * -0.2));
  CHECK(M(2, 3) == Approx(m * -0.2));
  CHECK(M(1, 5) == Approx(m * 0.1));
  CHECK(M(2, 4) == Approx(-m * 0.1));
  const Matrix3<double> I_co =
      I + m * (r.squaredNorm() * Matrix3<double>::Identity() - r * r.transpose());
  CHECK((M.bottomRightCorner<3, 3>() - I_co).norm() < 1e-13);
}

TEMPLATE_TEST_CASE("C_RB(nu) and C_A(nu) are skew-symmetric and do no work", "[vehicle][coriolis]",
                   double, float) {
  using S = TestType;
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  const S tol = std::is_same<S, float>::value ? S(1e-4) : S(1e-11);
  Matrix3<S> I;
  I << S(0.3), S(-0.02), S(0.01), S(-0.02), S(0.4), S(0.03), S(0.01), S(0.03), S(0.5);
  const Matrix6<S> M_rb =
      kv::rigid_body_mass_matrix(S(12), I, Vector3<S>(S(0.05), S(-0.03), S(0.1)));
  for (int k = 0; k < 200; ++k) {
    const Matrix6<S> M_a = random_spd<S>(rng);
    Vector6<S> nu;
    for (int i = 0; i < 6; ++i) nu(i) = S(u(rng));
    for (const Matrix6<S>* M : {&M_rb, &M_a}) {
      const Matrix6<S> C = kv::coriolis_matrix(*M, nu);
      const S scale = M->norm() * nu.norm();
      CHECK((C + C.transpose()).norm() == S(0));
      CHECK(std::abs(nu.dot(C * nu)) <= tol * scale * nu.norm());
      // The matrix-free force equals C(ν) ν.
      CHECK((kv::coriolis_force(*M, nu) - C * nu).norm() <= tol * scale * nu.norm());
    }
  }
}

TEST_CASE("C_RB with the CG at the origin has Fossen's closed form", "[vehicle][coriolis]") {
  // With r_g = 0, M_RB = diag(m I3, I_g) and the m2c form gives (Fossen 2021, Theorem 3.2 with
  // r_g = 0): C_RB = [[0, −m S(ν1)], [−m S(ν1), −S(I_g ν2)]], written out here by hand.
  const double m = 13.5;
  Matrix3<double> I;
  I << 0.26, 0.01, -0.02, 0.01, 0.23, 0.03, -0.02, 0.03, 0.37;
  const Matrix6<double> M_rb = kv::rigid_body_mass_matrix(m, I, Vector3<double>::Zero());
  Vector6<double> nu;
  nu << 0.7, -0.3, 0.2, 0.1, -0.4, 0.25;
  const Vector3<double> v = nu.head<3>(), w = nu.tail<3>();
  Matrix6<double> expected = Matrix6<double>::Zero();
  expected.topRightCorner<3, 3>() = -m * kelp::skew(v);
  expected.bottomLeftCorner<3, 3>() = -m * kelp::skew(v);
  expected.bottomRightCorner<3, 3>() = -kelp::skew(Vector3<double>(I * w));
  CHECK((kv::rigid_body_coriolis_matrix(M_rb, nu) - expected).norm() < 1e-13);
  // The added-mass wrapper uses the same m2c form: check it against the hand-written diagonal case
  // C_A = [[0, −S(A11 ν1)], [−S(A11 ν1), −S(A22 ν2)]] for M_A = diag(A11, A22).
  Vector6<double> a;
  a << 6.36, 7.12, 18.68, 0.189, 0.135, 0.222;
  const Matrix6<double> M_a = a.asDiagonal();
  Matrix6<double> expected_a = Matrix6<double>::Zero();
  const Vector3<double> Av = a.head<3>().cwiseProduct(v), Aw = a.tail<3>().cwiseProduct(w);
  expected_a.topRightCorner<3, 3>() = -kelp::skew(Av);
  expected_a.bottomLeftCorner<3, 3>() = -kelp::skew(Av);
  expected_a.bottomRightCorner<3, 3>() = -kelp::skew(Aw);
  CHECK((kv::added_mass_coriolis_matrix(M_a, nu) - expected_a).norm() < 1e-13);
}

TEST_CASE("m2c gives the hand-computed matrix for a fixed input", "[vehicle][coriolis]") {
  // M = diag(1..6) with one coupling M(0,4) = M(4,0) = 0.5; ν = (1, 2, 3, 0.1, 0.2, 0.3).
  // By hand: a = M11 ν1 + M12 ν2 = (1 + 0.5·0.2, 4, 9) = (1.1, 4, 9);
  //          b = M21 ν1 + M22 ν2 = (0.4, 5·0.2 + 0.5·1, 1.8) = (0.4, 1.5, 1.8).
  // C = [0, -S(a); -S(a), -S(b)] with -S(a) = [0 a_z -a_y; -a_z 0 a_x; a_y -a_x 0].
  Matrix6<double> M = Vector6<double>(1, 2, 3, 4, 5, 6).asDiagonal();
  M(0, 4) = M(4, 0) = 0.5;
  const Vector6<double> nu(1, 2, 3, 0.1, 0.2, 0.3);
  Matrix6<double> expected;
  expected << 0, 0, 0, 0, 9, -4,  //
      0, 0, 0, -9, 0, 1.1,        //
      0, 0, 0, 4, -1.1, 0,        //
      0, 9, -4, 0, 1.8, -1.5,     //
      -9, 0, 1.1, -1.8, 0, 0.4,   //
      4, -1.1, 0, 1.5, -0.4, 0;
  CHECK((kv::coriolis_matrix(M, nu) - expected).norm() < 1e-14);
  // And the unsymmetric input is symmetrised: adding an antisymmetric part changes nothing.
  Matrix6<double> Mu = M;
  Mu(1, 2) += 0.7;
  Mu(2, 1) -= 0.7;
  CHECK((kv::coriolis_matrix(Mu, nu) - expected).norm() < 1e-14);
}

TEST_CASE("diagonal_added_mass builds diag of the magnitudes", "[vehicle][mass]") {
  const Matrix6<double> Ma = kv::diagonal_added_mass(Vector6<double>(1, 2, 3, 4, 5, 6));
  CHECK(Ma(2, 2) == 3.0);
  CHECK(Ma(2, 3) == 0.0);
  CHECK_THROWS_AS(kv::diagonal_added_mass(Vector6<double>(1, -2, 3, 4, 5, 6)),
                  kelp::invalid_argument);
}
