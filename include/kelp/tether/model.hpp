/// \file
/// \brief Lumped-mass tether: the parameters (`TetherParameters`, their bounds and `validate`)
/// and the model built from them (`TetherModel`: segment length, node masses, volumes and
/// lengths, which ends are free). See kelp/tether/lumped_mass.hpp for the formulation.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <string>

#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
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

/// \brief Which lumped-mass line model the force evaluation follows.
///
/// Both share the formulation of Hall & Goupee (2015) as MoorDyn v2 implements it (tangents,
/// Morison drag split, added mass in the node mass matrices, weight, buoyancy, Froude–Krylov
/// forcing, seabed spring–damper); they differ in four places (docs/equations.md, section 4;
/// benchmarks/results/tether.md, "kelp's line and MoorDyn's" for the measured effect of the
/// first three):
///
/// - added-mass rate terms (Cat ≠ Can): `kelp` has them (the model is passive), `moordyn` not;
/// - internal dashpot BA·ε̇: `kelp` clamps the axial force at 0 (a cable never pushes),
///   `moordyn` lets it act in compression too;
/// - seabed damping at touchdown: `kelp` ramps it in over `seabed_damping_depth`, `moordyn`
///   switches it on at first contact (a force step);
/// - the dashpot of a segment folded below a tenth of its rest length: `kelp` fades it out
///   (TetherModel::dashpot_fade: its direction is undefined at zero length), `moordyn` keeps it;
///   nothing differs while every segment is longer than that.
enum class LineModel {
  /// kelp's passive line: the added-mass rate terms (Lagrange's equations with the
  /// tangent-dependent added mass; see compute_forces), an axial force that never pushes (unless
  /// `compressive_damping`), the seabed damping ramped in over `seabed_damping_depth`, the
  /// dashpot faded out on a segment folded below l/10 (TetherModel::dashpot_fade).
  kelp,
  /// MoorDyn v2's line model (source/Line.cpp of MoorDyn v2.7.1): no added-mass rate terms, the
  /// internal dashpot acting in compression as well (`compressive_damping` is implied), the seabed
  /// damping switched on at first contact (`seabed_damping_depth` is ignored, as if 0). For users
  /// porting MoorDyn models and for validation against MoorDyn.
  moordyn
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
  /// Internal damping as a ratio ζ [-] of a segment's critical axial damping, as MoorDyn's
  /// `BA/-zeta` input takes it (a negative BA read as −ζ, MoorDyn v2 Line.cpp): when > 0, the
  /// model uses BA = ζ · (L/N) · sqrt(EA · μ) (internal_damping_from_ratio), so that each
  /// segment's dashpot BA/l = ζ · sqrt(EA · μ) and the damping ratio do not change with the
  /// number of segments. 0 (the default): `internal_damping` is BA. Give one or the other.
  /// TetherModel::parameters() holds the BA it uses, with this field 0.
  Scalar internal_damping_ratio = Scalar(0);
  /// When true, the internal dashpot acts in compression too, as in MoorDyn v2 (Line.cpp: the
  /// damping tension is added whether or not the segment is stretched, and the sum is not
  /// clamped): use it to reproduce MoorDyn. Default false: a cable cannot push, so the total
  /// axial force is max(0, EA·max(0, ε) + BA·ε̇).
  bool compressive_damping = false;
  /// The line model: kelp's passive line (default) or MoorDyn v2's (see LineModel; `moordyn`
  /// implies compressive_damping and a zero seabed_damping_depth). One field rather than a preset
  /// that sets several: it travels with the parameters (copies, scenario files), it cannot be
  /// half applied, and it reads as what it is when a line is printed or compared.
  LineModel line_model = LineModel::kelp;
  /// Bending stiffness EI [N m²] (0: a perfectly flexible line). Discrete bending energy
  /// EI/l · (1 − u_{i−1}·u_i) at each interior node, i.e. ½ EI κ² l for small angles with
  /// κ = θ/l. Enters the implicit schemes' symmetric Jacobian through the residual only (it
  /// couples nodes i−1 and i+1), so keep EI/l³ ≪ node mass / dt² there, or use
  /// JacobianKind::whole, which has it; the explicit stable-dt estimate accounts for it. An end
  /// is pinned (free to turn) unless its EndMotion::direction is set: a clamped end adds
  /// 2EI/l · (1 − t·u) there (see compute_forces).
  Scalar bending_stiffness = Scalar(0);
  /// Breaking strength [N]: when a segment's axial force exceeds it at the end of a step, the
  /// line parts there (TetherState::parted; see kelp/tether/failure.hpp). 0 or +∞ (the default
  /// 0): the line never parts. The Fathom ROV tether is rated at 350 lbf = 1557 N
  /// (tether::presets::rov_tether).
  Scalar breaking_strength = Scalar(0);
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

/// \brief Internal damping BA [N s] for the damping ratio ζ of MoorDyn's `BA/-zeta` input:
/// BA = ζ · l · sqrt(EA · μ), with l the unstretched segment length, EA the axial stiffness and
/// μ the mass per length in air (MoorDyn v2, Line.cpp: the material damping c = −BA_in · L/N ·
/// sqrt(E ρ) with E = EA/A and ρ = μ/A, times A). The segment's dashpot BA/l = ζ sqrt(EA μ) is
/// then the same for any number of segments.
/// \tparam Scalar double, float or an automatic-differentiation type.
/// \param ratio the damping ratio ζ [-] (≥ 0).
/// \param segment_length the unstretched segment length l = L/N [m].
/// \param axial_stiffness EA [N].
/// \param mass_per_length μ, mass per unit unstretched length in air [kg/m].
/// \return BA [N s].
template <typename Scalar>
Scalar internal_damping_from_ratio(const Scalar& ratio, const Scalar& segment_length,
                                   const Scalar& axial_stiffness, const Scalar& mass_per_length) {
  using std::sqrt;
  return ratio * segment_length * sqrt(axial_stiffness * mass_per_length);
}

/// \brief Checks tether parameters.
/// \tparam Scalar double or float.
/// \param p the parameters.
/// \throws kelp::invalid_argument naming the offending field: segments in [1, 100000]; length,
/// diameter, mass_per_length, axial_stiffness, friction_velocity finite and > 0; the rest finite
/// and ≥ 0 (breaking_strength may be +∞); every magnitude at most its bound in
/// kelp::tether::limits; internal_damping and internal_damping_ratio not both > 0; segments at
/// least 1 µm long; end modes EndMode values; line_model a LineModel value.
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
  bounded(p.internal_damping_ratio, limits::max_coefficient, "internal_damping_ratio", true);
  KELP_CHECK(!(p.internal_damping > Scalar(0) && p.internal_damping_ratio > Scalar(0)),
             "internal_damping and internal_damping_ratio are both set: give BA [N s] or the "
             "damping ratio, not both");
  bounded(p.bending_stiffness, limits::max_bending_stiffness, "bending_stiffness", true);
  // +∞ is allowed (never parts), as is 0.
  KELP_CHECK(!(p.breaking_strength < Scalar(0)) && p.breaking_strength == p.breaking_strength,
             "breaking_strength must be >= 0 (0 or infinity: the line never parts)");
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
  KELP_CHECK(p.line_model == LineModel::kelp || p.line_model == LineModel::moordyn,
             "line_model must be LineModel::kelp or LineModel::moordyn");
}

