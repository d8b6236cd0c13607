/// \file
/// \brief Lumped-mass tether: the state (positions, velocities, clock, integrator history), the
/// prescribed end motion (`TetherBoundary`), the end forces, and the preallocated workspace
/// (scratch and outputs of the force evaluation and the integrators), with their checks.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <utility>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/tether/model.hpp"

namespace kelp::tether {

/// \brief One flag per segment (0 or 1), e.g. TetherState::parted.
using SegmentFlags = Eigen::Matrix<std::uint8_t, Eigen::Dynamic, 1>;

namespace detail {
/// Scalars kept per step of the implicit steps' block elimination (see
/// detail::factor_solve_block_tridiagonal).
inline constexpr int kNewtonFactorStepSize = 30;
/// Scalars of a kept Newton factorisation of a tether of `nodes` nodes: at most nodes / 2
/// elimination steps and the meeting node's block.
inline Eigen::Index newton_factor_size(int nodes) {
  return Eigen::Index(kNewtonFactorStepSize) * (nodes / 2) + 8;
}
}  // namespace detail

/// \brief The Newton matrix an implicit step kept for the next ones (the simplified Newton /
/// W-method of ImplicitOptions::newton): the block factorisation of J = M + γh D_v + (γh)² D_x
/// at the point where it was last formed, the taut/slack/clamped branch of every segment it was
/// formed with, its γh, and how many steps have used it.
///
/// It lives in the state because it determines the next step's iterates: saving and restoring a
/// state restores it too, so a run is reproduced bit for bit. A state built from a model has it
/// sized and empty (`gh` = 0: the next implicit step forms a new one).
/// \tparam Scalar double or float.
template <typename Scalar>
struct KeptNewtonMatrix {
  /// Factorisation (detail::factor_solve_block_tridiagonal's layout).
  VectorX<Scalar> factor;
  /// Branch of each segment in the factored matrix: 0 no axial force, 1 dashpot, 2 taut.
  VectorX<Scalar> branch;
  /// γh [s] the matrix was formed with; 0 when none is kept.
  Scalar gh = Scalar(0);
  /// Steps committed with this factorisation since it was formed.
  int age = 0;
  /// Steps that form their own matrix instead of trying a kept one: after a step whose first
  /// correction with a kept matrix missed the tolerance, 1, 3, 7, … up to 31 while that repeats
  /// (a line moving too fast for a matrix to serve the next step).
  int pause = 0;
  /// The last pause (0 after a kept matrix served a step with one correction).
  int backoff = 0;

  /// \brief True when a factorisation is kept and sized for `nodes` nodes.
  /// \param nodes the tether's node count N + 1.
  /// \return whether `gh` > 0 and both buffers have the sizes resize(nodes) gives them.
  bool holds(int nodes) const {
    return gh > Scalar(0) && factor.size() == detail::newton_factor_size(nodes) &&
           branch.size() == nodes - 1;
  }
  /// \brief Forgets the kept factorisation and its history (the buffers stay allocated).
  void clear() {
    gh = Scalar(0);
    age = 0;
    pause = 0;
    backoff = 0;
  }
  /// \brief Sizes the buffers for `nodes` nodes, nothing kept.
  /// \param nodes the tether's node count N + 1, ≥ 2 (not checked here).
  void resize(int nodes) {
    factor.setZero(detail::newton_factor_size(nodes));
    branch.setZero(nodes - 1);
    clear();
  }
};

/// \brief Everything that determines the tether's next step: positions and velocities of all
/// N + 1 nodes (NED), the clock, and the integrator history (BDF2's previous step, also the
/// implicit schemes' velocity predictor, with the accelerations the last implicit step left, and
/// the Newton matrix the simplified Newton method keeps).
///
/// Saving a copy of a state and restoring it later reproduces the following steps bit for bit;
/// the workspace holds scratch only. The clock is a double for every Scalar, so a float tether
/// keeps exact time over any run length (10 ms steps for 24 h end within 1e-10 s relative).
/// \tparam Scalar double or float.
template <typename Scalar>
struct TetherState {
  /// Node positions, 3 × (N+1), NED [m].
  Matrix3X<Scalar> position;
  /// Node velocities, 3 × (N+1), NED [m/s].
  Matrix3X<Scalar> velocity;
  /// Simulation time [s] (double for every Scalar: one clock that does not drift).
  double time = 0.0;
  /// Rounding error of `time` carried by the compensated (Kahan) sum of the step lengths, so that
  /// after n steps of dt the clock is n·dt to one rounding however long the run (a plain sum
  /// drifts by up to n/2 units in the last place: microseconds after hours of 10 ms steps, and
  /// the wave phase with it). Reset it to 0 when setting `time` by hand.
  double time_carry = 0.0;
  /// Positions one step before `position` (integrator history; valid when previous_dt > 0).
  Matrix3X<Scalar> previous_position;
  /// Velocities one step before `velocity` (integrator history; valid when previous_dt > 0).
  Matrix3X<Scalar> previous_velocity;
  /// Length of the step that led from the previous positions to `position` [s]; 0 when there
  /// is no history (a new state, or one whose positions were set by hand: call clear_history()).
  double previous_dt = 0.0;
  /// The implicit steps' kept Newton matrix (see KeptNewtonMatrix; ImplicitOptions::newton).
  KeptNewtonMatrix<Scalar> newton;
  /// Node accelerations at `time`, 3 × (N+1), NED [m/s²] (valid when has_acceleration): those of
  /// the implicit step that led to this state, (v − v̂)/(γh) at its converged iterate, that is
  /// M⁻¹F there to the step's tolerance (kinematic ends: the difference of their prescribed
  /// velocities). The next BDF2 step's velocity predictor v_{n−1} + 2h·a_n (step_bdf2).
  Matrix3X<Scalar> acceleration;
  /// True when `acceleration` is this state's: set by the implicit steps, cleared by every
  /// other step, clear_history(), a parting (kelp/tether/failure.hpp) and a winch re-mesh.
  bool has_acceleration = false;
  /// Which extrapolation the next BDF2 step starts its Newton iteration from: true, the
  /// accelerations' v_{n−1} + 2h·a_n; false, the linear 2v_n − v_{n−1}. A BDF2 step that had
  /// both and was not made by one correction with the kept Newton matrix sets it to the one that
  /// came closer to its own solution (step_bdf2).
  bool predict_from_acceleration = true;
  /// Per segment: 1 when the line has parted there (TetherParameters::breaking_strength, see
  /// kelp/tether/failure.hpp), else 0. A parted segment carries no axial force and no bending;
  /// its two nodes become the free ends of the two pieces. Empty or all zero: an intact line
  /// (a state assembled by hand may leave it empty). A re-mesh that inserts or removes nodes
  /// must carry these flags with their segments.
  SegmentFlags parted;
  /// Unstretched length of segment 0, the segment at a winch on the start end [m]; 0 (the
  /// default, and always without a winch): the model's segment length l. A winch
  /// (kelp/tether/winch.hpp) changes it step by step and keeps it in [remove_ratio·l,
  /// insert_ratio·l] by inserting and removing nodes. It lives in the state (not the model)
  /// because it changes during a run and determines the next step.
  Scalar winch_length = Scalar(0);
  /// Rate at which the winch pays line out [m/s] (negative: reeling in); the winch's own state
  /// (its speed is limited in acceleration), 0 without a winch. Finite: the steps, the winch
  /// and check_state refuse a state whose rate is not.
  Scalar payout_rate = Scalar(0);

