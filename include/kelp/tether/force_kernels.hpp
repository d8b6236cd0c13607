/// \file
/// \brief What the SIMD passes of the lumped-mass tether's force evaluation share: the constants
/// of one evaluation (`detail::ForcePass`), the node kinds, the pass buffer's columns, and the
/// switch between the passes' builds (`detail::wide_force_passes`). The packet kernels are in
/// kelp/tether/force_pass_body.hpp (built for the compiler flags' packets and, on x86-64, for
/// AVX2 as well, chosen at run time), the scalar passes and the public entry points in
/// kelp/tether/forces.hpp.
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <cmath>
#include <cstdint>

#include "kelp/core/kernel_path.hpp"
#include "kelp/core/types.hpp"
#include "kelp/environment/obstacles.hpp"
#include "kelp/tether/model.hpp"
#include "kelp/tether/state.hpp"

namespace kelp::tether {

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

/// What segment_wetness (kelp/tether/forces.hpp) gives for one segment: the wet shares a, b it
/// lumps on its nodes and their derivatives in the nodes' depths.
template <typename Scalar>
struct SegmentWetness {
  Scalar a, b, daa, dab, dbb;
};

/// The implicit step's momentum residual, which the force passes form in their last loop
/// (finish_block) while the node forces are in registers, instead of a pass of their own that
/// gathered the forces back: on the free nodes f0 … f1, with M_i = a_i I + b_i q_i q_iᵀ,
///   rhs_i = −R_i = γh F_i − M_i (v_i − v̂_i),
/// `r_max` = max_i max_k |R_ik| / a_i and `sum` a sum of the R_ik in which each appears once or
/// twice (the passes' last packet may overlap the one before), finite only when every R_ik is
/// (detail::implicit_attempt's convergence test and finiteness check).
template <typename Scalar>
struct ImplicitResidual {
  const Scalar* v_hat;  ///< v̂ of the step, 3 × (N+1), column-major
  Scalar gh;            ///< γh [s]
  int f0, f1;           ///< the free nodes
  Scalar* rhs;          ///< out: −R, 3 × (N+1), column-major (free columns only)
  Scalar r_max{};       ///< out: the scaled max-norm
  Scalar sum{};         ///< out: a sum of the residual's entries (finite when they all are)
};

/// Everything compute_forces' passes share: the environment's and the model's constants of one
/// evaluation, the node kinds (0 start, 1 interior, 2 end), and where the positions and
/// velocities are (column-major 3 × (N+1) with the given column strides).
template <typename Scalar>
struct ForcePass {
  const TetherParameters<Scalar>* p;
  int n;
  Scalar rho, g, bed, l, l2, inv_l, ea_l, ba_l, ea, ba, can, cat, inv_d, bed_k, bed_c;
  /// 1/l_f of the dashpot's fade (TetherModel::dashpot_fade), used when `fade`.
  Scalar inv_fade;
  /// Half the cable diameter [m]: a node at least this deep under the surface is wholly wet.
  Scalar half_d;
  bool clamp, damping, fade, still, bending, mass_turns;
  /// Segment 0 has its own rest length (a winch, TetherWorkspace::winch_length): node 0 then
  /// takes kinds[0] and node 1 kinds[3], both built for it.
  bool winch = false;
  /// Node kinds: 0 start, 1 interior, 2 end, 3 node 1 next to a winch segment.
  NodeConstants<Scalar> kinds[4];
  const Scalar* x;
  Eigen::Index xs;
  const Scalar* v;
  Eigen::Index vs;
  /// When set: M⁻¹F of every node is written here as well (3 × (N+1), column-major).
  Scalar* acc = nullptr;
  /// When set: the implicit step's residual is formed as well (ImplicitResidual).
  ImplicitResidual<Scalar>* residual = nullptr;
  /// The positions and velocities are already in TetherWorkspace::pass_buffer (compute_forces'
  /// input check put them there).
  bool inputs_ready = false;
  /// One flag per segment when the line has parted (TetherWorkspace::parted), else null.
  const std::uint8_t* parted = nullptr;
  /// The environment's obstacles (environment::ObstacleSet), or null: no contact pass at all.
  const environment::ObstacleSet* obstacles = nullptr;
  /// The last segment whose wetness the general path computed (−1: none yet) and that wetness:
  /// the positions do not change within an evaluation, so the node after it reuses it.
  mutable int wet_segment = -1;
  mutable SegmentWetness<Scalar> wet{};
  Scalar X(int k, int i) const { return x[i * xs + k]; }
  Scalar V(int k, int i) const { return v[i * vs + k]; }
  /// The positions as a 3 × (N+1) matrix.
  Eigen::Map<const Matrix3X<Scalar>, 0, Eigen::OuterStride<>> positions() const {
    return {x, 3, n + 1, Eigen::OuterStride<>(xs)};
  }
};

/// Columns of TetherWorkspace::pass_buffer.
enum PassColumn : int {
  kSegmentForce = 0,
  kNodeForce = 3,
  kMassRate = 6,
  kPosition = 9,
  kVelocity = 12
};

/// Whether a double evaluation may take the force passes' AVX2 build on a CPU with AVX2 (where
/// kelp dispatches at run time, KELP_X86_DISPATCH; true unless set otherwise), and whether the
/// implicit steps' array passes (kelp/tether/step_pass_body.hpp) and the kept-factor solve
/// (kelp/tether/kept_solve_body.hpp) may take theirs. Both builds give the same bits: the switch
/// is there for the tests that compare them and the benchmarks that measure the baseline,
/// process-wide.
inline std::atomic<bool>& wide_force_passes() {
  static std::atomic<bool> allowed{true};
  return allowed;
}

/// Whether a double evaluation takes the force passes' AVX2 build now: a dispatching build on a
/// CPU with AVX2 (checked once; GCC's and clang's check includes the OS's support), with
/// wide_force_passes() set.
inline bool force_passes_take_avx2() {
#if defined(KELP_X86_DISPATCH)
  // __builtin_cpu_init first: the check may run before libgcc's constructor that fills the CPU
  // model (a static object's constructor that evaluates forces).
  static const bool cpu_has_avx2 = (__builtin_cpu_init(), __builtin_cpu_supports("avx2"));
  return cpu_has_avx2 && wide_force_passes().load(std::memory_order_relaxed);
#else
  return false;
#endif
}

}  // namespace detail

}  // namespace kelp::tether
