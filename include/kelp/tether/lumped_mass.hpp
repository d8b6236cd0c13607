/// \file
/// \brief Lumped-mass tether model: parameters, workspace, state, end conditions and the force
/// evaluation (axial tension, internal damping, optional bending stiffness, weight and buoyancy,
/// Morison drag, added mass, fluid-inertia forcing, seabed contact with friction).
///
/// The line of unstretched length L is cut into N segments of length l = L/N joined at N+1 nodes
/// (node 0 = start end, e.g. the ASV; node N = far end, e.g. the AUV). The model follows the
/// lumped-mass formulation of Hall & Goupee (2015, "Validation of a lumped-mass mooring line
/// model with DeepCwind semisubmersible model test data", Ocean Engineering 104) as implemented
/// in MoorDyn v2 (source/Line.cpp); the code is kelp's own. Two deliberate differences from
/// MoorDyn: the added mass enters through the kinetic energy (its rate of change included, so the
/// line is passive), and the axial force never pushes (see TetherParameters::compressive_damping).
///
/// Frames and units: world NED (z down, mean sea surface at z = 0, free surface at z = −ζ), SI.
/// Environments are duck-typed (`Env`): anything with `water_density()`, `gravity()`,
/// `seabed_depth()`, `surface_elevation(x, y, t)` and `sample_water(points, t, vel, acc)` as
/// `kelp::environment::Environment` has (its `sample_water(points, t, vel, acc, elevation)`, when
/// present, saves the per-node elevation queries).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>

#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/simd.hpp"
#include "kelp/core/types.hpp"

namespace kelp::tether {

/// \brief How a tether end moves.
enum class EndMode {
  /// Position and velocity prescribed each step (a fixed anchor or a point on a vehicle); the
  /// tether reports the force it exerts on that point.
  kinematic,
  /// The end node moves freely under the tether forces (optionally carrying a point mass).
  free
};

/// \brief Upper bounds of TetherParameters (validate() refuses values above them). Far above any
/// real tether (a 1 km, 150 mm steel mooring chain has 450 kg/m and EA 2e9 N), they keep every
/// force computed from the parameters finite.
namespace limits {
inline constexpr int max_segments = 100000;            ///< segments
inline constexpr double max_length = 1e5;              ///< length, seabed_damping_depth [m]
inline constexpr double min_segment_length = 1e-6;     ///< length / segments [m]
inline constexpr double max_diameter = 10.0;           ///< diameter [m]
inline constexpr double max_mass_per_length = 1e5;     ///< mass_per_length [kg/m]
inline constexpr double max_axial_stiffness = 1e13;    ///< EA [N], internal damping BA [N s]
inline constexpr double max_bending_stiffness = 1e12;  ///< EI [N m²]
inline constexpr double max_coefficient = 100.0;       ///< drag, added-mass, friction coefficients
inline constexpr double max_seabed_constant = 1e13;  ///< seabed stiffness [Pa/m], damping [Pa s/m]
inline constexpr double max_speed = 1e3;             ///< friction_velocity [m/s]
inline constexpr double max_point_mass = 1e9;        ///< end point masses [kg]
}  // namespace limits

/// \brief User-facing physical description of a lumped-mass tether (all magnitudes positive).
///
/// Defaults are a small ROV tether used as kelp's benchmark line (20 m, d 8 mm, 0.07 kg/m,
/// EA 1e5 N, Cdn 1.2, Cdt 0.008, Can 1) with 100 segments and MoorDyn's seabed constants
/// (MoorDyn v2 documentation: kBot 3e6 Pa/m, cBot 3e5 Pa s/m).
/// \tparam Scalar double or float.
template <typename Scalar>
struct TetherParameters {
  /// Number of segments N (≥ 1); the line has N + 1 nodes.
  int segments = 100;
  /// Unstretched length L [m].
  Scalar length = Scalar(20);
  /// Hydrodynamic (and volume-equivalent) diameter d [m].
  Scalar diameter = Scalar(0.008);
  /// Mass per unit unstretched length in air μ [kg/m].
  Scalar mass_per_length = Scalar(0.07);
  /// Axial stiffness EA [N].
  Scalar axial_stiffness = Scalar(1e5);
  /// Internal (axial) damping BA [N s]: the damping tension is BA · ε̇ (ε the strain). The total
  /// axial force EA·max(0, ε) + BA·ε̇ is clamped at zero, so a contracting segment never pushes
  /// (unless `compressive_damping`).
  Scalar internal_damping = Scalar(0);
  /// When true, the internal dashpot acts in compression too, as in MoorDyn v2 (Line.cpp: the
  /// damping tension is added whether or not the segment is stretched, and the sum is not
  /// clamped): use it to reproduce MoorDyn. Default false: a cable cannot push, so the total
  /// axial force is max(0, EA·max(0, ε) + BA·ε̇).
  bool compressive_damping = false;
  /// Bending stiffness EI [N m²] (0: a perfectly flexible line). Discrete bending energy
  /// EI/l · (1 − u_{i−1}·u_i) at each interior node, i.e. ½ EI κ² l for small angles with
  /// κ = θ/l. Enters the implicit schemes through the residual only (not the Jacobian: it would
  /// couple nodes i−1 and i+1), so keep EI/l³ ≪ node mass / dt² there; the explicit stable-dt
  /// estimate accounts for it.
  Scalar bending_stiffness = Scalar(0);
  /// Normal drag coefficient Cdn [-] (on the projected area d·l).
  Scalar normal_drag = Scalar(1.2);
  /// Tangential drag coefficient Cdt [-] (on the wetted surface π·d·l, as MoorDyn does).
  Scalar tangential_drag = Scalar(0.008);
  /// Normal added-mass coefficient Can [-].
  Scalar normal_added_mass = Scalar(1);
  /// Tangential added-mass coefficient Cat [-].
  Scalar tangential_added_mass = Scalar(0);
  /// Seabed stiffness kb [Pa/m] = [N/m³]: contact force per node (z − h)·kb·d·l_i
  /// (MoorDyn's default 3e6).
  Scalar seabed_stiffness = Scalar(3e6);
  /// Seabed damping cb [Pa s/m]: contact damping ż·cb·d·l_i while in contact (MoorDyn's 3e5).
  Scalar seabed_damping = Scalar(3e5);
  /// Penetration [m] over which the seabed damping ramps up from zero at first touch to its full
  /// value, so that the normal contact force is continuous (MoorDyn switches the damping on at
  /// once, a force step of cb·d·l_i·ż at touchdown that leaves Newton's method nothing to
  /// converge to when a node lands in a step; 0 reproduces it).
  Scalar seabed_damping_depth = Scalar(1e-3);
  /// Seabed Coulomb friction coefficient μ_f [-] (0 disables friction).
  Scalar seabed_friction = Scalar(0);
  /// Horizontal speed [m/s] below which seabed friction is viscous (saturated-viscous model).
  Scalar friction_velocity = Scalar(0.01);
  /// Motion of the start end (node 0).
  EndMode start_mode = EndMode::kinematic;
  /// Motion of the far end (node N).
  EndMode end_mode = EndMode::kinematic;
  /// Extra point mass lumped at node 0 [kg], used only when the start end is free (a kinematic
  /// end's mass belongs to the body that moves it, so it is not reported as tether load).
  Scalar start_point_mass = Scalar(0);
  /// Extra point mass lumped at node N [kg], used only when the far end is free (see
  /// start_point_mass).
  Scalar end_point_mass = Scalar(0);
};

/// \brief Checks tether parameters.
/// \throws kelp::invalid_argument naming the offending field: segments in [1, 100000]; length,
/// diameter, mass_per_length, axial_stiffness, friction_velocity finite and > 0; the rest finite
/// and ≥ 0; every magnitude at most its bound in kelp::tether::limits; segments at least 1 µm
/// long; end modes EndMode values.
template <typename Scalar>
void validate(const TetherParameters<Scalar>& p) {
  // Each magnitude finite and of the right sign, then below a generous physical bound (far above
  // any cable, chain or umbilical, so that the forces computed from them cannot overflow).
  const auto bounded = [](const Scalar& x, double bound, const char* name, bool zero_ok) {
    if (zero_ok)
      check_non_negative(x, name);
    else
      check_positive(x, name);
    check_at_most(x, bound, name);
  };
  KELP_CHECK(p.segments >= 1 && p.segments <= limits::max_segments,
             "segments must be in [1, " + std::to_string(limits::max_segments) + "]");
  bounded(p.length, limits::max_length, "length", false);
  bounded(p.diameter, limits::max_diameter, "diameter", false);
  bounded(p.mass_per_length, limits::max_mass_per_length, "mass_per_length", false);
  bounded(p.axial_stiffness, limits::max_axial_stiffness, "axial_stiffness", false);
  bounded(p.internal_damping, limits::max_axial_stiffness, "internal_damping", true);
  bounded(p.bending_stiffness, limits::max_bending_stiffness, "bending_stiffness", true);
  bounded(p.normal_drag, limits::max_coefficient, "normal_drag", true);
  bounded(p.tangential_drag, limits::max_coefficient, "tangential_drag", true);
  bounded(p.normal_added_mass, limits::max_coefficient, "normal_added_mass", true);
  bounded(p.tangential_added_mass, limits::max_coefficient, "tangential_added_mass", true);
  bounded(p.seabed_stiffness, limits::max_seabed_constant, "seabed_stiffness", true);
  bounded(p.seabed_damping, limits::max_seabed_constant, "seabed_damping", true);
  bounded(p.seabed_damping_depth, limits::max_length, "seabed_damping_depth", true);
  bounded(p.seabed_friction, limits::max_coefficient, "seabed_friction", true);
  bounded(p.friction_velocity, limits::max_speed, "friction_velocity", false);
  bounded(p.start_point_mass, limits::max_point_mass, "start_point_mass", true);
  bounded(p.end_point_mass, limits::max_point_mass, "end_point_mass", true);
  // Segments shorter than this make EA/l and the stable explicit step absurd.
  check_at_least(p.length / Scalar(p.segments), limits::min_segment_length,
                 "length / segments (the segment length)");
  KELP_CHECK(p.start_mode == EndMode::kinematic || p.start_mode == EndMode::free,
             "start_mode must be EndMode::kinematic or EndMode::free");
  KELP_CHECK(p.end_mode == EndMode::kinematic || p.end_mode == EndMode::free,
             "end_mode must be EndMode::kinematic or EndMode::free");
}

/// \brief Validated tether parameters with the per-step constants precomputed.
///
/// Build once from `TetherParameters`; constant afterwards.
/// \tparam Scalar double or float.
template <typename Scalar>
class TetherModel {
 public:
  /// \brief Validates `p` (see validate(const TetherParameters&)) and precomputes constants.
  /// \throws kelp::invalid_argument naming the offending field.
  explicit TetherModel(const TetherParameters<Scalar>& p) : p_(p) {
    validate(p);
    const int n = p.segments;
    const Scalar N = Scalar(n);
    l_ = p.length / N;
    inv_l_ = Scalar(1) / l_;
    ea_over_l_ = p.axial_stiffness / l_;
    ba_over_l_ = p.internal_damping / l_;
    area_ = Scalar(kelp::pi) * p.diameter * p.diameter / Scalar(4);
    node_mass_.resize(n + 1);
    node_volume_.resize(n + 1);
    node_length_.resize(n + 1);
    for (int i = 0; i <= n; ++i) {
      const Scalar li = (i == 0 || i == n) ? l_ / Scalar(2) : l_;
      node_length_(i) = li;
      node_mass_(i) = p.mass_per_length * li;
      node_volume_(i) = area_ * li;
    }
    if (p.start_mode == EndMode::free) node_mass_(0) += p.start_point_mass;
    if (p.end_mode == EndMode::free) node_mass_(n) += p.end_point_mass;
    min_node_mass_ = node_mass_.minCoeff();
    first_free_ = p.start_mode == EndMode::kinematic ? 1 : 0;
    last_free_ = p.end_mode == EndMode::kinematic ? n - 1 : n;
  }