  TetherState() = default;
  /// \brief Zero state sized for `model`, no history.
  /// \param model the tether (its node and segment counts); all nodes at the origin, at rest,
  /// time 0, an intact line, no winch.
  explicit TetherState(const TetherModel<Scalar>& model)
      : position(Matrix3X<Scalar>::Zero(3, model.nodes())),
        velocity(Matrix3X<Scalar>::Zero(3, model.nodes())),
        previous_position(Matrix3X<Scalar>::Zero(3, model.nodes())),
        previous_velocity(Matrix3X<Scalar>::Zero(3, model.nodes())),
        acceleration(Matrix3X<Scalar>::Zero(3, model.nodes())),
        parted(SegmentFlags::Zero(model.segments())) {
    newton.resize(model.nodes());
  }

  /// \brief Number of parted segments (0 for an intact line). O(N).
  /// \return the count of nonzero flags in `parted`.
  int parted_segments() const { return parted.size() ? int(parted.template cast<int>().sum()) : 0; }

  /// \brief True when the state carries the previous step (BDF2 history).
  /// \return whether previous_dt > 0.
  bool has_history() const { return previous_dt > 0.0; }
  /// \brief Forgets the integrator history: the next implicit step starts with backward Euler.
  /// Call it after editing `position` or `velocity` by hand. The kept Newton matrix and the
  /// accelerations are dropped too.
  void clear_history() {
    previous_dt = 0.0;
    newton.clear();
    has_acceleration = false;
    predict_from_acceleration = true;
  }
};

/// \brief Motion of a kinematic end point over a step, NED.
///
/// Within a step of length h starting at t₀ the end is taken at p + v τ + ½ a τ², with velocity
/// v + a τ (τ = t − t₀).
/// \tparam Scalar double or float.
template <typename Scalar>
struct EndMotion {
  /// Position at the start of the step, NED [m].
  Vector3<Scalar> position = Vector3<Scalar>::Zero();
  /// Velocity, NED [m/s].
  Vector3<Scalar> velocity = Vector3<Scalar>::Zero();
  /// Acceleration, NED [m/s²] (also enters the end force through the end node's inertia).
  Vector3<Scalar> acceleration = Vector3<Scalar>::Zero();
  /// Zero (the default): a pinned end, free to turn. A unit vector, NED: a clamped end, the
  /// direction in which the line leaves the end point (towards node 1 at the start, towards
  /// node N − 1 at the far end), held over the step. With a bending stiffness EI > 0 the line
  /// then has the bending energy 2EI/l·(1 − t·u) at that end (u the direction of its end segment
  /// away from the end; the angle is taken over half a segment, as a clamped beam's rotation
  /// between the wall and its first node: see compute_forces); with EI = 0 it changes nothing.
  /// Its length is ignored (normalised); it must be finite.
  Vector3<Scalar> direction = Vector3<Scalar>::Zero();

  /// \brief Position τ seconds into the step.
  /// \param tau time since the start of the step τ [s].
  /// \return p + v τ + ½ a τ², NED [m].
  Vector3<Scalar> position_at(Scalar tau) const {
    return position + tau * velocity + (Scalar(0.5) * tau * tau) * acceleration;
  }
  /// \brief Velocity τ seconds into the step.
  /// \param tau time since the start of the step τ [s].
  /// \return v + a τ, NED [m/s].
  Vector3<Scalar> velocity_at(Scalar tau) const { return velocity + tau * acceleration; }
  /// \brief The same motion seen from τ seconds into the step (position and velocity at τ).
  /// \param tau time since the start of the step τ [s].
  /// \return the motion starting at position_at(τ) with velocity_at(τ); the same acceleration
  /// and direction.
  EndMotion after(Scalar tau) const {
    return {position_at(tau), velocity_at(tau), acceleration, direction};
  }
};

/// \brief Prescribed motion of both ends (an entry is ignored when that end is free).
/// \tparam Scalar double or float.
template <typename Scalar>
struct TetherBoundary {
  /// Node 0 (start, e.g. the ASV attachment point).
  EndMotion<Scalar> start;
  /// Node N (far end, e.g. the AUV attachment point).
  EndMotion<Scalar> end;

