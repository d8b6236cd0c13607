/// \file
/// \brief Line failure: a tether parts where a segment's axial force exceeds the line's breaking
/// strength (TetherParameters::breaking_strength), and the two pieces fly on as free lines hanging
/// from their attachment points. The event (`LineFailure`) says when and where.
///
/// The model (MoorDyn v2 added line failure for the same use, its PR #379; kelp's is its own):
/// - **When.** After every committed step (tether::step, hence tether::advance and
///   system::step) the axial force of every segment is evaluated at the committed positions and
///   velocities, T_s = max(0, EA/l·max(0, l_s − l) + σ(l_s)·BA/l·u_s·(v_{s+1} − v_s)) (as
///   compute_forces, the dashpot included: a snap load parts a line through both). If the largest
///   exceeds the breaking strength, that segment parts at the end of the step: one parting per step
///   (the first one unloads the rest of the line), at the step's resolution in time.
/// - **What parts.** A flag per segment in the state (TetherState::parted). A parted segment
///   carries no axial force (elastic or dashpot) and no bending moment, in the forces, the
///   symmetric and the whole Jacobian, the active set and the energy. Nothing else changes: no
///   node is added or removed, so mass and momentum are those of the step before.
/// - **The free ends.** The parted segment's two nodes become the free ends of the two pieces.
///   Each keeps its lumped mass, volume, weight, buoyancy and drag length (half the parted
///   segment's material goes with each piece, as a cable's two halves do when its strength member
///   fails in one place), and its tangent becomes its own remaining segment's direction, exactly as
///   at the ends of an intact line (detail::chord_nodes): drag and added mass of the free end are
///   split along the piece it belongs to, not along the gap that opens between the pieces.
/// - **After.** The pieces stay attached to their vehicles (the ends' modes are unchanged) and
///   hang or trail as free lines; the implicit schemes' kept Newton matrix is dropped (its
///   branches are no longer those of the line); their BDF2 history is kept (positions and
///   velocities are continuous through the parting, only the force changes).
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/tether/model.hpp"
#include "kelp/tether/state.hpp"

namespace kelp::tether {

/// \brief Where and when a line parted.
/// \tparam Scalar double or float.
template <typename Scalar>
struct LineFailure {
  /// Simulation time at the end of the step in which the axial force exceeded the breaking
  /// strength [s].
  double time = 0.0;
  /// The segment that parted, s in [0, N): between nodes s and s + 1 (-1: none).
  int segment = -1;
  /// Its axial force at that time [N] (above TetherParameters::breaking_strength).
  Scalar tension = Scalar(0);
  /// The segment's midpoint at that time, NED [m].
  Vector3<Scalar> position = Vector3<Scalar>::Zero();
};

/// \brief Axial force T_s [N] of segment s in `state` (its positions and velocities), as
/// compute_forces evaluates it: EA/l·max(0, l_s − l) plus the faded dashpot σ(l_s)·BA/l·u·Δv,
/// clamped at zero unless compressive_damping; 0 for a parted segment; segment 0 at a winch with
/// its own rest length. No check of `s`.
/// \tparam Scalar double or float.
/// \param model the tether (EA/l, BA/l, dashpot fade, compressive_damping).
/// \param state the state (positions NED [m], velocities [m/s], winch length, parted flags).
/// \param s the segment, 0 ≤ s < N, between nodes s and s + 1.
/// \return T_s [N] (≥ 0 unless compressive_damping).
template <typename Scalar>
Scalar segment_axial_force(const TetherModel<Scalar>& model, const TetherState<Scalar>& state,
                           int s) {
  using std::sqrt;
  if (state.parted.size() > s && state.parted(s)) return Scalar(0);
  const Vector3<Scalar> d = state.position.col(s + 1) - state.position.col(s);
  const Scalar ls = sqrt(d.squaredNorm());
  // Segment 0 at a winch has its own rest length l_w (TetherState::winch_length), hence EA/l_w,
  // BA/l_w and a fade length scaled by l_w/l (as the force pass takes them).
  const bool winch = s == 0 && state.winch_length > Scalar(0);
  const Scalar scale = winch ? state.winch_length / model.segment_length() : Scalar(1);
  const Scalar ext = ls - model.segment_length() * scale;
  Scalar t = ext > Scalar(0) ? model.axial_spring() / scale * ext : Scalar(0);
  if (model.axial_damper() != Scalar(0) && ls > Scalar(0)) {
    const Scalar rate = d.dot(state.velocity.col(s + 1) - state.velocity.col(s)) / ls;
    t += model.dashpot_fade(ls / scale).value * (model.axial_damper() / scale) * rate;
  }
  if (!model.parameters().compressive_damping && !(t > Scalar(0))) t = Scalar(0);
  return t;
}

/// \brief Parts the line at its most loaded segment when that segment's axial force
/// (segment_axial_force) exceeds the breaking strength: sets its flag in `state.parted` (sizing
/// the flags for an intact state that has none), drops the kept Newton matrix and the
/// accelerations (TetherState::has_acceleration), and describes the event in `event`. Does
/// nothing when the line cannot part (TetherModel::can_part) or no segment is over the strength.
/// O(N), no heap allocation (unless `state.parted` is empty).
/// \returns true when the line parted.
/// \tparam Scalar double or float.
/// \param model the tether (its breaking strength).
/// \param[in,out] state the committed state: a flag is set in `parted`, the kept Newton matrix
/// and the accelerations cleared, when the line parts.
/// \param[out] event set only when the line parts: time [s], segment, axial force [N] and
/// midpoint (NED [m]).
template <typename Scalar>
bool part_if_overloaded(const TetherModel<Scalar>& model, TetherState<Scalar>& state,
                        LineFailure<Scalar>& event) {
  if (!model.can_part()) return false;
  const int n = model.segments();
  const Scalar strength = model.parameters().breaking_strength;
  int worst = -1;
  Scalar worst_t = strength;
  for (int s = 0; s < n; ++s) {
    const Scalar t = segment_axial_force(model, state, s);
    if (t > worst_t) {
      worst_t = t;
      worst = s;
    }
  }
  if (worst < 0) return false;
  if (state.parted.size() != n) state.parted.setZero(n);
  state.parted(worst) = 1;
  state.newton.clear();
  state.has_acceleration = false;  // forces of the intact line
  event.time = state.time;
  event.segment = worst;
  event.tension = worst_t;
  event.position = Scalar(0.5) * (state.position.col(worst) + state.position.col(worst + 1));
  return true;
}

using LineFailured = LineFailure<double>;  ///< LineFailure<double>
using LineFailuref = LineFailure<float>;   ///< LineFailure<float>

}  // namespace kelp::tether