  /// \brief The parameters the model was built from.
  const TetherParameters<Scalar>& parameters() const { return p_; }
  /// \brief Number of segments N.
  int segments() const { return p_.segments; }
  /// \brief Number of nodes N + 1.
  int nodes() const { return p_.segments + 1; }
  /// \brief Unstretched segment length l = L/N [m].
  Scalar segment_length() const { return l_; }
  /// \brief 1/l [1/m].
  Scalar inverse_segment_length() const { return inv_l_; }
  /// \brief EA/l [N/m]: the axial spring constant of one segment.
  Scalar axial_spring() const { return ea_over_l_; }
  /// \brief BA/l [N s/m]: the axial damper constant of one segment.
  Scalar axial_damper() const { return ba_over_l_; }
  /// \brief Cross-section area A = π d²/4 [m²].
  Scalar area() const { return area_; }
  /// \brief Structural mass of node i [kg] (μ times its share of length, plus the point mass of a
  /// free end).
  Scalar node_mass(int i) const { return node_mass_(i); }
  /// \brief Smallest structural node mass [kg]: a lower bound on every eigenvalue of every node
  /// mass matrix (added mass only adds to it).
  Scalar min_node_mass() const { return min_node_mass_; }
  /// \brief Displaced volume of node i [m³] (A times its share of length).
  Scalar node_volume(int i) const { return node_volume_(i); }
  /// \brief Length of line lumped at node i [m] (l, or l/2 at the ends).
  Scalar node_length(int i) const { return node_length_(i); }
  /// \brief Index of the first node integrated (0 if the start end is free, else 1).
  int first_free_node() const { return first_free_; }
  /// \brief Index of the last node integrated (N if the far end is free, else N − 1).
  int last_free_node() const { return last_free_; }
  /// \brief Submerged weight per unit length w = (μ − ρA) g [N/m] (negative: buoyant line).
  Scalar submerged_weight_per_length(Scalar water_density, Scalar gravity) const {
    return (p_.mass_per_length - water_density * area_) * gravity;
  }

 private:
  TetherParameters<Scalar> p_;
  Scalar l_, inv_l_, ea_over_l_, ba_over_l_, area_, min_node_mass_;
  VectorX<Scalar> node_mass_, node_volume_, node_length_;
  int first_free_ = 1, last_free_ = 0;
};

/// \brief Everything that determines the tether's next step: positions and velocities of all
/// N + 1 nodes (NED), the clock, and the integrator history (BDF2's previous step, also the
/// implicit schemes' velocity predictor).
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

  TetherState() = default;
  /// \brief Zero state sized for `model`, no history.
  explicit TetherState(const TetherModel<Scalar>& model)
      : position(Matrix3X<Scalar>::Zero(3, model.nodes())),
        velocity(Matrix3X<Scalar>::Zero(3, model.nodes())),
        previous_position(Matrix3X<Scalar>::Zero(3, model.nodes())),
        previous_velocity(Matrix3X<Scalar>::Zero(3, model.nodes())) {}

  /// \brief True when the state carries the previous step (BDF2 history).
  bool has_history() const { return previous_dt > 0.0; }
  /// \brief Forgets the integrator history: the next implicit step starts with backward Euler.
  /// Call it after editing `position` or `velocity` by hand.
  void clear_history() { previous_dt = 0.0; }
};

/// \brief Motion of a kinematic end point over a step, NED.
///
/// Within a step of length h starting at t₀ the end is taken at p + v τ + ½ a τ², with velocity
/// v + a τ (τ = t − t₀).
template <typename Scalar>
struct EndMotion {
  /// Position at the start of the step, NED [m].
  Vector3<Scalar> position = Vector3<Scalar>::Zero();
  /// Velocity, NED [m/s].
  Vector3<Scalar> velocity = Vector3<Scalar>::Zero();
  /// Acceleration, NED [m/s²] (also enters the end force through the end node's inertia).
  Vector3<Scalar> acceleration = Vector3<Scalar>::Zero();

  /// \brief Position τ seconds into the step.
  Vector3<Scalar> position_at(Scalar tau) const {
    return position + tau * velocity + (Scalar(0.5) * tau * tau) * acceleration;
  }
  /// \brief Velocity τ seconds into the step.
  Vector3<Scalar> velocity_at(Scalar tau) const { return velocity + tau * acceleration; }
  /// \brief The same motion seen from τ seconds into the step (position and velocity at τ).
  EndMotion after(Scalar tau) const { return {position_at(tau), velocity_at(tau), acceleration}; }
};

/// \brief Prescribed motion of both ends (an entry is ignored when that end is free).
template <typename Scalar>
struct TetherBoundary {
  /// Node 0 (start, e.g. the ASV attachment point).
  EndMotion<Scalar> start;
  /// Node N (far end, e.g. the AUV attachment point).
  EndMotion<Scalar> end;

  /// \brief The same end motions seen from τ seconds into the step (for sub-steps).
  TetherBoundary after(Scalar tau) const { return {start.after(tau), end.after(tau)}; }
  /// \brief Both ends fixed at the given NED points [m].
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
template <typename Scalar>
struct EndForces {
  /// On the start attachment point (node 0).
  Vector3<Scalar> on_start = Vector3<Scalar>::Zero();
  /// On the far attachment point (node N).
  Vector3<Scalar> on_end = Vector3<Scalar>::Zero();
};

/// \brief A copy of a TetherState kept in preallocated buffers (no allocation when saved or
/// restored once sized), so that a failed driver or step can put the state back bit for bit.
template <typename Scalar>
struct StateBackup {
  Matrix3X<Scalar> position, velocity, previous_position, previous_velocity;
  double time = 0.0, time_carry = 0.0, previous_dt = 0.0;