  /// \brief The same end motions seen from τ seconds into the step (for sub-steps).
  /// \param tau time since the start of the step τ [s].
  /// \return both ends' EndMotion::after(τ).
  TetherBoundary after(Scalar tau) const { return {start.after(tau), end.after(tau)}; }
  /// \brief Both ends fixed at the given NED points [m].
  /// \tparam D1 an Eigen 3-vector expression type.
  /// \tparam D2 an Eigen 3-vector expression type.
  /// \param start_ned node 0's position, NED [m].
  /// \param end_ned node N's position, NED [m].
  /// \return the boundary with zero velocities and accelerations, both ends pinned (no
  /// direction); not checked for finiteness (see check_boundary()).
  template <typename D1, typename D2>
  static TetherBoundary fixed(const Eigen::MatrixBase<D1>& start_ned,
                              const Eigen::MatrixBase<D2>& end_ned) {
    TetherBoundary b;
    b.start.position = start_ned;
    b.end.position = end_ned;
    return b;
  }
};

/// \brief Forces the tether exerts on its two attachment points, NED [N] (zero for a free end).
/// \tparam Scalar double or float.
template <typename Scalar>
struct EndForces {
  /// On the start attachment point (node 0).
  Vector3<Scalar> on_start = Vector3<Scalar>::Zero();
  /// On the far attachment point (node N).
  Vector3<Scalar> on_end = Vector3<Scalar>::Zero();
};

namespace detail {
/// \throws kelp::invalid_argument naming `who` and the count unless `nodes` is a tether's node
/// count: segments + 1 with segments in [1, limits::max_segments].
inline void check_node_count(int nodes, const char* who) {
  if (!(nodes >= 2 && nodes <= limits::max_segments + 1))
    ::kelp::detail::throw_invalid_argument(std::string(who) + ": nodes must be in [2, " +
                                           std::to_string(limits::max_segments + 1) +
                                           "] (segments + 1), got " + std::to_string(nodes));
}
}  // namespace detail

/// \brief A copy of a TetherState kept in preallocated buffers (no allocation when saved or
/// restored once sized), so that a failed driver or step can put the state back bit for bit.
/// \tparam Scalar double or float.
template <typename Scalar>
struct StateBackup {
  /// \brief Saved TetherState::position, velocity, previous_position, previous_velocity,
  /// acceleration (3 × (N+1), NED [m], [m/s], [m/s²]).
  ///@{
  Matrix3X<Scalar> position, velocity, previous_position, previous_velocity, acceleration;
  ///@}
  bool has_acceleration = false;          ///< saved TetherState::has_acceleration
  bool predict_from_acceleration = true;  ///< saved TetherState::predict_from_acceleration
  /// \brief Saved TetherState::time, time_carry, previous_dt [s].
  ///@{
  double time = 0.0, time_carry = 0.0, previous_dt = 0.0;
  ///@}
  KeptNewtonMatrix<Scalar> newton;  ///< saved TetherState::newton
  SegmentFlags parted;              ///< saved TetherState::parted
  /// \brief Saved TetherState::winch_length [m] and payout_rate [m/s].
  ///@{
  Scalar winch_length = Scalar(0), payout_rate = Scalar(0);
  ///@}

