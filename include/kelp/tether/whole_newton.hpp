/// \file
/// \brief The exact-Newton path of the implicit tether steps: the whole Newton matrix
/// J = M + γh ∂(M d)/∂x − γh ∂F/∂v − (γh)² ∂F/∂x over the free nodes (block-pentadiagonal, not
/// symmetric; kelp/tether/jacobian.hpp), its block LU factorisation and solve (O(N), in the
/// workspace), and the Newton direction with the active set of the axial-force kinks.
/// Factorisation and solve are separate so that a factor can serve several solves.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <string>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/tether/jacobian.hpp"
#include "kelp/tether/model.hpp"
#include "kelp/tether/state.hpp"

namespace kelp::tether {

namespace detail {

/// Sink of force_jacobian_blocks that adds the blocks of the whole Newton matrix over the free
/// nodes f0…f1 into ws.newton_lu (the kinematic ends' columns are known, their rows are not
/// equations: both are dropped).
template <typename Scalar>
struct NewtonMatrixSink {
  Eigen::Matrix<Scalar, 9, Eigen::Dynamic>& store;
  int f0, f1;
  Scalar gh, gh2;
  bool keep(int i, int j) const { return i >= f0 && i <= f1 && j >= f0 && j <= f1; }
  Eigen::Map<Matrix3<Scalar>> at(int i, int j) {
    return Eigen::Map<Matrix3<Scalar>>(store.col(band_block_index(i, j)).data());
  }
  using Block = Eigen::Map<Eigen::Matrix<Scalar, 9, 1>>;
  using Input = Eigen::Map<const Eigen::Matrix<Scalar, 9, 1>>;
  // Block (i, j) as a vector of 9 (fixed-size packets, no aliasing test).
  EIGEN_ALWAYS_INLINE Block out(int i, int j) {
    return Block(store.data() + 9 * band_block_index(i, j));
  }
  static EIGEN_ALWAYS_INLINE Input in(const Matrix3<Scalar>& a) { return Input(a.data()); }
  EIGEN_ALWAYS_INLINE void x(int i, int j, const Matrix3<Scalar>& a, Scalar c) {
    if (keep(i, j)) out(i, j) += (-gh2 * c) * in(a);
  }
  EIGEN_ALWAYS_INLINE void v(int i, int j, const Matrix3<Scalar>& a, Scalar c) {
    if (keep(i, j)) out(i, j) += (-gh * c) * in(a);
  }
  EIGEN_ALWAYS_INLINE void m(int i, int j, const Matrix3<Scalar>& a, Scalar c) {
    if (keep(i, j)) out(i, j) += (gh * c) * in(a);
  }
  EIGEN_ALWAYS_INLINE void xv(int i, int j, const Matrix3<Scalar>& ax, const Matrix3<Scalar>& av,
                              Scalar c) {
    if (keep(i, j)) out(i, j) += (-gh2 * c) * in(ax) + (-gh * c) * in(av);
  }
  EIGEN_ALWAYS_INLINE void xvm(int i, int j, const Matrix3<Scalar>& ax, const Matrix3<Scalar>& av,
                               const Matrix3<Scalar>& am, Scalar c) {
    if (keep(i, j)) out(i, j) += (-gh2 * c) * in(ax) + (-gh * c) * in(av) + (gh * c) * in(am);
  }
};

}  // namespace detail

/// \brief Assembles the whole Newton matrix of the implicit step's residual
/// R(v) = M(x)(v − v̂) − γh F(x̂ + γh v, v) at the iterate (x, v):
/// J = ∂R/∂v = M + γh ∂(M d)/∂x − γh ∂F/∂v − (γh)² ∂F/∂x, d = v − v̂, over the free nodes, into
/// `ws.newton_lu` (block (i, j), |i − j| ≤ 2, at column 5i + j − i + 2; other columns zero).
///
/// \tparam Scalar double or float.
/// \tparam Env the environment type (kelp/tether/lumped_mass.hpp).
/// \tparam DX an Eigen 3×(N+1) matrix type.
/// \tparam DV an Eigen 3×(N+1) matrix type.
/// \tparam DD an Eigen 3×(N+1) matrix type.
/// \param[in] model the tether.
/// \param[in,out] ws the workspace: reads the last compute_forces (masses, tangents, Jacobian
/// ingredients), writes `newton_lu`.
/// \param[in] env the water (its kinematics' derivatives at the nodes).
/// \param[in] x the iterate's positions x̂ + γh v, NED [m], 3×(N+1).
/// \param[in] v the iterate's velocities, NED [m/s], 3×(N+1).
/// \param[in] d v − v̂, the velocity change from the predictor [m/s], 3×(N+1) (for ∂(M d)/∂x).
/// \param[in] gh γh [s]: γ = 1 for backward Euler, 2/3 for BDF2, h the step.
/// \param[in] branches when not null, the branch of every segment (TetherWorkspace::seg_branch
/// values: 0, 1, 2) replaces the one compute_forces took (active set, whole_newton_direction).
/// Preconditions: the last compute_forces of `ws` was at (x, v) with the water the step holds.
/// O(N), no heap allocation.
template <typename Scalar, typename Env, typename DX, typename DV, typename DD>
void assemble_whole_newton_matrix(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                                  const Env& env, const Eigen::MatrixBase<DX>& x,
                                  const Eigen::MatrixBase<DV>& v, const Eigen::MatrixBase<DD>& d,
                                  Scalar gh, const VectorX<Scalar>* branches = nullptr) {
  const int f0 = model.first_free_node(), f1 = model.last_free_node();
  ws.newton_lu.middleCols(5 * Eigen::Index(f0), 5 * Eigen::Index(f1 - f0 + 1)).setZero();
  detail::NewtonMatrixSink<Scalar> sink{ws.newton_lu, f0, f1, gh, gh * gh};
  for (int i = f0; i <= f1; ++i) {
    auto mi = sink.at(i, i);
    const Vector3<Scalar> q = ws.tangent.col(i);
    mi = (ws.mass_tan(i) * q) * q.transpose();
    mi.diagonal().array() += ws.mass_iso(i);
  }
  detail::force_jacobian_blocks(model, ws, env, x, v, &d, branches, sink);
}

/// \brief Block LU factorisation, in place, of the block-pentadiagonal matrix in
/// `ws.newton_lu` over the free nodes (assemble_whole_newton_matrix): A = L U with L unit block
/// lower triangular (blocks L_{i,i−2}, L_{i,i−1} stored in place of A's) and U block upper
/// (U_{i,i+1}, U_{i,i+2} in place; the diagonal block stored as its inverse U_ii⁻¹). O(N):
/// about 7 products of 3×3 blocks and one 3×3 inverse per node.
///
/// No pivoting between blocks: each pivot block U_ii is the Schur complement of the leading
/// nodes, inverted by cofactors. The Newton matrix is M (symmetric positive definite) plus γh,
/// (γh)² times the force derivatives, whose dominant parts (axial stiffness, dashpot, drag's
/// |v_r| terms, seabed) are symmetric positive semi-definite; the non-symmetric parts (the
/// tangent's dependence of drag and added mass, the rate terms) are of the order of the drag
/// and small beside them, so the pivots stay near those of the symmetric positive definite
/// block-Cholesky factorisation (Golub & Van Loan, Matrix Computations, 4th ed., §4.4.1:
/// Gaussian elimination without pivoting is stable for matrices whose symmetric part is
/// positive definite, when the skew part is moderate). A pivot block that is not finite or
/// numerically singular (|det U_ii| ≤ ε·‖U_ii‖³, ε of Scalar) is refused.
/// \throws kelp::numerical_error naming the node; the implicit steps then halve the step.
/// \tparam Scalar double or float.
/// \param[in] model the tether (its free nodes).
/// \param[in,out] ws the workspace whose `newton_lu` holds the assembled matrix; overwritten by
/// its factor (also on a throw: re-assemble before using it again).
template <typename Scalar>
void factor_whole_newton_matrix(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws) {
  using std::abs;
  using M3 = Matrix3<Scalar>;
  using Map = Eigen::Map<M3>;
  const int f0 = model.first_free_node(), f1 = model.last_free_node();
  Scalar* const base = ws.newton_lu.data();
  const auto blk = [base](int i, int j) { return Map(base + 9 * detail::band_block_index(i, j)); };
  for (int i = f0; i <= f1; ++i) {
    auto b2 = blk(i, i);
    if (i - 2 >= f0) {
      auto l0 = blk(i, i - 2);
      const M3 l = l0 * blk(i - 2, i - 2);  // × U⁻¹ of node i − 2
      l0 = l;
      blk(i, i - 1).noalias() -= l * blk(i - 2, i - 1);
      b2.noalias() -= l * blk(i - 2, i);
    }
    if (i - 1 >= f0) {
      auto l1 = blk(i, i - 1);
      const M3 l = l1 * blk(i - 1, i - 1);
      l1 = l;
      b2.noalias() -= l * blk(i - 1, i);
      if (i + 1 <= f1) blk(i, i + 1).noalias() -= l * blk(i - 1, i + 1);
    }
    const M3 u = b2;
    const Scalar det = u.determinant();
    const Scalar scale = u.cwiseAbs().maxCoeff();
    if (!(abs(det) > std::numeric_limits<Scalar>::epsilon() * scale * scale * scale) ||
        !is_finite(det))
      ::kelp::detail::throw_numerical_error(
          "tether Newton step (whole Jacobian): singular or non-finite pivot block at node " +
          std::to_string(i) + "; the state is unchanged");
    b2 = u.inverse();
  }
}

/// \brief Solves A δ = rhs with the factor of factor_whole_newton_matrix, over the free nodes:
/// reads `rhs` (3×(N+1), free columns), writes the free columns of `delta` (may alias `rhs`).
/// O(N), no heap allocation.
/// \tparam Scalar double or float.
/// \tparam DR an Eigen 3×(N+1) matrix type.
/// \tparam DD a writable Eigen 3×(N+1) matrix type.
/// \param[in] model the tether (its free nodes).
/// \param[in] ws the workspace whose `newton_lu` holds the factor.
/// \param[in] rhs the right-hand side (ws.rhs: −R, forces [N]), 3×(N+1).
/// \param[out] delta the solution δ (velocity correction [m/s]) in its free columns; the
/// kinematic end columns are not written.
template <typename Scalar, typename DR, typename DD>
void solve_whole_newton_matrix(const TetherModel<Scalar>& model, const TetherWorkspace<Scalar>& ws,
                               const Eigen::MatrixBase<DR>& rhs, Eigen::MatrixBase<DD>& delta) {
  using V3 = Vector3<Scalar>;
  using CMap = Eigen::Map<const Matrix3<Scalar>>;
  const int f0 = model.first_free_node(), f1 = model.last_free_node();
  const Scalar* const base = ws.newton_lu.data();
  const auto blk = [base](int i, int j) { return CMap(base + 9 * detail::band_block_index(i, j)); };
  for (int i = f0; i <= f1; ++i) {
    V3 y = rhs.col(i);
    if (i - 2 >= f0) y.noalias() -= blk(i, i - 2) * delta.col(i - 2);
    if (i - 1 >= f0) y.noalias() -= blk(i, i - 1) * delta.col(i - 1);
    delta.col(i) = y;
  }
  for (int i = f1; i >= f0; --i) {
    V3 y = delta.col(i);
    if (i + 1 <= f1) y.noalias() -= blk(i, i + 1) * delta.col(i + 1);
    if (i + 2 <= f1) y.noalias() -= blk(i, i + 2) * delta.col(i + 2);
    delta.col(i) = blk(i, i) * y;
  }
}

namespace detail {

/// Newton direction of the implicit step with the whole Jacobian (ImplicitOptions::jacobian ==
/// JacobianKind::whole), at the iterate (x, v) of the last compute_forces: solves J δ = −R
/// (ws.rhs = −R) into ws.delta, J assembled and factored in ws.newton_lu. The kinks of the
/// axial force are handled by segment_active_set (the primal–dual active set: each
/// segment on the branch its predicted extension and stretch rate give, at most `max_passes`
/// factorisations); the other kinks (surface band, seabed, friction) take the branch of the
/// current iterate. ws.rhs is restored; ws.newton_lu keeps the last factor. No heap allocation.
/// \returns the number of factorisations (active-set passes).
template <typename Scalar, typename Env, typename DX, typename DV, typename DD>
int whole_newton_direction(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                           const Env& env, const Eigen::MatrixBase<DX>& x,
                           const Eigen::MatrixBase<DV>& v, const Eigen::MatrixBase<DD>& d,
                           Scalar gh, Scalar band, int max_passes) {
  return segment_active_set(model, ws, gh, band, max_passes, [&](bool on_true) {
    assemble_whole_newton_matrix(model, ws, env, x, v, d, gh, on_true ? nullptr : &ws.seg_branch);
    factor_whole_newton_matrix(model, ws);
    solve_whole_newton_matrix(model, ws, ws.rhs, ws.delta);
  });
}

}  // namespace detail

}  // namespace kelp::tether
