/// \file
/// \brief The winding angle of a tether around an axis (a pile, a mooring line, a riser): how far
/// the line goes round it, signed, from the line's geometry alone (docs/entanglement.md).
///
/// **Definition.** Let e be the unit direction of the axis (through the points `from` → `to`),
/// and project every node onto the plane normal to e, relative to the axis:
/// q_i = (I − e eᵀ)(p_i − from); its angle θ_i about e (right-handed). The line's nodes are
/// taken from the start end (node 0, the boat's end in kelp::system) to the far end (the ROV's).
/// - The line's swept angle S = Σ_i wrap(θ_{i+1} − θ_i), each segment's increment wrapped to
///   (−π, π]: the angle the line turns about the axis. It needs no history (it is summed along
///   the line, so any number of turns is counted) and it changes continuously while the line
///   moves, except when a segment passes *through* the axis, where it jumps by 2π — which can
///   only happen beyond the ends of a finite obstacle (the line lifted over the top of a pile:
///   a real unwrapping) or through a line that does not touch it.
/// - The chord's angle C = wrap(θ_N − θ_0) ∈ (−π, π]: the angle the straight line between the
///   two ends sweeps (the shorter way round).
/// - S − C is then a multiple of 2π: the winding number of the closed loop "line, then the
///   chord back", i.e. how many times the line goes round the axis relative to the straight
///   chord. A line that passes by (on the chord's side of the axis) gives exactly 0, one that
///   went round once and left with its ends on the same side gives exactly ±2π.
/// - That integer jumps whenever the (virtual) chord crosses the axis — e.g. half-way through
///   a wrap, when the ROV is behind the pile. To make the winding continuous in time, the
///   chord's angle is faded out while the chord passes within `blend_radius` b of the axis
///   (b: the obstacle's radius; the chord of a line that wraps passes through the obstacle):
///       W = S − C · min(1, d_c / b),
///   where d_c is the distance of the chord's projection (a 2-D segment) from the axis (for
///   d_c ≥ b, S − C is rounded to its whole number of turns, removing rounding errors). C jumps
///   only where d_c = 0, where its factor is 0, so W is continuous; W = S − C exactly (a
///   multiple of 2π) while the chord is clear of the obstacle, and W = S (e.g. ≈ π for a line
///   half-way round a pile) when the chord goes through the axis.
///
/// Nodes on the axis (|q| below 1e-9 of the line's size) have no angle; they are skipped (the
/// line goes through the axis there, beyond a finite obstacle's end). With fewer than two nodes
/// off the axis the winding is 0.
///
/// Node-count changes (a winch inserting a node on a segment) change S by the angle that node
/// adds, which is zero for a node on the segment's straight line: the winding needs no history.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "kelp/core/angles.hpp"
#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/types.hpp"

namespace kelp::tether {

/// \brief The parts of a winding angle (all [rad] except the distance [m]).
struct Winding {
  double angle = 0;           ///< W = swept − chord · min(1, chord_distance / blend_radius)
  double swept = 0;           ///< S: the line's angle swept about the axis, start → end
  double chord = 0;           ///< C: the chord's angle, start → end, in (−π, π]
  double chord_distance = 0;  ///< d_c: distance of the chord's projection from the axis [m]
};

/// \brief The winding angle of the line with nodes `nodes` (3×n, NED [m], start end first) about
/// the axis through `from` and `to` (see the file's definition). No allocation.
/// \tparam Derived an Eigen matrix type of 3 rows (double or float), e.g. TetherState::position.
/// \param[in] nodes the node positions, 3×n, NED [m], node 0 (the start end) first.
/// \param[in] from a point on the axis, NED [m] (e.g. the foot of a pile).
/// \param[in] to another point on the axis, NED [m]; the angles are right-handed about
/// from → to.
/// \param[in] blend_radius b [m] (> 0): the distance from the axis within which the chord's
/// angle is faded out (the obstacle's radius, or its radius plus the tether's).
/// \throws kelp::invalid_argument for non-finite input, from == to, or b ≤ 0.
/// \return the winding W and its parts S, C [rad] and d_c [m] (all 0 with fewer than two nodes
/// off the axis).
template <typename Derived>
Winding winding_angle(const Eigen::MatrixBase<Derived>& nodes, const Vector3<double>& from,
                      const Vector3<double>& to, double blend_radius) {
  static_assert(Derived::RowsAtCompileTime == 3 || Derived::RowsAtCompileTime == Eigen::Dynamic,
                "winding_angle: nodes must be 3 x n");
  KELP_CHECK(nodes.rows() == 3, "winding_angle: nodes must have 3 rows");
  KELP_CHECK(nodes.allFinite() && from.allFinite() && to.allFinite(),
             "winding_angle: nodes and axis points must be finite");
  KELP_CHECK(std::isfinite(blend_radius) && blend_radius > 0,
             "winding_angle: blend_radius must be finite and > 0");
  const Vector3<double> axis = to - from;
  const double length = axis.norm();
  KELP_CHECK(length > 0, "winding_angle: the axis points must differ");
  const Vector3<double> e = axis / length;
  // An orthonormal frame (u, v) of the plane normal to e, v = e × u (right-handed about e).
  const Vector3<double> helper =
      std::abs(e.x()) < 0.9 ? Vector3<double>::UnitX() : Vector3<double>::UnitY();
  const Vector3<double> u = (helper - helper.dot(e) * e).normalized();
  const Vector3<double> v = e.cross(u);
  const auto project = [&](Eigen::Index i) {
    const Vector3<double> r = nodes.col(i).template cast<double>() - from;
    return Eigen::Vector2d(r.dot(u), r.dot(v));
  };
  Winding w;
  const Eigen::Index n = nodes.cols();
  // A size for "on the axis": 1e-9 of the line's extent and the axis' length.
  double size = length;
  for (Eigen::Index i = 0; i < n; ++i) size = std::max(size, project(i).norm());
  const double eps = 1e-9 * size;
  bool have = false;
  Eigen::Vector2d first(0, 0), last(0, 0);
  double theta = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector2d q = project(i);
    if (q.norm() <= eps) continue;
    const double t = std::atan2(q.y(), q.x());
    if (!have) {
      first = q;
      have = true;
    } else {
      w.swept += kelp::wrap_angle_exact(t - theta);
    }
    theta = t;
    last = q;
  }
  if (!have) return w;
  w.chord = std::atan2(first.x() * last.y() - first.y() * last.x(), first.dot(last));
  // Distance of the 2-D segment first–last from the origin.
  const Eigen::Vector2d ab = last - first;
  const double l2 = ab.squaredNorm();
  const double s = l2 > 0 ? std::clamp(-first.dot(ab) / l2, 0.0, 1.0) : 0.0;
  w.chord_distance = (first + s * ab).norm();
  // Clear of the obstacle, S − C is a whole number of turns: rounded, so that one wrap reads
  // 2π exactly rather than 2π less a rounding error (a threshold of one wrap then fires).
  const double turn = 2.0 * kelp::pi;
  w.angle = w.chord_distance >= blend_radius
                ? turn * std::round((w.swept - w.chord) / turn)
                : w.swept - w.chord * (w.chord_distance / blend_radius);
  return w;
}

}  // namespace kelp::tether