  /// \brief Sizes the buffers for `nodes` nodes.
  /// \param nodes the tether's node count N + 1.
  /// \throws kelp::invalid_argument naming `nodes` unless it is in [2, limits::max_segments + 1].
  void resize(int nodes) {
    detail::check_node_count(nodes, "StateBackup::resize");
    for (Matrix3X<Scalar>* m :
         {&position, &velocity, &previous_position, &previous_velocity, &acceleration})
      m->setZero(3, nodes);
    newton.resize(nodes);
    parted.setZero(nodes - 1);
  }
  /// \brief Copies `s` (history and kept Newton matrix included).
  /// \param s the state to save; no allocation when the buffers already have its sizes.
  void save(const TetherState<Scalar>& s) {
    position = s.position;
    velocity = s.velocity;
    previous_position = s.previous_position;
    previous_velocity = s.previous_velocity;
    acceleration = s.acceleration;
    has_acceleration = s.has_acceleration;
    predict_from_acceleration = s.predict_from_acceleration;
    time = s.time;
    time_carry = s.time_carry;
    previous_dt = s.previous_dt;
    winch_length = s.winch_length;
    payout_rate = s.payout_rate;
    newton.factor = s.newton.factor;
    newton.branch = s.newton.branch;
    newton.gh = s.newton.gh;
    newton.age = s.newton.age;
    newton.pause = s.newton.pause;
    newton.backoff = s.newton.backoff;
    parted = s.parted;
  }
  /// \brief Puts the saved state back into `s`.
  /// \param[out] s the state overwritten with the saved one (every field save() copied).
  void restore(TetherState<Scalar>& s) const {
    s.position = position;
    s.velocity = velocity;
    s.previous_position = previous_position;
    s.previous_velocity = previous_velocity;
    s.acceleration = acceleration;
    s.has_acceleration = has_acceleration;
    s.predict_from_acceleration = predict_from_acceleration;
    s.time = time;
    s.time_carry = time_carry;
    s.previous_dt = previous_dt;
    s.winch_length = winch_length;
    s.payout_rate = payout_rate;
    s.newton.factor = newton.factor;
    s.newton.branch = newton.branch;
    s.newton.gh = newton.gh;
    s.newton.age = newton.age;
    s.newton.pause = newton.pause;
    s.newton.backoff = newton.backoff;
    s.parted = parted;
  }
};

/// \brief Preallocated mutable buffers for force evaluation and integration (Pinocchio's `Data`).
///
/// Built from a model; every step reuses these buffers, so no heap allocation happens in a step.
/// Fields are public so that tests and diagnostics can read intermediate quantities; their
/// content is valid after the last force evaluation.
/// \tparam Scalar double or float.
template <typename Scalar>
struct TetherWorkspace {
  // --- per evaluation, per node -------------------------------------------------------------
  Matrix3X<Scalar> force;               ///< net force on each node (no constraint force), NED [N]
  Matrix3X<Scalar> acceleration;        ///< node accelerations of the explicit steps, NED [m/s²]
  Matrix3X<Scalar> tangent;             ///< unit node tangent q_i (zero if degenerate)
  Matrix3X<Scalar> water_velocity;      ///< current + wave orbital velocity at each node [m/s]
  Matrix3X<Scalar> water_acceleration;  ///< water acceleration at each node [m/s²]
  VectorX<Scalar> surface_elevation;    ///< free-surface elevation ζ above each node [m]
  Matrix3X<Scalar> bending;             ///< bending force on each node (when EI > 0) [N]
  VectorX<Scalar> mass_iso;             ///< a_i: M_i = a_i I + b_i q qᵀ [kg]
  VectorX<Scalar> mass_tan;             ///< b_i [kg]
  VectorX<Scalar> mass_iso_inv;         ///< 1/a_i [1/kg]
  VectorX<Scalar> mass_tan_ratio;  ///< b_i/(a_i + b_i): M_i⁻¹ = (I − (b/(a+b)) q qᵀ)/a [-]
  VectorX<Scalar> seabed_force;    ///< upward normal seabed contact force on node i [N]
  /// Seabed normal force that sets the friction limit μ_f N when `frozen_friction` [N]
  VectorX<Scalar> friction_normal;
  /// Set by the implicit steps for the duration of their Newton iteration: the friction limit
  /// then uses the normal force at the start of the step (`friction_normal`), a first-order lag
  /// that keeps the friction's dependence on the contact force (which is not symmetric, so not in
  /// the block Jacobian) from stalling Newton's method at impacts.
  bool frozen_friction = false;
  VectorX<Scalar> submerged;  ///< submerged fraction φ_i of node i (1 wet, 0 in air)
  // --- per evaluation, per segment ------------------------------------------------------------
  Matrix3X<Scalar> direction;        ///< unit vector u_s from node s to s+1 (0 if zero length)
  VectorX<Scalar> tension;           ///< axial force T_s: elastic (≥ 0) plus dashpot [N]
  VectorX<Scalar> stretched_length;  ///< segment length l_s [m]
  // --- Jacobian ingredients (filled when requested) --------------------------------------------
  VectorX<Scalar> seg_k_uu;  ///< axial stiffness minus geometric term: EA/l − T⁺/l_s or −T⁺/l_s
  VectorX<Scalar> seg_k_perp;  ///< geometric stiffness T/l_s [N/m]
  VectorX<Scalar> seg_c_uu;    ///< BA/l, or 0 while the axial force is clamped at zero [N s/m]
  /// −∂F_i/∂v_i from drag and seabed, symmetric (xx, yx, zx, yy, zy, zz) [N s/m]
  Eigen::Matrix<Scalar, 6, Eigen::Dynamic> node_dv;
  VectorX<Scalar> node_kz;  ///< −∂F_z/∂z from the seabed [N/m]
  /// −∂F_i/∂x_i of the obstacle contacts' normal stiffness, symmetric (xx, yx, zx, yy, zy, zz)
  /// [N/m]; meaningful only while `any_contact` (kelp/tether/contact.hpp)
  Eigen::Matrix<Scalar, 6, Eigen::Dynamic> node_kc;
  // --- obstacle contact (kelp/tether/contact.hpp), filled when the environment has obstacles ---
  /// Force of the obstacles (cylinders, boxes, a height-field seabed) on each node, NED [N]
  /// (zero without obstacles)
  Matrix3X<Scalar> contact_force;
  /// Normal contact force of the cylinders and boxes on each segment [N] (≥ 0)
  VectorX<Scalar> segment_contact;
  /// The obstacle pressing hardest on each segment: ObstacleSet index (cylinders first, then
  /// boxes), or −1 when it touches none
  Eigen::VectorXi segment_obstacle;
  /// True when the last force evaluation found a contact with an obstacle
  bool any_contact = false;
  // --- linear solver and integrator buffers ----------------------------------------------------
  /// What the block elimination of the Newton solve keeps for its back substitution, two
  /// columns per elimination step (detail::solve_block_tridiagonal)
  Eigen::Matrix<Scalar, 17, Eigen::Dynamic> block_inv;
  /// The whole Newton matrix (ImplicitOptions::jacobian == JacobianKind::whole) and, after
  /// factor_whole_newton_matrix, its block LU factor: column 5i + (j − i + 2) holds the 3×3 block
  /// (i, j), |i − j| ≤ 2, column-major (assemble_whole_newton_matrix)
  Eigen::Matrix<Scalar, 9, Eigen::Dynamic> newton_lu;
  /// \brief A Newton factorisation formed in the current step (ImplicitOptions::newton =
  /// simplified), swapped into TetherState::newton when the step is committed, and its segment
  /// branches (as KeptNewtonMatrix::factor and branch).
  ///@{
  VectorX<Scalar> newton_factor, newton_branch;
  ///@}
  /// \brief Newton right-hand side (−R, forces [N]) and correction (velocity [m/s]).
  ///@{
  Matrix3X<Scalar> rhs, delta;
  ///@}
  Matrix3X<Scalar> rhs_true;      ///< −R saved while the active-set passes modify rhs
  VectorX<Scalar> seg_true_k_uu;  ///< seg_k_uu saved while the active-set passes modify it
  VectorX<Scalar> seg_true_c_uu;  ///< seg_c_uu saved while the active-set passes modify it
  VectorX<Scalar> seg_rate;       ///< segment stretch rate u_s·(v_{s+1} − v_s) [m/s]
  /// The parted segments the force evaluation uses (1: parted; see TetherState::parted), copied
  /// from the state by every step (detail::load_parted); set it the same way before calling
  /// compute_forces by hand on a state whose line has parted
  SegmentFlags parted;
  /// True when any entry of `parted` is set (the force passes then take their general path)
  bool any_parted = false;
  /// \brief Unit clamp directions of the start and far end (EndMotion::direction; zero:
  /// pinned), NED, that the force evaluation uses, copied from the boundary by every step
  /// (detail::load_clamps); set them the same way before calling compute_forces by hand on a
  /// clamped line.
  ///@{
  Vector3<Scalar> clamp_start = Vector3<Scalar>::Zero(), clamp_end = Vector3<Scalar>::Zero();
  ///@}
  /// \brief True when segment s has parted (in the flags of the last detail::load_parted).
  /// \param s the segment, 0 ≤ s < N (not checked).
  /// \return whether `any_parted` and parted(s) is set.
  bool is_parted(int s) const { return any_parted && parted(s) != 0; }
  /// Branch of segment s in the Newton step's linear model: 0 no force (slack, or clamped at
  /// zero), 1 dashpot only (slack), 2 elastic plus dashpot (taut)
  VectorX<Scalar> seg_branch;
  /// \brief Integrator stages and Newton / line-search iterates: positions (x…, NED [m]) and
  /// velocities (v…, NED [m/s]), 3 × (N+1) each.
  ///@{
  Matrix3X<Scalar> x0, v0, x1, v1, xs, vs;
  ///@}
  /// compute_forces' scratch, one contiguous column per component: T_s u_s of each segment
  /// (columns 0–2), each node's force before the added-mass coupling to its neighbours (3–5),
  /// that coupling term (6–8), and the positions (9–11) and velocities (12–14) evaluated
  Eigen::Matrix<Scalar, Eigen::Dynamic, 15> pass_buffer;
  /// \brief Copies of positions and velocities given to compute_forces as expressions rather
  /// than as column-major storage.
  ///@{
  Matrix3X<Scalar> x_eval, v_eval;
  ///@}
  /// State at entry of a driver (`advance`, `solve_static_equilibrium`), restored if it fails
  StateBackup<Scalar> entry_backup;
  /// State at entry of an implicit step that is retried in sub-steps, restored if they fail
  StateBackup<Scalar> retry_backup;
  /// water_velocity, water_acceleration and surface_elevation hold zeros (set by resize and by
  /// compute_forces in a still environment, whose water query it then skips; cleared when the
  /// query runs)
  bool water_is_zero = false;
  /// Set by the implicit steps after their first force evaluation (unless
  /// ImplicitOptions::resample_water): compute_forces then reuses water_velocity,
  /// water_acceleration and surface_elevation, sampled at the step's predicted node positions
  /// at t + h, instead of querying the environment at every Newton iterate.
  bool water_frozen = false;
  /// Forces the tether exerts on its kinematic attachment points at the end of the last step
  /// (the state it returned, at t + h), NED [N], whatever the scheme: the force on the end node
  /// (segment tension, weight, buoyancy, drag and fluid forces) less its inertia along the
  /// prescribed motion, F_node − M_node a_end, which is the force that holds the end node on its
  /// path, what a body carrying the end feels. The implicit schemes take it at their final iterate
  /// (to the Newton tolerance); the explicit ones evaluate the forces once more at the end state,
  /// which the next explicit step takes as its first stage when it starts from exactly that state
  /// (end_evaluated). Zero for a free end.
  /// end_forces_from_workspace gives the same after a compute_forces.
  EndForces<Scalar> end_forces;
  /// The same instant's force on the end nodes without the inertia term, F_node [N] (end_forces
  /// + M_node a_end): for a coupling that carries the end node's mass with the body itself, or a
  /// comparison with a code that reports the end node's net force.
  EndForces<Scalar> end_node_forces;
  /// The force buffers and `acceleration` hold the evaluation an explicit step made at its end:
  /// at time end_evaluation_time, positions end_position and velocities end_velocity, for the
  /// model and environment at end_model and end_environment (and the environment's instance id,
  /// when it has one: kelp's Environment does, a new one for every copy or assignment). The next
  /// explicit step takes it as its first stage when it starts from exactly that (bitwise equal
  /// state, same objects, same winch length). Set it false to force a fresh evaluation, e.g.
  /// after changing a custom environment in place between two steps.
  bool end_evaluated = false;
  double end_evaluation_time = 0.0;  ///< time of the kept end evaluation [s] (end_evaluated)
  const void* end_model = nullptr;   ///< address of the model it was made with (identity only)
  /// Address of the environment it was made with (identity only, never dereferenced)
  const void* end_environment = nullptr;
  std::uint64_t end_environment_id = 0;  ///< that environment's instance id (0: none)
  Scalar end_winch_length = Scalar(0);   ///< TetherWorkspace::winch_length it used [m]
  /// \brief Positions (NED [m]) and velocities (NED [m/s]) of the kept end evaluation.
  ///@{
  Matrix3X<Scalar> end_position, end_velocity;
  ///@}
  /// Impulse the tether delivered to its attachment points over the last step (the step
  /// functions) or the last `advance` (summed over its sub-steps) [N s]: the end force weighted
  /// as the integrator weights the node forces in its momentum update (symplectic Euler h F(t),
  /// RK2 h F(t + h/2), RK4 h/6 (F₁ + 2F₂ + 2F₃ + F₄), implicit Euler and BDF2 h F(t + h)). A body
  /// that carries an end and receives exactly this impulse keeps the momentum of body and tether
  /// balanced whatever the integrator (kelp::system::step does so).
  EndForces<Scalar> end_impulse;
  /// Unstretched length of segment 0 the force evaluation uses [m] (0: the model's l): the
  /// steps copy TetherState::winch_length here before they evaluate forces (a winch at the
  /// start end; kelp/tether/winch.hpp). Set it by hand only to call compute_forces directly.
  Scalar winch_length = Scalar(0);