  /// \brief Sizes the buffers for `nodes` nodes.
  void resize(int nodes) {
    for (Matrix3X<Scalar>* m : {&position, &velocity, &previous_position, &previous_velocity})
      m->setZero(3, nodes);
  }
  /// \brief Copies `s` (history included).
  void save(const TetherState<Scalar>& s) {
    position = s.position;
    velocity = s.velocity;
    previous_position = s.previous_position;
    previous_velocity = s.previous_velocity;
    time = s.time;
    time_carry = s.time_carry;
    previous_dt = s.previous_dt;
  }
  /// \brief Puts the saved state back into `s`.
  void restore(TetherState<Scalar>& s) const {
    s.position = position;
    s.velocity = velocity;
    s.previous_position = previous_position;
    s.previous_velocity = previous_velocity;
    s.time = time;
    s.time_carry = time_carry;
    s.previous_dt = previous_dt;
  }
};

/// \brief Preallocated mutable buffers for force evaluation and integration (Pinocchio's `Data`).
///
/// Built from a model; every step reuses these buffers, so no heap allocation happens in a step.
/// Fields are public so that tests and diagnostics can read intermediate quantities; their
/// content is valid after the last force evaluation.
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
  // --- linear solver and integrator buffers ----------------------------------------------------
  /// What the block elimination of the Newton solve keeps for its back substitution, two
  /// columns per elimination step (detail::solve_block_tridiagonal)
  Eigen::Matrix<Scalar, 17, Eigen::Dynamic> block_inv;
  Matrix3X<Scalar> rhs, delta;    ///< Newton right-hand side and correction
  Matrix3X<Scalar> rhs_true;      ///< −R saved while the active-set passes modify rhs
  VectorX<Scalar> seg_true_k_uu;  ///< seg_k_uu saved while the active-set passes modify it
  VectorX<Scalar> seg_true_c_uu;  ///< seg_c_uu saved while the active-set passes modify it
  VectorX<Scalar> seg_rate;       ///< segment stretch rate u_s·(v_{s+1} − v_s) [m/s]
  /// Branch of segment s in the Newton step's linear model: 0 no force (slack, or clamped at
  /// zero), 1 dashpot only (slack), 2 elastic plus dashpot (taut)
  VectorX<Scalar> seg_branch;
  Matrix3X<Scalar> x0, v0, x1, v1, xs, vs;  ///< integrator stages and Newton/line-search iterates
  /// compute_forces' scratch, one contiguous column per component: T_s u_s of each segment
  /// (columns 0–2), each node's force before the added-mass coupling to its neighbours (3–5),
  /// and that coupling term (6–8)
  Eigen::Matrix<Scalar, Eigen::Dynamic, 9> pass_buffer;
  /// Copies of positions and velocities given to compute_forces as expressions rather than as
  /// column-major storage
  Matrix3X<Scalar> x_eval, v_eval;
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
  EndForces<Scalar> end_forces;  ///< forces on the attachment points after the last step
  /// Impulse the tether delivered to its attachment points over the last step (the step
  /// functions) or the last `advance` (summed over its sub-steps) [N s]: the end force weighted
  /// as the integrator weights the node forces in its momentum update (symplectic Euler h F(t),
  /// RK2 h F(t + h/2), RK4 h/6 (F₁ + 2F₂ + 2F₃ + F₄), implicit Euler and BDF2 h F(t + h)). A body
  /// that carries an end and receives exactly this impulse keeps the momentum of body and tether
  /// balanced whatever the integrator (kelp::system::step does so).
  EndForces<Scalar> end_impulse;

  TetherWorkspace() = default;
  /// \brief Buffers sized for `model`.
  explicit TetherWorkspace(const TetherModel<Scalar>& model) { resize(model.nodes()); }

  /// \brief (Re)allocates every buffer for `nodes` nodes (outside any step).
  void resize(int nodes) {
    for_each_buffer(*this, nodes,
                    [](auto& m, Eigen::Index rows, Eigen::Index cols) { m.setZero(rows, cols); });
    entry_backup.resize(nodes);
    retry_backup.resize(nodes);
    water_is_zero = true;
  }

  /// \brief True when every buffer has the size resize(nodes) gives it (false for a
  /// default-constructed workspace, one built for another tether, or one edited by hand). O(1).
  bool fits(int nodes) const {
    bool ok = nodes >= 2;
    for_each_buffer(*this, nodes, [&ok](const auto& m, Eigen::Index rows, Eigen::Index cols) {
      ok = ok && m.rows() == rows && m.cols() == cols;
    });
    return ok;
  }

 private:
  // Calls f(buffer, rows, cols) for every per-node and per-segment buffer of a workspace sized
  // for `nodes` nodes (Self: TetherWorkspace, const or not).
  template <typename Self, typename F>
  static void for_each_buffer(Self& w, int nodes, F&& f) {
    const Eigen::Index n = nodes, s = nodes - 1;
    for (auto* m : {&w.force, &w.bending, &w.acceleration, &w.tangent, &w.water_velocity,
                    &w.water_acceleration, &w.rhs, &w.rhs_true, &w.delta, &w.x0, &w.v0, &w.x1,
                    &w.v1, &w.xs, &w.vs, &w.x_eval, &w.v_eval})
      f(*m, 3, n);
    for (auto* v : {&w.mass_iso, &w.mass_tan, &w.mass_iso_inv, &w.mass_tan_ratio, &w.seabed_force,
                    &w.friction_normal, &w.submerged, &w.node_kz, &w.surface_elevation})
      f(*v, n, 1);
    f(w.direction, 3, s);
    for (auto* v : {&w.tension, &w.stretched_length, &w.seg_k_uu, &w.seg_k_perp, &w.seg_c_uu,
                    &w.seg_true_k_uu, &w.seg_true_c_uu, &w.seg_rate, &w.seg_branch})
      f(*v, s, 1);
    f(w.node_dv, 6, n);
    f(w.pass_buffer, n, 9);
    f(w.block_inv, 17, n);
  }
};