/// \brief Validated tether parameters with the per-step constants precomputed.
///
/// Build once from `TetherParameters`; constant afterwards.
/// \tparam Scalar double or float.
template <typename Scalar>
class TetherModel {
 public:
  /// \brief Validates `p` (see validate(const TetherParameters&)) and precomputes constants.
  /// \param p the parameters (copied; a damping ratio is converted to BA, and LineModel::moordyn
  /// resolved, see parameters()).
  /// \throws kelp::invalid_argument naming the offending field.
  explicit TetherModel(const TetherParameters<Scalar>& p) : p_(p) {
    validate(p);
    // MoorDyn's line model implies its dashpot and its touchdown (see LineModel): resolved here
    // once, so that every reader of parameters() (forces, Jacobian, stable step) sees them.
    if (p.line_model == LineModel::moordyn) {
      p_.compressive_damping = true;
      p_.seabed_damping_depth = Scalar(0);
    }
    rate_terms_ = p.line_model == LineModel::kelp && p.tangential_added_mass != p.normal_added_mass;
    const int n = p.segments;
    const Scalar N = Scalar(n);
    l_ = p.length / N;
    inv_l_ = Scalar(1) / l_;
    ea_over_l_ = p.axial_stiffness / l_;
    // A damping ratio becomes BA here, once, so that every reader of parameters() sees BA.
    if (p.internal_damping_ratio > Scalar(0)) {
      p_.internal_damping = internal_damping_from_ratio(p.internal_damping_ratio, l_,
                                                        p.axial_stiffness, p.mass_per_length);
      p_.internal_damping_ratio = Scalar(0);
    }
    ba_over_l_ = p_.internal_damping / l_;
    fade_length_ = p.line_model == LineModel::kelp ? kDashpotFadeFraction * l_ : Scalar(0);
    inv_fade_length_ = fade_length_ > Scalar(0) ? Scalar(1) / fade_length_ : Scalar(0);
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

  /// \brief The parameters the model was built from, as the model uses them: with
  /// LineModel::moordyn, `compressive_damping` is true and `seabed_damping_depth` 0.
  /// \return the model's copy; `internal_damping` holds BA [N s] and `internal_damping_ratio` 0.
  const TetherParameters<Scalar>& parameters() const { return p_; }
  /// \brief True when the forces carry the added-mass rate terms (see compute_forces): kelp's line
  /// model with Cat ≠ Can. False for LineModel::moordyn and whenever Cat = Can (the added mass is
  /// then isotropic and does not turn with the tangent).
  /// \return whether compute_forces adds the rate terms.
  bool added_mass_rate_terms() const { return rate_terms_; }
  /// \brief True when the line can part: a breaking strength that is positive and finite.
  /// \return whether part_if_overloaded() can part this line.
  bool can_part() const {
    return p_.breaking_strength > Scalar(0) && is_finite(p_.breaking_strength);
  }
  /// \brief Number of segments N.
  /// \return N ≥ 1.
  int segments() const { return p_.segments; }
  /// \brief Number of nodes N + 1.
  /// \return N + 1 ≥ 2 (the columns of a TetherState's position matrix).
  int nodes() const { return p_.segments + 1; }
  /// \brief Unstretched segment length l = L/N [m].
  /// \return l [m].
  Scalar segment_length() const { return l_; }
  /// \brief 1/l [1/m].
  /// \return 1/l [1/m].
  Scalar inverse_segment_length() const { return inv_l_; }
  /// \brief EA/l [N/m]: the axial spring constant of one segment.
  /// \return EA/l [N/m].
  Scalar axial_spring() const { return ea_over_l_; }
  /// \brief BA/l [N s/m]: the axial damper constant of one segment.
  /// \return BA/l [N s/m] (0 without internal damping).
  Scalar axial_damper() const { return ba_over_l_; }
  /// \brief Fraction of the rest length l below which kelp's line model fades its dashpot out:
  /// see dashpot_fade().
  static constexpr double kDashpotFadeFraction = 0.1;
  /// \brief Segment length l_f [m] below which the dashpot fades out (l/10 in kelp's line
  /// model; 0, no fade, in LineModel::moordyn): see dashpot_fade().
  /// \return l_f [m].
  Scalar dashpot_fade_length() const { return fade_length_; }
  /// \brief The value of dashpot_fade(): the dashpot's factor σ and its slope.
  struct Fade {
    /// \brief σ [-] in [0, 1], and dσ/dl_s [1/m].
    ///@{
    Scalar value, slope;
    ///@}
  };
  /// \brief The dashpot's factor σ(l_s) and its slope dσ/dl_s [1/m] for a segment of length
  /// l_s [m]: the damping tension is σ(l_s) BA·ε̇. σ = ρ²(3 − 2ρ), ρ = l_s/l_f, below l_f
  /// (a smoothstep: σ(0) = 0, σ(l_f) = 1, zero slope at both), 1 above it and without a fade.
  ///
  /// Why: the dashpot pulls along the segment's direction u = (x_{s+1} − x_s)/l_s, which is
  /// undefined at l_s = 0, and its force (BA/l)(u·e) u (e = v_{s+1} − v_s) jumps when two nodes
  /// pass through each other. Clamped at zero (a cable never pushes) it resists only their
  /// separation, so two coinciding nodes stick, and an implicit step in which they would pass
  /// through each other has no solution at all (in one dimension: the nodes cannot cross
  /// without being stopped by the damping, nor be stopped before crossing without it); Newton's
  /// method then fails at any sub-step (seen with the boat's attachment point running through
  /// the first node of a slack line in a rough sea). With the fade the damping force near
  /// l_s = 0 is (BA/l)(3/l_f²)(d·e) d (d = x_{s+1} − x_s), smooth. Physically a segment folded to
  /// a tenth of its rest length is a heap of slack cable whose chord rate is no strain rate of
  /// its material (the dashpot models the material's damping of a stretching cable); the fade
  /// changes nothing while every segment is longer than l/10 (MoorDyn's validation cases, a
  /// line in tension).
  /// \param ls the segment's stretched length l_s [m] (≥ 0).
  /// \return σ(l_s) and dσ/dl_s; {1, 0} at or above l_f, and always without a fade.
  Fade dashpot_fade(Scalar ls) const {
    if (!(ls < fade_length_)) return {Scalar(1), Scalar(0)};
    const Scalar r = ls * inv_fade_length_;
    return {r * r * (Scalar(3) - Scalar(2) * r),
            Scalar(6) * r * (Scalar(1) - r) * inv_fade_length_};
  }
  /// \brief 1/l_f [1/m] (0 without a fade).
  /// \return 1/l_f [1/m].
  Scalar inverse_dashpot_fade_length() const { return inv_fade_length_; }
  /// \brief Cross-section area A = π d²/4 [m²].
  /// \return A [m²].
  Scalar area() const { return area_; }
  /// \brief Structural mass of node i [kg] (μ times its share of length, plus the point mass of a
  /// free end).
  /// \param i the node, 0 ≤ i ≤ N (not checked).
  /// \return the node's mass [kg], without added mass.
  Scalar node_mass(int i) const { return node_mass_(i); }
  /// \brief Smallest structural node mass [kg]: a lower bound on every eigenvalue of every node
  /// mass matrix (added mass only adds to it).
  /// \return min_i node_mass(i) [kg].
  Scalar min_node_mass() const { return min_node_mass_; }
  /// \brief Displaced volume of node i [m³] (A times its share of length).
  /// \param i the node, 0 ≤ i ≤ N (not checked).
  /// \return the volume [m³] (end point masses add none).
  Scalar node_volume(int i) const { return node_volume_(i); }
  /// \brief Length of line lumped at node i [m] (l, or l/2 at the ends).
  /// \param i the node, 0 ≤ i ≤ N (not checked).
  /// \return the unstretched length [m].
  Scalar node_length(int i) const { return node_length_(i); }
  /// \brief Index of the first node integrated (0 if the start end is free, else 1).
  /// \return 0 or 1.
  int first_free_node() const { return first_free_; }
  /// \brief Index of the last node integrated (N if the far end is free, else N − 1).
  /// \return N or N − 1.
  int last_free_node() const { return last_free_; }
  /// \brief Submerged weight per unit length w = (μ − ρA) g [N/m] (negative: buoyant line).
  /// \param water_density ρ [kg/m³].
  /// \param gravity g [m/s²].
  /// \return w [N/m], per unit unstretched length.
  Scalar submerged_weight_per_length(Scalar water_density, Scalar gravity) const {
    return (p_.mass_per_length - water_density * area_) * gravity;
  }

 private:
  TetherParameters<Scalar> p_;
  Scalar l_, inv_l_, ea_over_l_, ba_over_l_, area_, min_node_mass_;
  Scalar fade_length_, inv_fade_length_;
  VectorX<Scalar> node_mass_, node_volume_, node_length_;
  int first_free_ = 1, last_free_ = 0;
  bool rate_terms_ = false;
};

/// \brief Double-precision parameters.
using TetherParametersd = TetherParameters<double>;
/// \brief Double-precision model.
using TetherModeld = TetherModel<double>;
/// \brief Single-precision parameters.
using TetherParametersf = TetherParameters<float>;
/// \brief Single-precision model.
using TetherModelf = TetherModel<float>;

}  // namespace kelp::tether