  TetherWorkspace() = default;
  /// \brief Buffers sized for `model`.
  /// \param model the tether the workspace serves (its node count only; no reference kept).
  explicit TetherWorkspace(const TetherModel<Scalar>& model) { resize(model.nodes()); }

  /// \brief (Re)allocates every buffer for `nodes` nodes (outside any step).
  /// \throws kelp::invalid_argument naming `nodes` unless it is in [2, limits::max_segments + 1]
  /// (a tether has at least one segment; the buffers are left as they were).
  /// \param nodes the node count N + 1 (TetherModel::nodes()).
  void resize(int nodes) {
    detail::check_node_count(nodes, "TetherWorkspace::resize");
    for_each_buffer(*this, nodes,
                    [](auto& m, Eigen::Index rows, Eigen::Index cols) { m.setZero(rows, cols); });
    entry_backup.resize(nodes);
    retry_backup.resize(nodes);
    water_is_zero = true;
    any_parted = false;
    any_contact = false;
    end_evaluated = false;
    segment_obstacle.setConstant(-1);
    clamp_start.setZero();
    clamp_end.setZero();
  }

  /// \brief True when every buffer has the size resize(nodes) gives it (false for a
  /// default-constructed workspace, one built for another tether, or one edited by hand). O(1).
  /// \param nodes the node count N + 1 to compare with.
  /// \return whether the workspace can serve a tether of `nodes` nodes.
  bool fits(int nodes) const {
    // Every size compared, without a branch per buffer (the force evaluation checks this at
    // every call): any difference leaves a bit set.
    Eigen::Index differ = 0;
    for_each_buffer(*this, nodes, [&differ](const auto& m, Eigen::Index rows, Eigen::Index cols) {
      differ |= (m.rows() ^ rows) | (m.cols() ^ cols);
    });
    return nodes >= 2 && differ == 0;
  }