namespace detail {

/// \throws kelp::invalid_argument unless `ws` was built for `model` (TetherWorkspace::fits).
template <typename Scalar>
void check_workspace(const TetherModel<Scalar>& model, const TetherWorkspace<Scalar>& ws) {
  KELP_CHECK(ws.fits(model.nodes()),
             "the workspace was not built for this tether: use TetherWorkspace(model)");
}

/// True for environments that can say they are still water at all times through
/// `bool is_still_water() const`, as kelp::environment::Environment can. Other environments are
/// always queried.
template <typename Env, typename = void>
struct has_still_water_query : std::false_type {};
template <typename Env>
struct has_still_water_query<
    Env, std::void_t<decltype(bool(std::declval<const Env&>().is_still_water()))>>
    : std::true_type {};

/// True for environments that sample the free-surface elevation along with the water
/// kinematics: `sample_water(points, t, velocity, acceleration, elevation)`, as
/// kelp::environment::Environment can. Other environments are asked `surface_elevation(x, y, t)`
/// node by node.
template <typename Env, typename Scalar, typename = void>
struct has_batch_surface : std::false_type {};
template <typename Env, typename Scalar>
struct has_batch_surface<
    Env, Scalar,
    std::void_t<decltype(std::declval<const Env&>().sample_water(
        std::declval<const Matrix3X<Scalar>&>(), 0.0, std::declval<Matrix3X<Scalar>&>(),
        std::declval<Matrix3X<Scalar>&>(), std::declval<VectorX<Scalar>&>()))>> : std::true_type {};

/// Water velocity, acceleration and surface elevation at the points `x` into the workspace.
template <typename Scalar, typename Env, typename DX>
void sample_water_at_nodes(const Env& env, const Eigen::MatrixBase<DX>& x, double t,
                           TetherWorkspace<Scalar>& ws) {
  if constexpr (has_batch_surface<Env, Scalar>::value) {
    env.sample_water(x, t, ws.water_velocity, ws.water_acceleration, ws.surface_elevation);
  } else {
    env.sample_water(x, t, ws.water_velocity, ws.water_acceleration);
    for (Eigen::Index i = 0; i < x.cols(); ++i)
      ws.surface_elevation(i) = Scalar(env.surface_elevation(x(0, i), x(1, i), t));
  }
}

/// True when `env` reports still water: its water velocity and acceleration are zero everywhere
/// and at all times.
template <typename Env>
bool is_still_water(const Env& env) {
  if constexpr (has_still_water_query<Env>::value)
    return env.is_still_water();
  else
    return false;
}

/// Tangent of node i of a line of n segments: the chord c = r_{i+1} − r_{i−1} inside (the
/// adjacent segment at the ends), 1/|c|² and 1/|c| (both zero for a zero chord) and the unit
/// tangent q = c/|c| (zero for a zero chord).
template <typename Scalar>
struct NodeTangent {
  Vector3<Scalar> chord;
  Scalar inv_c2, inv_c;
  Vector3<Scalar> q;
};

/// The NodeTangent of node i of positions `x` (3 × (n+1)).
template <typename Scalar, typename DX>
NodeTangent<Scalar> node_tangent(const Eigen::MatrixBase<DX>& x, int i, int n) {
  using std::sqrt;
  NodeTangent<Scalar> t;
  t.chord = x.col(i < n ? i + 1 : n) - x.col(i > 0 ? i - 1 : 0);
  const Scalar c2 = t.chord.squaredNorm();
  t.inv_c2 = c2 > Scalar(0) ? Scalar(1) / c2 : Scalar(0);
  t.inv_c = sqrt(t.inv_c2);
  t.q = t.chord * t.inv_c;
  return t;
}

/// Submerged fraction φ of a node at NED depth z [m] under a free surface at elevation ζ [m]:
/// the cable's cross-section of diameter D goes under over one diameter, taken as a linear ramp
/// φ = clamp(1 + (z + ζ)/D, 0, 1) (1: wet, a node at the surface included; 0: in air, at least
/// one diameter above the surface). Buoyancy, drag, fluid inertia and
/// added mass scale with φ, so the node forces are continuous in the positions (an on/off switch
/// at the surface would leave Newton's method no solution to converge to when a floating line
/// rests at the surface).
template <typename Scalar>
Scalar submerged_fraction(Scalar z, Scalar zeta, Scalar diameter,
                          Scalar inv_diameter = Scalar(-1)) {
  if (inv_diameter < Scalar(0)) inv_diameter = Scalar(1) / diameter;
  const Scalar f = Scalar(1) + (z + zeta) * inv_diameter;
  return f >= Scalar(1) ? Scalar(1) : (f > Scalar(0) ? f : Scalar(0));
}

/// Antiderivative Φ of submerged_fraction in the depth d = z + ζ, zero in air and d + D/2 when
/// wet: the buoyancy potential of a node is −ρ V g Φ [J].
template <typename Scalar>
Scalar submerged_depth_integral(Scalar z, Scalar zeta, Scalar diameter) {
  const Scalar d = z + zeta;
  if (d >= Scalar(0)) return d + Scalar(0.5) * diameter;
  if (d <= -diameter) return Scalar(0);
  return (d + diameter) * (d + diameter) / (Scalar(2) * diameter);
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

namespace detail {

/// Constants of one kind of node (start, interior, end) for compute_forces: fully wet, or
/// scaled to a submerged fraction φ.
template <typename Scalar>
struct NodeConstants {
  Scalar li, dry_weight, wet_weight, rho_vol, kn, kt, mass_dry, mass_iso_wet, mass_tan_wet;
  /// The constants of a node with submerged fraction φ (fluid terms scaled by φ).
  NodeConstants submerged(Scalar phi) const {
    NodeConstants c = *this;
    c.wet_weight = dry_weight + phi * (wet_weight - dry_weight);
    c.rho_vol = phi * rho_vol;
    c.kn = phi * kn;
    c.kt = phi * kt;
    c.mass_iso_wet = mass_dry + phi * (mass_iso_wet - mass_dry);
    c.mass_tan_wet = phi * mass_tan_wet;
    return c;
  }
};

/// Everything compute_forces' passes share: the environment's and the model's constants of one
/// evaluation, the node kinds (0 start, 1 interior, 2 end), and where the positions and
/// velocities are (column-major 3 × (N+1) with the given column strides).
template <typename Scalar>
struct ForcePass {
  const TetherParameters<Scalar>* p;
  int n;
  Scalar rho, g, bed, l, l2, inv_l, ea_l, ba_l, ea, ba, can, cat, inv_d, bed_k, bed_c;
  bool clamp, damping, still, bending, mass_turns;
  NodeConstants<Scalar> kinds[3];
  const Scalar* x;
  Eigen::Index xs;
  const Scalar* v;
  Eigen::Index vs;
  /// When set: M⁻¹F of every node is written here as well (3 × (N+1), column-major).
  Scalar* acc = nullptr;
  Scalar X(int k, int i) const { return x[i * xs + k]; }
  Scalar V(int k, int i) const { return v[i * vs + k]; }
  /// The positions as a 3 × (N+1) matrix.
  Eigen::Map<const Matrix3X<Scalar>, 0, Eigen::OuterStride<>> positions() const {
    return {x, 3, n + 1, Eigen::OuterStride<>(xs)};
  }
};

/// Columns of TetherWorkspace::pass_buffer.
enum PassColumn : int { kSegmentForce = 0, kNodeForce = 3, kMassRate = 6 };

/// ForcePass constants broadcast to every lane once per evaluation (the kernels run in loops
/// that would otherwise broadcast them block after block).
template <typename Scalar, bool Wide>
struct PackedConstants {
  using P = simd::Pack<Scalar, Wide>;
  P zero, one, two, l, l2, inv_l, ea, ea_l, ba, ba_l, bed, wet_weight, kn, kt, rho_vol,
      one_plus_can, cat_minus_can, mass_iso_wet, mass_tan_wet, mass_iso_inv, mass_tan_ratio;
  explicit PackedConstants(const ForcePass<Scalar>& c) {
    const NodeConstants<Scalar>& nc = c.kinds[1];
    zero = P::all(Scalar(0));
    one = P::all(Scalar(1));
    two = P::all(Scalar(2));
    l = P::all(c.l);
    l2 = P::all(c.l2);
    inv_l = P::all(c.inv_l);
    ea = P::all(c.ea);
    ea_l = P::all(c.ea_l);
    ba = P::all(c.ba);
    ba_l = P::all(c.ba_l);
    bed = P::all(c.bed);
    wet_weight = P::all(nc.wet_weight);
    kn = P::all(nc.kn);
    kt = P::all(nc.kt);
    rho_vol = P::all(nc.rho_vol);
    one_plus_can = P::all(Scalar(1) + c.can);
    cat_minus_can = P::all(c.cat - c.can);
    mass_iso_wet = P::all(nc.mass_iso_wet);
    mass_tan_wet = P::all(nc.mass_tan_wet);
    mass_iso_inv = P::all(Scalar(1) / nc.mass_iso_wet);
    mass_tan_ratio = P::all(nc.mass_tan_wet / (nc.mass_iso_wet + nc.mass_tan_wet));
  }
};

/// Segments s … s + lanes − 1 (see compute_forces): length, direction, axial force T_s (elastic
/// EA·ε when stretched plus the dashpot BA·ε̇ at any length, clamped at zero unless
/// compressive_damping), T_s u_s into the pass buffer, and the Jacobian terms.
template <bool WithJacobian, bool Wide, typename Scalar>
EIGEN_ALWAYS_INLINE void segment_block(const ForcePass<Scalar>& c,
                                       const PackedConstants<Scalar, Wide>& pc,
                                       TetherWorkspace<Scalar>& ws, int s) {
  using P = simd::Pack<Scalar, Wide>;
  const P zero = pc.zero;
  const Scalar* a = c.x + s * c.xs;
  const P d0 = P::gather(a + c.xs, c.xs) - P::gather(a, c.xs);
  const P d1 = P::gather(a + c.xs + 1, c.xs) - P::gather(a + 1, c.xs);
  const P d2 = P::gather(a + c.xs + 2, c.xs) - P::gather(a + 2, c.xs);
  const P ls2 = (d0 * d0 + d1 * d1) + d2 * d2;
  const P ls = sqrt(ls2);
  const auto positive = simd::greater(ls, zero);
  const P inv_ls = simd::select(positive, pc.one / ls, zero);
  const P u0 = d0 * inv_ls, u1 = d1 * inv_ls, u2 = d2 * inv_ls;
  const auto stretched = simd::greater(ls2, pc.l2);
  P tension = simd::select(stretched, (pc.ea * (ls - pc.l)) * pc.inv_l, zero);
  P k_axial = simd::select(stretched, pc.ea_l, zero);
  P c_axial = pc.ba_l;
  P rate = zero;
  if (c.damping) {
    const Scalar* b = c.v + s * c.vs;
    const P e0 = P::gather(b + c.vs, c.vs) - P::gather(b, c.vs);
    const P e1 = P::gather(b + c.vs + 1, c.vs) - P::gather(b + 1, c.vs);
    const P e2 = P::gather(b + c.vs + 2, c.vs) - P::gather(b + 2, c.vs);
    rate = (u0 * e0 + u1 * e1) + u2 * e2;
    tension += (pc.ba * rate) * pc.inv_l;
    if (c.clamp) {
      // A zero-length segment keeps its dashpot slope (its force is zero either way).
      const auto keep = simd::greater(tension, zero);
      tension = simd::select(keep, tension, zero);
      k_axial = simd::select(keep, k_axial, zero);
      c_axial = simd::select(keep || simd::greater_equal(zero, ls), c_axial, zero);
    }
  }
  ls.store(&ws.stretched_length(s));
  tension.store(&ws.tension(s));
  Scalar* dir = ws.direction.data() + 3 * s;
  u0.scatter(dir, 3);
  u1.scatter(dir + 1, 3);
  u2.scatter(dir + 2, 3);
  (tension * u0).store(&ws.pass_buffer(s, kSegmentForce));
  (tension * u1).store(&ws.pass_buffer(s, kSegmentForce + 1));
  (tension * u2).store(&ws.pass_buffer(s, kSegmentForce + 2));
  if constexpr (WithJacobian) {
    // ∂(T u)/∂x_{s+1} = k_axial u uᵀ + (T/l_s)(I − u uᵀ); the geometric term is kept only for
    // T > 0 so that the Jacobian stays positive semi-definite.
    const P k_perp = simd::select(simd::greater(tension, zero), tension * inv_ls, zero);
    (k_axial - k_perp).store(&ws.seg_k_uu(s));
    k_perp.store(&ws.seg_k_perp(s));
    c_axial.store(&ws.seg_c_uu(s));
    rate.store(&ws.seg_rate(s));
  }
}

/// Interior nodes i … i + lanes − 1 (1 ≤ i, i + lanes ≤ N) when all of them are below the
/// surface band and off the seabed (returns false, writing nothing, otherwise): tangent, node
/// force without the added-mass coupling to the neighbours, that coupling term w_i, masses and
/// the Jacobian terms. The same arithmetic as node_general for such nodes.
template <bool WithJacobian, bool Wide, typename Scalar>
EIGEN_ALWAYS_INLINE bool interior_block(const ForcePass<Scalar>& c,
                                        const PackedConstants<Scalar, Wide>& pc,
                                        TetherWorkspace<Scalar>& ws, int i) {
  using P = simd::Pack<Scalar, Wide>;
  const P zero = pc.zero;
  const Scalar* a = c.x + i * c.xs;
  const P z = P::gather(a + 2, c.xs);
  if (c.still) {
    if (simd::any(simd::less(z, zero) || simd::greater(z - pc.bed, zero))) return false;
  } else {
    const P zeta = P::load(&ws.surface_elevation(i));
    if (simd::any(simd::less(z + zeta, zero) || simd::greater(z - pc.bed, zero))) return false;
  }
  const P c0 = P::gather(a + c.xs, c.xs) - P::gather(a - c.xs, c.xs);
  const P c1 = P::gather(a + c.xs + 1, c.xs) - P::gather(a - c.xs + 1, c.xs);
  const P c2 = P::gather(a + c.xs + 2, c.xs) - P::gather(a - c.xs + 2, c.xs);
  const P cc = (c0 * c0 + c1 * c1) + c2 * c2;
  const P inv_c2 = simd::select(simd::greater(cc, zero), pc.one / cc, zero);
  const P inv_c = sqrt(inv_c2);
  const P q0 = c0 * inv_c, q1 = c1 * inv_c, q2 = c2 * inv_c;
  Scalar* tan = ws.tangent.data() + 3 * i;
  q0.scatter(tan, 3);
  q1.scatter(tan + 1, 3);
  q2.scatter(tan + 2, 3);
  const Scalar* tu = &ws.pass_buffer(i, kSegmentForce);
  const Eigen::Index col = ws.pass_buffer.rows();
  P f0 = P::load(tu) - P::load(tu - 1);
  P f1 = P::load(tu + col) - P::load(tu + col - 1);
  P f2 = P::load(tu + 2 * col) - P::load(tu + 2 * col - 1);
  f2 += pc.wet_weight;
  // Morison drag on the relative velocity, split along the chord.
  const Scalar* vi = c.v + i * c.vs;
  const Scalar* wi = ws.water_velocity.data() + 3 * i;
  const P vr0 = P::gather(wi, 3) - P::gather(vi, c.vs);
  const P vr1 = P::gather(wi + 1, 3) - P::gather(vi + 1, c.vs);
  const P vr2 = P::gather(wi + 2, 3) - P::gather(vi + 2, c.vs);
  const P vc = (vr0 * c0 + vr1 * c1) + vr2 * c2;
  const P sc = vc * inv_c2;
  const P vn0 = vr0 - sc * c0, vn1 = vr1 - sc * c1, vn2 = vr2 - sc * c2;
  const P vn_abs = sqrt((vn0 * vn0 + vn1 * vn1) + vn2 * vn2);
  const P vq = vc * inv_c;
  const P kn = pc.kn, kt = pc.kt;
  const P dn = kn * vn_abs, dt = (kt * abs(vq)) * vq;
  f0 += dn * vn0 + dt * q0;
  f1 += dn * vn1 + dt * q1;
  f2 += dn * vn2 + dt * q2;
  if (!c.still) {
    // Froude–Krylov plus added-mass forcing (zero where the water does not accelerate).
    const Scalar* ai = ws.water_acceleration.data() + 3 * i;
    const P aw0 = P::gather(ai, 3), aw1 = P::gather(ai + 1, 3), aw2 = P::gather(ai + 2, 3);
    const P qa = pc.cat_minus_can * ((q0 * aw0 + q1 * aw1) + q2 * aw2);
    const P rv = pc.rho_vol, ca = pc.one_plus_can;
    f0 += rv * (ca * aw0 + qa * q0);
    f1 += rv * (ca * aw1 + qa * q1);
    f2 += rv * (ca * aw2 + qa * q2);
  }
  pc.mass_iso_wet.store(&ws.mass_iso(i));
  pc.mass_tan_wet.store(&ws.mass_tan(i));
  pc.mass_iso_inv.store(&ws.mass_iso_inv(i));
  pc.mass_tan_ratio.store(&ws.mass_tan_ratio(i));
  if (c.mass_turns) {
    // Added-mass rate terms (see compute_forces; zero for a zero chord, where 1/|c| = 0).
    const P k = pc.mass_tan_wet * inv_c, ks = k * vq;
    const P dc0 = P::gather(vi + c.vs, c.vs) - P::gather(vi - c.vs, c.vs);
    const P dc1 = P::gather(vi + c.vs + 1, c.vs) - P::gather(vi - c.vs + 1, c.vs);
    const P dc2 = P::gather(vi + c.vs + 2, c.vs) - P::gather(vi - c.vs + 2, c.vs);
    const P m = k * ((dc0 * vn0 + dc1 * vn1) + dc2 * vn2) - ks * ((q0 * dc0 + q1 * dc1) + q2 * dc2);
    f0 += ks * dc0 + m * q0;
    f1 += ks * dc1 + m * q1;
    f2 += ks * dc2 + m * q2;
    (ks * vn0).store(&ws.pass_buffer(i, kMassRate));
    (ks * vn1).store(&ws.pass_buffer(i, kMassRate + 1));
    (ks * vn2).store(&ws.pass_buffer(i, kMassRate + 2));
  }
  f0.store(&ws.pass_buffer(i, kNodeForce));
  f1.store(&ws.pass_buffer(i, kNodeForce + 1));
  f2.store(&ws.pass_buffer(i, kNodeForce + 2));
  pc.one.store(&ws.submerged(i));
  zero.store(&ws.seabed_force(i));
  if constexpr (WithJacobian) {
    // −∂F/∂v of the drag (q held fixed) = c1 I + (c3 − c1) q qᵀ + cn v_n v_nᵀ.
    const P cn = simd::select(simd::greater(vn_abs, zero), kn / vn_abs, zero);
    const P c31 = (pc.two * kt) * abs(vq) - dn;
    Scalar* dv = ws.node_dv.data() + 6 * i;
    (dn + c31 * q0 * q0 + cn * vn0 * vn0).scatter(dv, 6);
    (c31 * q1 * q0 + cn * vn1 * vn0).scatter(dv + 1, 6);
    (c31 * q2 * q0 + cn * vn2 * vn0).scatter(dv + 2, 6);
    (dn + c31 * q1 * q1 + cn * vn1 * vn1).scatter(dv + 3, 6);
    (c31 * q2 * q1 + cn * vn2 * vn1).scatter(dv + 4, 6);
    (dn + c31 * q2 * q2 + cn * vn2 * vn2).scatter(dv + 5, 6);
    zero.store(&ws.node_kz(i));
  }
  return true;
}

/// Node i, any kind and state (end node, surface band, in air, on the seabed): tangent, node
/// force without the added-mass coupling to the neighbours, that coupling term w_i, masses,
/// submerged fraction, seabed force and the Jacobian terms.
template <bool WithJacobian, typename Scalar>
void node_general(const ForcePass<Scalar>& c, TetherWorkspace<Scalar>& ws, int i) {
  using std::abs;
  using std::sqrt;
  using V3 = Vector3<Scalar>;
  const TetherParameters<Scalar>& p = *c.p;
  const int n = c.n;
  // Tangent: unit(r_{i+1} − r_{i−1}) inside, the adjacent segment at the ends. The drag below
  // is written with the unnormalised chord and 1/|c|² so that its square root and the
  // tangent's run in parallel instead of one after the other.
  const int hi = i < n ? i + 1 : n, lo = i > 0 ? i - 1 : 0;
  const NodeTangent<Scalar> nt = node_tangent<Scalar>(c.positions(), i, n);
  const V3& chord = nt.chord;
  const Scalar inv_c2 = nt.inv_c2, inv_c = nt.inv_c;
  const V3& q = nt.q;
  ws.tangent.col(i) = q;
  V3 f;
  for (int k = 0; k < 3; ++k) {
    const Scalar in = i < n ? ws.pass_buffer(i, kSegmentForce + k) : Scalar(0);
    const Scalar out = i > 0 ? ws.pass_buffer(i - 1, kSegmentForce + k) : Scalar(0);
    f(k) = in - out;
  }
  const int kind = i == 0 ? 0 : (i == n ? 2 : 1);
  const Scalar li = c.kinds[kind].li;
  const Scalar z = c.X(2, i);
  const Scalar zeta = c.still ? Scalar(0) : ws.surface_elevation(i);
  // (Below the surface φ = 1 without the ramp's arithmetic.)
  const Scalar phi =
      z + zeta >= Scalar(0) ? Scalar(1) : submerged_fraction(z, zeta, p.diameter, c.inv_d);
  ws.submerged(i) = phi;
  const bool wet = phi > Scalar(0);
  // A node in the surface band (0 < φ < 1) scales its wet constants by φ.
  NodeConstants<Scalar> band;
  const bool in_band = wet && phi < Scalar(1);
  const NodeConstants<Scalar>& nc = in_band ? (band = c.kinds[kind].submerged(phi)) : c.kinds[kind];
  // −∂F_i/∂v_i (symmetric: xx, yx, zx, yy, zy, zz), filled only WithJacobian.
  Scalar dv[6] = {Scalar(0), Scalar(0), Scalar(0), Scalar(0), Scalar(0), Scalar(0)};
  V3 w = V3::Zero();
  if (wet) {
    f(2) += nc.wet_weight;
    // Morison drag on the relative velocity, split along q.
    const V3 vi(c.V(0, i), c.V(1, i), c.V(2, i));
    const V3 vr = ws.water_velocity.col(i) - vi;
    const Scalar vc = (vr(0) * chord(0) + vr(1) * chord(1)) + vr(2) * chord(2);  // = |c| v_q
    const Scalar sc = vc * inv_c2;
    const V3 vn = vr - sc * chord;
    const Scalar vn_abs = sqrt((vn(0) * vn(0) + vn(1) * vn(1)) + vn(2) * vn(2));
    const Scalar vq = vc * inv_c;
    const Scalar kn = nc.kn, kt = nc.kt;
    const Scalar dn = kn * vn_abs, dt = (kt * abs(vq)) * vq;
    for (int k = 0; k < 3; ++k) f(k) += dn * vn(k) + dt * q(k);
    if (!c.still) {
      // Froude–Krylov plus added-mass forcing from the water acceleration.
      const V3 aw = ws.water_acceleration.col(i);
      const Scalar qa = (c.cat - c.can) * ((q(0) * aw(0) + q(1) * aw(1)) + q(2) * aw(2));
      for (int k = 0; k < 3; ++k) f(k) += nc.rho_vol * ((Scalar(1) + c.can) * aw(k) + qa * q(k));
    }
    ws.mass_iso(i) = nc.mass_iso_wet;
    ws.mass_tan(i) = nc.mass_tan_wet;
    if (c.mass_turns) {
      // Added-mass rate terms, written with w_r = u_water − v = −v_r (vr above; both factors
      // of each term flip sign): G_i = b[(q̇·w_r) q + s q̇] and ∂T/∂x = ±b s P w_r/|c| with
      // s = q·w_r = vq, P w_r = vn, q̇ = P (v_hi − v_lo)/|c|.
      // With k = b/|c| and dc = v_hi − v_lo: G_i = k[s dc + (dc·vn − s q·dc) q], w = k s vn,
      // which goes to node hi with a plus sign and to node lo with a minus sign.
      const Scalar k = nc.mass_tan_wet * inv_c, ks = k * vq;
      const V3 dc(c.V(0, hi) - c.V(0, lo), c.V(1, hi) - c.V(1, lo), c.V(2, hi) - c.V(2, lo));
      const Scalar m = k * ((dc(0) * vn(0) + dc(1) * vn(1)) + dc(2) * vn(2)) -
                       ks * ((q(0) * dc(0) + q(1) * dc(1)) + q(2) * dc(2));
      for (int j = 0; j < 3; ++j) f(j) += ks * dc(j) + m * q(j);
      w = ks * vn;
    }
    if constexpr (WithJacobian) {
      // −∂F/∂v of the drag (q held fixed): kn(|v_n| P + v_n v_nᵀ/|v_n|) + 2 kt |v_q| q qᵀ
      // = c1 I + (c3 − c1) q qᵀ + cn v_n v_nᵀ.
      const Scalar cn = vn_abs > Scalar(0) ? kn / vn_abs : Scalar(0);
      const Scalar c31 = (Scalar(2) * kt) * abs(vq) - dn;
      dv[0] = dn + c31 * q(0) * q(0) + cn * vn(0) * vn(0);
      dv[1] = c31 * q(1) * q(0) + cn * vn(1) * vn(0);
      dv[2] = c31 * q(2) * q(0) + cn * vn(2) * vn(0);
      dv[3] = dn + c31 * q(1) * q(1) + cn * vn(1) * vn(1);
      dv[4] = c31 * q(2) * q(1) + cn * vn(2) * vn(1);
      dv[5] = dn + c31 * q(2) * q(2) + cn * vn(2) * vn(2);
    }
  } else {
    f(2) += nc.dry_weight;
    ws.mass_iso(i) = nc.mass_dry;
    ws.mass_tan(i) = Scalar(0);
  }
  // Seabed: spring–damper normal force (never pulling) and saturated-viscous friction.
  Scalar normal(0), kz(0);
  const Scalar pen = z - c.bed;
  if (pen > Scalar(0)) {
    const Scalar vz = c.V(2, i);
    const Scalar ramp = pen < p.seabed_damping_depth ? pen / p.seabed_damping_depth : Scalar(1);
    normal = (pen * c.bed_k + vz * c.bed_c * ramp) * li;
    if (normal > Scalar(0)) {
      f(2) -= normal;
      kz = c.bed_k * li;
      // The ramp's ∂/∂z while landing (ż > 0); left out when rising, where it is negative.
      if (ramp < Scalar(1) && vz > Scalar(0)) kz += vz * c.bed_c * li / p.seabed_damping_depth;
      if constexpr (WithJacobian) dv[5] += c.bed_c * ramp * li;
      if (p.seabed_friction > Scalar(0)) {
        const Scalar vx = c.V(0, i), vy = c.V(1, i);
        const Scalar vh2 = vx * vx + vy * vy;
        const Scalar vf = p.friction_velocity;
        // The implicit steps hold the normal force of the start of the step (see
        // TetherWorkspace::frozen_friction).
        const Scalar fmax =
            p.seabed_friction * (ws.frozen_friction ? ws.friction_normal(i) : normal);
        const Scalar coef = vh2 > vf * vf ? fmax / sqrt(vh2) : fmax / vf;
        f(0) -= coef * vx;
        f(1) -= coef * vy;
        if constexpr (WithJacobian) {
          dv[0] += coef;
          dv[3] += coef;
        }
      }
    } else {
      normal = Scalar(0);
    }
  }
  ws.seabed_force(i) = normal;
  ws.mass_iso_inv(i) = Scalar(1) / ws.mass_iso(i);
  ws.mass_tan_ratio(i) = ws.mass_tan(i) / (ws.mass_iso(i) + ws.mass_tan(i));
  // In the surface band the buoyancy −φ ρ V g grows with depth: a restoring spring ρ V g / D.
  if (in_band) kz += c.kinds[kind].rho_vol * c.g / p.diameter;
  if constexpr (WithJacobian) {
    for (int k = 0; k < 6; ++k) ws.node_dv(k, i) = dv[k];
    ws.node_kz(i) = kz;
  }
  for (int k = 0; k < 3; ++k) {
    ws.pass_buffer(i, kNodeForce + k) = f(k);
    ws.pass_buffer(i, kMassRate + k) = w(k);
  }
}

/// Node forces i … i + lanes − 1 into ws.force: the node pass's force plus the added-mass
/// coupling of the neighbours (+w_{i−1} − w_{i+1}; at node 0 the node's own −w_0, at node N its
/// own +w_N, as its chord is its own segment) and bending.
template <bool Wide, typename Scalar>
EIGEN_ALWAYS_INLINE void finish_block(const ForcePass<Scalar>& c, TetherWorkspace<Scalar>& ws,
                                      int i) {
  using P = simd::Pack<Scalar, Wide>;
  P f[3];
  for (int k = 0; k < 3; ++k) {
    f[k] = P::load(&ws.pass_buffer(i, kNodeForce + k));
    if (c.mass_turns) {
      const Scalar* w = &ws.pass_buffer(0, kMassRate + k);
      if constexpr (P::lanes == 1) {
        const Scalar prev = i > 0 ? w[i - 1] : -w[0], next = i < c.n ? w[i + 1] : -w[c.n];
        f[k] = f[k] + (P::all(prev) - P::all(next));
      } else {
        f[k] = f[k] + (P::load(w + i - 1) - P::load(w + i + 1));
      }
    }
    if (c.bending) f[k] += P::gather(ws.bending.data() + 3 * i + k, 3);
    f[k].scatter(ws.force.data() + 3 * i + k, 3);
  }
  if (c.acc) {
    // a = M⁻¹F = (F − (b/(a+b)) q (q·F)) / a (see accelerations_from_forces).
    const Scalar* tq = ws.tangent.data() + 3 * i;
    const P q0 = P::gather(tq, 3), q1 = P::gather(tq + 1, 3), q2 = P::gather(tq + 2, 3);
    const P rq = P::load(&ws.mass_tan_ratio(i)) * ((q0 * f[0] + q1 * f[1]) + q2 * f[2]);
    const P ia = P::load(&ws.mass_iso_inv(i));
    Scalar* a = c.acc + 3 * i;
    ((f[0] - rq * q0) * ia).scatter(a, 3);
    ((f[1] - rq * q1) * ia).scatter(a + 1, 3);
    ((f[2] - rq * q2) * ia).scatter(a + 2, 3);
  }
}

/// Bending forces into ws.bending from the segment pass (see compute_forces).
template <typename Scalar>
void bending_forces(const ForcePass<Scalar>& c, TetherWorkspace<Scalar>& ws) {
  using V3 = Vector3<Scalar>;
  // E_i = k (1 − c), c = u_a·u_b, k = EI/l at interior node i between segment a (i−1) and b (i);
  // F_{i−1} = −k (u_b − c u_a)/l_a, F_{i+1} = k (u_a − c u_b)/l_b, F_i = −F_{i−1} − F_{i+1}.
  ws.bending.setZero();
  const Scalar k = c.p->bending_stiffness * c.inv_l;
  for (int i = 1; i < c.n; ++i) {
    const Scalar la = ws.stretched_length(i - 1), lb = ws.stretched_length(i);
    if (!(la > Scalar(0) && lb > Scalar(0))) continue;
    const V3 ua = ws.direction.col(i - 1), ub = ws.direction.col(i);
    const Scalar cs = ua.dot(ub);
    const V3 fa = (-k / la) * (ub - cs * ua);
    const V3 fb = (k / lb) * (ua - cs * ub);
    ws.bending.col(i - 1) += fa;
    ws.bending.col(i + 1) += fb;
    ws.bending.col(i) -= fa + fb;
  }
}

/// Points `data`/`stride` at the columns of `m` when it is column-major storage with unit inner
/// stride; otherwise evaluates `m` into `copy` (sized by the workspace) and points at that.
template <typename Scalar, typename D>
void bind_columns(const Eigen::MatrixBase<D>& m, Matrix3X<Scalar>& copy, const Scalar*& data,
                  Eigen::Index& stride) {
  using M = typename D::PlainObject;
  constexpr int flags = Eigen::internal::traits<D>::Flags;
  if constexpr (bool(flags & Eigen::DirectAccessBit) && !bool(flags & Eigen::RowMajorBit) &&
                std::is_same_v<typename M::Scalar, Scalar>) {
    if (m.derived().innerStride() == 1) {
      data = m.derived().data();
      stride = m.derived().outerStride();
      return;
    }
  }
  copy = m;
  data = copy.data();
  stride = 3;
}

/// The passes of compute_forces on positions and velocities stored column-major with the given
/// column strides.
template <bool WithJacobian, typename Scalar>
void force_passes(ForcePass<Scalar>& c, TetherWorkspace<Scalar>& ws) {
  constexpr bool wide = simd::vectorized<Scalar>;
  constexpr int lanes = simd::Pack<Scalar, wide>::lanes;
  const int n = c.n;
  const PackedConstants<Scalar, wide> packed(c);
  const PackedConstants<Scalar, false> single(c);
  int s = 0;
  if constexpr (wide)
    for (; s + lanes <= n; s += lanes) segment_block<WithJacobian, true>(c, packed, ws, s);
  for (; s < n; ++s) segment_block<WithJacobian, false>(c, single, ws, s);
  if (c.bending) bending_forces(c, ws);
  node_general<WithJacobian>(c, ws, 0);
  int i = 1;
  if constexpr (wide)
    for (; i + lanes <= n; i += lanes)
      if (!interior_block<WithJacobian, true>(c, packed, ws, i))
        for (int j = i; j < i + lanes; ++j)
          if (!interior_block<WithJacobian, false>(c, single, ws, j))
            node_general<WithJacobian>(c, ws, j);
  for (; i < n; ++i)
    if (!interior_block<WithJacobian, false>(c, single, ws, i))
      node_general<WithJacobian>(c, ws, i);
  if (n > 0) node_general<WithJacobian>(c, ws, n);
  finish_block<false>(c, ws, 0);
  i = 1;
  if constexpr (wide)
    for (; i + lanes <= n; i += lanes) finish_block<true>(c, ws, i);
  for (; i <= n; ++i) finish_block<false>(c, ws, i);
}

}  // namespace detail

namespace detail {

/// compute_forces, and when `acc` is not null the node accelerations M⁻¹F of every node into
/// `acc` (3 × (N+1), column-major; the kinematic ends' entries are M⁻¹F too, not their
/// prescribed accelerations).
template <bool WithJacobian, typename Scalar, typename Env, typename DX, typename DV>
void evaluate_forces(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws, const Env& env,
                     double t, const Eigen::MatrixBase<DX>& x, const Eigen::MatrixBase<DV>& v,
                     Scalar* acc) {
  const TetherParameters<Scalar>& p = model.parameters();
  const int n = model.segments();
  ForcePass<Scalar> c;
  c.p = &p;
  c.n = n;
  c.rho = Scalar(env.water_density());
  c.g = Scalar(env.gravity());
  c.bed = Scalar(env.seabed_depth());
  c.l = model.segment_length();
  c.l2 = c.l * c.l;
  c.inv_l = model.inverse_segment_length();
  c.ea_l = model.axial_spring();
  c.ba_l = model.axial_damper();
  c.ea = p.axial_stiffness;
  c.ba = p.internal_damping;
  c.can = p.normal_added_mass;
  c.cat = p.tangential_added_mass;
  c.inv_d = Scalar(1) / p.diameter;
  c.bed_k = p.seabed_stiffness * p.diameter;
  c.bed_c = p.seabed_damping * p.diameter;
  c.clamp = !p.compressive_damping;
  c.damping = c.ba != Scalar(0);
  c.bending = p.bending_stiffness > Scalar(0);
  // Added-mass rate terms (see above); none when Cat = Can (b = 0).
  c.mass_turns = c.cat != c.can;

  // Water velocity and acceleration at the nodes; a still environment (no waves, no current)
  // gives zeros everywhere, which the buffers keep from the last time they were zeroed.
  c.still = is_still_water(env);
  if (!c.still) {
    if (!ws.water_frozen) {
      ws.water_is_zero = false;
      sample_water_at_nodes(env, x, t, ws);
    }
  } else if (!ws.water_is_zero) {
    ws.water_velocity.setZero();
    ws.water_acceleration.setZero();
    ws.surface_elevation.setZero();
    ws.water_is_zero = true;
  }

  // The constants of the three kinds of node (start, interior, end), once per evaluation.
  const Scalar half_rho_d = Scalar(0.5) * c.rho * p.diameter;
  const Scalar kn_per_l = half_rho_d * p.normal_drag;
  const Scalar kt_per_l = half_rho_d * Scalar(kelp::pi) * p.tangential_drag;
  const auto node_constants = [&](int i) {
    const Scalar m = model.node_mass(i), vol = model.node_volume(i), li = model.node_length(i);
    return NodeConstants<Scalar>{li,
                                 m * c.g,
                                 (m - c.rho * vol) * c.g,
                                 c.rho * vol,
                                 kn_per_l * li,
                                 kt_per_l * li,
                                 m,
                                 m + c.rho * vol * c.can,
                                 c.rho * vol * (c.cat - c.can)};
  };
  c.kinds[0] = node_constants(0);
  c.kinds[1] = node_constants(n > 1 ? 1 : 0);
  c.kinds[2] = node_constants(n);

  // The passes read the coordinates through a pointer and a column stride: straight from
  // column-major storage, or from a copy of any other expression.
  bind_columns(x, ws.x_eval, c.x, c.xs);
  bind_columns(v, ws.v_eval, c.v, c.vs);
  c.acc = acc;
  force_passes<WithJacobian>(c, ws);
}

}  // namespace detail

/// \brief Net force on every node of the tether at positions `x`, velocities `v`, time `t`.
///
/// Fills `ws.force` (NED [N]) and the per-node mass matrices M_i = a_i I + b_i q_i q_iᵀ
/// (`ws.mass_iso`, `ws.mass_tan`), plus tensions, tangents and seabed forces. Per node i:
/// \f[ F_i = T_i u_i − T_{i−1} u_{i−1} + (m_i − ρ V_i) g e_z + F^{drag}_i + F^{FK}_i + F^{bed}_i
/// \f]
/// - axial: T_s = max(0, EA·max(0, ε_s) + BA ε̇_s): the elastic part acts only when l_s > l, the
///   dashpot at any length, and the sum is clamped at zero so that a segment never pushes
///   (`compressive_damping` drops the clamp, as MoorDyn does);
/// - drag (Morison, on v_r = u_water − v_i): ½ρ d l_i Cdn |v_rn| v_rn + ½ρ π d l_i Cdt |v_rt| v_rt;
/// - fluid inertia: ρ V_i [(1 + Can)(I − q qᵀ) + (1 + Cat) q qᵀ] a_water;
/// - added mass ρ V_i [Can (I − q qᵀ) + Cat q qᵀ] in the mass matrix (never as a force from a
///   previous acceleration), with the terms of its rate of change: the added mass is part of the
///   kinetic energy ½ v_rᵀ M_i v_r (v_r = v_i − u_water), and since M_i = a_i I + b_i q_i q_iᵀ
///   turns with the tangent, Lagrange's equations add G_i = −b_i[(q̇_i·v_r) q_i + (q_i·v_r) q̇_i]
///   on node i and ±b_i (q_i·v_r)(I − q_i q_iᵀ) v_r/|c_i| on the two nodes of its chord c_i
///   (∂T/∂x). Without them the line gains energy whenever Cat ≠ Can; with them the model is
///   passive (Lamb 1932, Hydrodynamics §137: fluid kinetic energy in Lagrange's equations);
/// - seabed (z_i > h): upward (z_i − h) kb d l_i + ż_i cb d l_i (≥ 0), and saturated-viscous
///   friction −μ_f N v_h / max(|v_h|, v_f);
/// - buoyancy, drag, fluid inertia and added mass scale with the node's submerged fraction φ_i,
///   which goes from 1 to 0 as the node rises through the free surface over one cable diameter
///   (detail::submerged_fraction): nodes in air get none.
/// Evaluated in passes over SIMD packets (kelp/core/simd.hpp): the segments, then the interior
/// nodes of the wet line a packet at a time (the ends and nodes in the surface band, in air or
/// on the seabed one by one, with every branch), then the added-mass coupling of neighbours and
/// bending. Also fills `ws.mass_iso_inv` and `ws.mass_tan_ratio`. No heap allocation.
/// \tparam WithJacobian also fill the Jacobian ingredients (`ws.seg_*`, `ws.node_dv`,
/// `ws.node_kz`); the Jacobian leaves out the added-mass rate terms G_i (quadratic in the
/// velocities, small beside the mass term M/h of a step).
/// \param[in] model the tether \param[in,out] ws workspace \param[in] env environment
/// \param[in] t time [s] \param[in] x node positions 3×(N+1) [m] \param[in] v velocities [m/s]
/// \throws kelp::invalid_argument when `ws` was not built for `model` (TetherWorkspace::fits),
/// x or v is not 3×(N+1), or t, x or v is not finite (O(N) check; the integrators call the
/// evaluation behind it directly, after checking the state once per step).
template <bool WithJacobian = false, typename Scalar, typename Env, typename DX, typename DV>
void compute_forces(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws, const Env& env,
                    double t, const Eigen::MatrixBase<DX>& x, const Eigen::MatrixBase<DV>& v) {
  detail::check_workspace(model, ws);
  KELP_CHECK(
      x.rows() == 3 && x.cols() == model.nodes() && v.rows() == 3 && v.cols() == model.nodes(),
      "compute_forces: x and v must be 3 x (segments + 1)");
  check_finite(t, "compute_forces: t");
  // One pass over the inputs: NaN and ±Inf survive the sum (a sum that overflows is refused
  // too, rightly: coordinates of 1e307 m are not a tether).
  if (!is_finite(x.sum() + v.sum())) {
    check_all_finite(x, "compute_forces: x");
    check_all_finite(v, "compute_forces: v");
    ::kelp::detail::throw_invalid_argument("compute_forces: x and v overflow");
  }
  detail::evaluate_forces<WithJacobian>(model, ws, env, t, x, v, static_cast<Scalar*>(nullptr));
}

/// \brief Node accelerations a_i = M_i⁻¹ F_i from the last `compute_forces` (free nodes only;
/// kinematic ends get the prescribed acceleration `a_start`, `a_end`).
///
/// M_i = a I + b q qᵀ is inverted in closed form: M⁻¹ F = (F − b/(a+b) q (q·F)) / a, with
/// 1/a and b/(a+b) from compute_forces (constants along the wet part of the line).
/// \throws kelp::invalid_argument when `ws` was not built for `model`, `acc` is not 3×(N+1) or
/// an end acceleration is not finite.
template <typename Scalar, typename DA>
void accelerations_from_forces(const TetherModel<Scalar>& model, TetherWorkspace<Scalar>& ws,
                               const Vector3<Scalar>& a_start, const Vector3<Scalar>& a_end,
                               Eigen::MatrixBase<DA>& acc) {
  detail::check_workspace(model, ws);
  KELP_CHECK(acc.rows() == 3 && acc.cols() == model.nodes(),
             "accelerations_from_forces: acc must be 3 x (segments + 1)");
  check_all_finite(a_start, "accelerations_from_forces: a_start");
  check_all_finite(a_end, "accelerations_from_forces: a_end");
  const int n = model.segments();
  for (int i = model.first_free_node(); i <= model.last_free_node(); ++i) {
    const auto q = ws.tangent.col(i);
    const auto f = ws.force.col(i);
    acc.col(i) = (f - (ws.mass_tan_ratio(i) * q.dot(f)) * q) * ws.mass_iso_inv(i);
  }
  if (model.first_free_node() == 1) acc.col(0) = a_start;
  if (model.last_free_node() == n - 1) acc.col(n) = a_end;
}

/// \brief Forces the tether exerts on its kinematic attachment points from the last
/// `compute_forces`: F_end = F_node − M_node a_end (the negative of the constraint force that
/// holds the end node on its prescribed path), NED [N]. Zero for a free end.
/// \throws kelp::invalid_argument when `ws` was not built for `model` or `boundary` is not finite.
template <typename Scalar>
EndForces<Scalar> end_forces_from_workspace(const TetherModel<Scalar>& model,
                                            const TetherWorkspace<Scalar>& ws,
                                            const TetherBoundary<Scalar>& boundary) {
  detail::check_workspace(model, ws);
  check_boundary(boundary);
  EndForces<Scalar> out;
  const int n = model.segments();
  const auto inertia = [&](int i, const Vector3<Scalar>& a) -> Vector3<Scalar> {
    const Vector3<Scalar> q = ws.tangent.col(i);
    return ws.mass_iso(i) * a + ws.mass_tan(i) * q.dot(a) * q;
  };
  if (model.parameters().start_mode == EndMode::kinematic)
    out.on_start = ws.force.col(0) - inertia(0, boundary.start.acceleration);
  if (model.parameters().end_mode == EndMode::kinematic)
    out.on_end = ws.force.col(n) - inertia(n, boundary.end.acceleration);
  return out;
}

/// \brief Total mechanical energy [J]: kinetic ½ Σ vᵢᵀ Mᵢ vᵢ (with added mass) + potential of
/// the weight −Σ mᵢ g zᵢ (NED z down) and of the buoyancy Σ ρVᵢ g Φ(zᵢ + ζ) (Φ the depth of a
/// wet node plus D/2, see detail::submerged_depth_integral) + elastic ½ EA/l Σ (l_s − l)² over
/// stretched segments + bending EI/l Σ (1 − u_{i−1}·u_i). Ignores the seabed spring. Recomputes the
/// tangents and wetness itself.
/// \throws kelp::invalid_argument when the state does not fit the model or is not finite.
template <typename Scalar, typename Env>
Scalar tether_energy(const TetherModel<Scalar>& model, const Env& env,
                     const TetherState<Scalar>& state) {
  using std::sqrt;
  check_state(model, state);
  const TetherParameters<Scalar>& p = model.parameters();
  const int n = model.segments();
  const Scalar rho = Scalar(env.water_density()), g = Scalar(env.gravity());
  const Scalar l = model.segment_length();
  Scalar e(0);
  for (int s = 0; s < n; ++s) {
    const Scalar ls = (state.position.col(s + 1) - state.position.col(s)).norm();
    if (ls > l) e += Scalar(0.5) * model.axial_spring() * (ls - l) * (ls - l);
  }
  if (p.bending_stiffness > Scalar(0))
    for (int i = 1; i < n; ++i) {
      const Vector3<Scalar> a = state.position.col(i) - state.position.col(i - 1);
      const Vector3<Scalar> b = state.position.col(i + 1) - state.position.col(i);
      const Scalar na = a.norm(), nb = b.norm();
      if (na > Scalar(0) && nb > Scalar(0))
        e += p.bending_stiffness / l * (Scalar(1) - a.dot(b) / (na * nb));
    }
  for (int i = 0; i <= n; ++i) {
    const Vector3<Scalar> q = detail::node_tangent<Scalar>(state.position, i, n).q;
    const Scalar zeta =
        Scalar(env.surface_elevation(state.position(0, i), state.position(1, i), state.time));
    const Scalar z = state.position(2, i);
    const Scalar phi = detail::submerged_fraction(z, zeta, p.diameter);
    const Scalar m = model.node_mass(i), rv = phi * rho * model.node_volume(i);
    const Vector3<Scalar> vi = state.velocity.col(i);
    const Scalar vq = vi.dot(q);
    e += Scalar(0.5) * ((m + rv * p.normal_added_mass) * vi.squaredNorm() +
                        rv * (p.tangential_added_mass - p.normal_added_mass) * vq * vq);
    e -= m * g * z -
         rho * model.node_volume(i) * g * detail::submerged_depth_integral(z, zeta, p.diameter);
  }
  return e;
}

/// \brief Checks that a state fits the model and is finite (its history too, when it has one).
/// \throws kelp::invalid_argument naming `state.position` / `state.velocity` / `state.time` /
/// `state.previous_position` / `state.previous_velocity` / `state.previous_dt`.
template <typename Scalar>
void check_state(const TetherModel<Scalar>& model, const TetherState<Scalar>& state) {
  KELP_CHECK(state.position.rows() == 3 && state.velocity.rows() == 3 &&
                 state.position.cols() == model.nodes() && state.velocity.cols() == model.nodes(),
             "state.position and state.velocity must have segments + 1 columns");
  check_all_finite(state.position, "state.position");
  check_all_finite(state.velocity, "state.velocity");
  check_finite(state.time, "state.time");
  check_non_negative(state.previous_dt, "state.previous_dt");
  if (state.has_history()) {
    KELP_CHECK(state.previous_position.cols() == model.nodes() &&
                   state.previous_velocity.cols() == model.nodes(),
               "state.previous_position and state.previous_velocity must have segments + 1 "
               "columns when state.previous_dt > 0");
    check_all_finite(state.previous_position, "state.previous_position");
    check_all_finite(state.previous_velocity, "state.previous_velocity");
  }
}

/// \brief Checks that the boundary motion is finite.
/// \throws kelp::invalid_argument naming the field.
template <typename Scalar>
void check_boundary(const TetherBoundary<Scalar>& b) {
  check_all_finite(b.start.position, "boundary.start.position");
  check_all_finite(b.start.velocity, "boundary.start.velocity");
  check_all_finite(b.start.acceleration, "boundary.start.acceleration");
  check_all_finite(b.end.position, "boundary.end.position");
  check_all_finite(b.end.velocity, "boundary.end.velocity");
  check_all_finite(b.end.acceleration, "boundary.end.acceleration");
}

/// \brief Straight-line state: nodes evenly spaced from `start_ned` to `end_ned`, at rest.
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

/// \brief Double-precision aliases.
using TetherParametersd = TetherParameters<double>;
using TetherModeld = TetherModel<double>;
using TetherStated = TetherState<double>;
using TetherWorkspaced = TetherWorkspace<double>;
using TetherBoundaryd = TetherBoundary<double>;
/// \brief Single-precision aliases.
using TetherParametersf = TetherParameters<float>;
using TetherModelf = TetherModel<float>;
using TetherStatef = TetherState<float>;
using TetherWorkspacef = TetherWorkspace<float>;
using TetherBoundaryf = TetherBoundary<float>;

}  // namespace kelp::tether