 private:
  // Calls f(buffer, rows, cols) for every per-node and per-segment buffer of a workspace sized
  // for `nodes` nodes (Self: TetherWorkspace, const or not).
  template <typename Self, typename F>
  static void for_each_buffer(Self& w, int nodes, F&& f) {
    const Eigen::Index n = nodes, s = nodes - 1;
    // Buffers of one shape, unrolled (fits() runs at every force evaluation).
    const auto each = [&f](Eigen::Index rows, Eigen::Index cols, auto&... m) {
      (f(m, rows, cols), ...);
    };
    each(3, n, w.force, w.bending, w.acceleration, w.tangent, w.water_velocity,
         w.water_acceleration, w.rhs, w.rhs_true, w.delta, w.x0, w.v0, w.x1, w.v1, w.xs, w.vs,
         w.x_eval, w.v_eval, w.contact_force, w.end_position, w.end_velocity);
    each(n, 1, w.mass_iso, w.mass_tan, w.mass_iso_inv, w.mass_tan_ratio, w.seabed_force,
         w.friction_normal, w.submerged, w.node_kz, w.surface_elevation);
    f(w.direction, 3, s);
    each(s, 1, w.tension, w.stretched_length, w.seg_k_uu, w.seg_k_perp, w.seg_c_uu, w.seg_true_k_uu,
         w.seg_true_c_uu, w.seg_rate, w.seg_branch);
    f(w.node_dv, 6, n);
    f(w.node_kc, 6, n);
    f(w.segment_contact, s, 1);
    f(w.segment_obstacle, s, 1);
    f(w.pass_buffer, n, 15);
    f(w.block_inv, 17, n);
    f(w.newton_lu, 9, 5 * n);
    f(w.newton_factor, detail::newton_factor_size(nodes), 1);
    f(w.newton_branch, s, 1);
    f(w.parted, s, 1);
  }
};

namespace detail {

/// \throws kelp::invalid_argument unless `ws` was built for `model` (TetherWorkspace::fits).
template <typename Scalar>
void check_workspace(const TetherModel<Scalar>& model, const TetherWorkspace<Scalar>& ws) {
  KELP_CHECK(ws.fits(model.nodes()),
             "the workspace was not built for this tether: use TetherWorkspace(model)");
}

/// Copies the state's parted segments into the workspace (TetherWorkspace::parted), which the
/// force evaluation reads; a state without flags (empty) is an intact line. O(N) bytes.
template <typename Scalar>
void load_parted(const TetherState<Scalar>& state, TetherWorkspace<Scalar>& ws) {
  // Any flag set, 8 bytes at a time (Eigen's any() tests them one by one, every step).
  const auto any_set = [](const SegmentFlags& f) {
    const std::uint8_t* p = f.data();
    const Eigen::Index n = f.size();
    std::uint64_t bits = 0;
    Eigen::Index j = 0;
    for (; j + 8 <= n; j += 8) {
      std::uint64_t w;
      std::memcpy(&w, p + j, 8);
      bits |= w;
    }
    for (; j < n; ++j) bits |= p[j];
    return bits != 0;
  };
  if (state.parted.size() == ws.parted.size() && any_set(state.parted)) {
    ws.parted = state.parted;
    ws.any_parted = true;
  } else if (ws.any_parted) {
    ws.parted.setZero();
    ws.any_parted = false;
  }
}

/// Copies the boundary's clamp directions (EndMotion::direction, normalised; zero for a pinned
/// or free end) into the workspace (TetherWorkspace::clamp_start, clamp_end).
template <typename Scalar>
void load_clamps(const TetherModel<Scalar>& model, const TetherBoundary<Scalar>& b,
                 TetherWorkspace<Scalar>& ws) {
  const auto unit = [](const Vector3<Scalar>& d) -> Vector3<Scalar> {
    const Scalar n = d.norm();
    return n > Scalar(0) ? Vector3<Scalar>(d / n) : Vector3<Scalar>::Zero();
  };
  const TetherParameters<Scalar>& p = model.parameters();
  ws.clamp_start =
      p.start_mode == EndMode::kinematic ? unit(b.start.direction) : Vector3<Scalar>::Zero();
  ws.clamp_end = p.end_mode == EndMode::kinematic ? unit(b.end.direction) : Vector3<Scalar>::Zero();
}

/// True when segment 0 has its own unstretched length (a winch at the start end, see
/// TetherWorkspace::winch_length).
template <typename Scalar>
bool has_winch_segment(const TetherWorkspace<Scalar>& ws) {
  return ws.winch_length > Scalar(0);
}

/// Unstretched length [m], axial spring EA/l_s [N/m] and damper BA/l_s [N s/m] of segment s,
/// and the factor by which its rest length scales the dashpot's fade length (l_s/l): the
/// model's uniform values, or segment 0's at a winch (TetherWorkspace::winch_length).
template <typename Scalar>
struct SegmentSprings {
  Scalar l, ea_l, ba_l, scale;
};
template <typename Scalar>
SegmentSprings<Scalar> segment_springs(const TetherModel<Scalar>& model,
                                       const TetherWorkspace<Scalar>& ws, int s) {
  if (s == 0 && has_winch_segment(ws)) {
    const Scalar lw = ws.winch_length;
    const TetherParameters<Scalar>& p = model.parameters();
    return {lw, p.axial_stiffness / lw, p.internal_damping / lw, lw / model.segment_length()};
  }
  return {model.segment_length(), model.axial_spring(), model.axial_damper(), Scalar(1)};
}

/// The dashpot fade (TetherModel::dashpot_fade) of segment s at length l_s: its fade length
/// scales with the segment's rest length (segment 0 at a winch).
template <typename Scalar>
typename TetherModel<Scalar>::Fade segment_fade(const TetherModel<Scalar>& model,
                                                const TetherWorkspace<Scalar>& ws, int s,
                                                Scalar ls) {
  if (s != 0 || !has_winch_segment(ws)) return model.dashpot_fade(ls);
  const Scalar scale = ws.winch_length / model.segment_length();
  typename TetherModel<Scalar>::Fade f = model.dashpot_fade(ls / scale);
  f.slope /= scale;
  return f;
}

/// Extra line [m] lumped at node i by a winch segment of rest length `winch_length`
/// (TetherState::winch_length; 0: no winch): (l_w − l)/2 at nodes 0 and 1, 0 elsewhere.
template <typename Scalar>
Scalar winch_extra_length(const TetherModel<Scalar>& model, Scalar winch_length, int i) {
  if (i > 1 || !(winch_length > Scalar(0))) return Scalar(0);
  return Scalar(0.5) * (winch_length - model.segment_length());
}

/// Length of line lumped at node i [m] (TetherModel::node_length, with segment 0 of length
/// TetherWorkspace::winch_length at a winch: half of it at node 0 and at node 1).
template <typename Scalar>
Scalar node_length_at(const TetherModel<Scalar>& model, const TetherWorkspace<Scalar>& ws, int i) {
  if (i > 1 || !has_winch_segment(ws)) return model.node_length(i);
  return model.node_length(i) + winch_extra_length(model, ws.winch_length, i);
}

/// Structural mass [kg] and displaced volume [m³] of node i (as node_length_at).
template <typename Scalar>
Scalar node_mass_at(const TetherModel<Scalar>& model, const TetherWorkspace<Scalar>& ws, int i) {
  if (i > 1 || !has_winch_segment(ws)) return model.node_mass(i);
  return model.node_mass(i) +
         model.parameters().mass_per_length * (node_length_at(model, ws, i) - model.node_length(i));
}
template <typename Scalar>
Scalar node_volume_at(const TetherModel<Scalar>& model, const TetherWorkspace<Scalar>& ws, int i) {
  if (i > 1 || !has_winch_segment(ws)) return model.node_volume(i);
  return model.node_volume(i) +
         model.area() * (node_length_at(model, ws, i) - model.node_length(i));
}

/// Applies the prescribed end motion τ seconds into a step to the kinematic end nodes.
template <typename Scalar, typename DX, typename DV>
void apply_boundary(const TetherModel<Scalar>& model, const TetherBoundary<Scalar>& b, Scalar tau,
                    Eigen::MatrixBase<DX>& x, Eigen::MatrixBase<DV>& v) {
  const int n = model.segments();
  if (model.parameters().start_mode == EndMode::kinematic) {
    x.col(0) = b.start.position_at(tau);
    v.col(0) = b.start.velocity_at(tau);
  }
  if (model.parameters().end_mode == EndMode::kinematic) {
    x.col(n) = b.end.position_at(tau);
    v.col(n) = b.end.velocity_at(tau);
  }
}

}  // namespace detail

/// \brief Checks that a state fits the model and is finite (its history too, when it has one).
/// \throws kelp::invalid_argument naming `state.position` / `state.velocity` / `state.time` /
/// `state.winch_length` / `state.payout_rate` / `state.previous_position` /
/// `state.previous_velocity` / `state.previous_dt` / `state.acceleration` (or the sizes:
/// segments + 1 columns, `state.parted` empty or one flag per segment).
/// \tparam Scalar double or float.
/// \param model the tether the state must fit.
/// \param state the state checked (its winch fields, TetherState::winch_length and payout_rate,
/// finite; their ranges are the winch's and the steps' to check).
template <typename Scalar>
void check_state(const TetherModel<Scalar>& model, const TetherState<Scalar>& state) {
  KELP_CHECK(state.position.rows() == 3 && state.velocity.rows() == 3 &&
                 state.position.cols() == model.nodes() && state.velocity.cols() == model.nodes(),
             "state.position and state.velocity must have segments + 1 columns");
  check_all_finite(state.position, "state.position");
  check_all_finite(state.velocity, "state.velocity");
  check_finite(state.time, "state.time");
  check_finite(state.winch_length, "state.winch_length");
  check_finite(state.payout_rate, "state.payout_rate");
  check_non_negative(state.previous_dt, "state.previous_dt");
  KELP_CHECK(state.parted.size() == 0 || state.parted.size() == model.segments(),
             "state.parted must be empty or have one flag per segment");
  if (state.has_history()) {
    KELP_CHECK(state.previous_position.cols() == model.nodes() &&
                   state.previous_velocity.cols() == model.nodes(),
               "state.previous_position and state.previous_velocity must have segments + 1 "
               "columns when state.previous_dt > 0");
    check_all_finite(state.previous_position, "state.previous_position");
    check_all_finite(state.previous_velocity, "state.previous_velocity");
  }
  if (state.has_acceleration) {
    KELP_CHECK(state.acceleration.cols() == model.nodes(),
               "state.acceleration must have segments + 1 columns when state.has_acceleration");
    check_all_finite(state.acceleration, "state.acceleration");
  }
}

/// \brief Checks that the boundary motion is finite.
/// \tparam Scalar double or float.
/// \param b the boundary: every position, velocity, acceleration and direction of both ends
/// (also those of a free end, which the steps ignore).
/// \throws kelp::invalid_argument naming the field.
template <typename Scalar>
void check_boundary(const TetherBoundary<Scalar>& b) {
  check_all_finite(b.start.position, "boundary.start.position");
  check_all_finite(b.start.velocity, "boundary.start.velocity");
  check_all_finite(b.start.acceleration, "boundary.start.acceleration");
  check_all_finite(b.end.position, "boundary.end.position");
  check_all_finite(b.end.velocity, "boundary.end.velocity");
  check_all_finite(b.end.acceleration, "boundary.end.acceleration");
  check_all_finite(b.start.direction, "boundary.start.direction");
  check_all_finite(b.end.direction, "boundary.end.direction");
}

/// \brief Straight-line state: nodes evenly spaced from `start_ned` to `end_ned`, at rest.
/// \tparam Scalar double or float (deduced from the model).
/// \tparam D1 an Eigen 3-vector expression type.
/// \tparam D2 an Eigen 3-vector expression type.
/// \param model the tether.
/// \param start_ned node 0's position, NED [m].
/// \param end_ned node N's position, NED [m] (any distance: the line may start stretched or
/// slack).
/// \return a state at time 0 without history, an intact line, no winch.
/// \throws kelp::invalid_argument when either point is not finite.
template <typename Scalar, typename D1, typename D2>
TetherState<Scalar> straight_line_state(const TetherModel<Scalar>& model,
                                        const Eigen::MatrixBase<D1>& start_ned,
                                        const Eigen::MatrixBase<D2>& end_ned) {
  check_all_finite(start_ned, "start_ned");
  check_all_finite(end_ned, "end_ned");
  TetherState<Scalar> s(model);
  const int n = model.segments();
  const Vector3<Scalar> a(start_ned), b(end_ned);
  for (int i = 0; i <= n; ++i) s.position.col(i) = a + (Scalar(i) / Scalar(n)) * (b - a);
  return s;
}

/// \brief Double-precision state.
using TetherStated = TetherState<double>;
/// \brief Double-precision workspace.
using TetherWorkspaced = TetherWorkspace<double>;
/// \brief Double-precision boundary.
using TetherBoundaryd = TetherBoundary<double>;
/// \brief Single-precision state.
using TetherStatef = TetherState<float>;
/// \brief Single-precision workspace.
using TetherWorkspacef = TetherWorkspace<float>;
/// \brief Single-precision boundary.
using TetherBoundaryf = TetherBoundary<float>;

}  // namespace kelp::tether
