/// \file
/// \brief A winch at the start end of a lumped-mass tether: the unstretched length changes with
/// a commanded payout rate limited by the winch's speed, acceleration and pull; the segment at
/// the winch (segment 0) grows and shrinks, and a node is inserted there when it passes
/// `insert_ratio`·l and removed when it falls below `remove_ratio`·l, conserving the line's mass
/// and linear momentum exactly (docs/equations.md, section "Winch").
///
/// The line's node count changes, so the winch keeps one TetherModel per segment count it can
/// reach (`WinchModel`, built once) and one workspace and one spare state per count
/// (`WinchWorkspace`, built once): a re-mesh writes the new state into the spare of the new
/// count and swaps buffers, so nothing is allocated in a step. The time-varying part (segment 0's
/// unstretched length, the payout rate) lives in TetherState (winch_length, payout_rate), so that
/// the models stay constant and a saved state reproduces a run.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "kelp/core/error.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/tether/model.hpp"
#include "kelp/tether/state.hpp"

namespace kelp::tether {

/// \brief A winch on the start end (node 0) of a tether (all magnitudes positive).
///
/// Defaults: a small electric ROV tether winch (0.5 m/s line speed, 0.5 m/s², 400 N pull).
/// \tparam Scalar double or float.
template <typename Scalar>
struct WinchParameters {
  /// Shortest unstretched line the winch leaves out [m] (≥ one nominal segment).
  Scalar min_length = Scalar(5);
  /// Longest unstretched line the winch can pay out [m]: the capacity the buffers are sized
  /// for.
  Scalar max_length = Scalar(60);
  /// Largest line speed, in or out [m/s].
  Scalar max_speed = Scalar(0.5);
  /// Largest change of line speed [m/s²].
  Scalar max_acceleration = Scalar(0.5);
  /// Largest pull the winch can reel in against [N]: above it the winch stops reeling in
  /// (its brake holds; it does not pay out by itself).
  Scalar max_pull = Scalar(400);
  /// A node is inserted when segment 0 is longer than insert_ratio·l (l the nominal segment
  /// length); it then becomes (insert_ratio − 1)·l long.
  Scalar insert_ratio = Scalar(1.5);
  /// A node is removed when segment 0 is shorter than remove_ratio·l; it then becomes
  /// (remove_ratio + 1)·l long.
  Scalar remove_ratio = Scalar(0.5);
};

/// \brief Checks winch parameters for a line of nominal segment length `l` [m].
/// \throws kelp::invalid_argument naming the field: lengths finite, min_length ≥ l,
/// max_length ≥ min_length and ≤ limits::max_length; speeds, acceleration, pull finite and > 0;
/// 0.1 ≤ remove_ratio < 1 < insert_ratio ≤ 3 and insert_ratio − remove_ratio ≥ 1 (so that
/// after either re-mesh segment 0 lies inside the band and a re-mesh cannot undo itself at once).
/// \tparam Scalar double or float.
/// \param w the winch parameters.
/// \param l the line's nominal segment length [m] (TetherParameters length / segments).
template <typename Scalar>
void validate(const WinchParameters<Scalar>& w, Scalar l) {
  check_positive(w.min_length, "winch.min_length");
  check_at_least(w.min_length, l, "winch.min_length (at least one segment)");
  check_at_least(w.max_length, w.min_length, "winch.max_length (at least min_length)");
  check_at_most(w.max_length, limits::max_length, "winch.max_length");
  check_positive(w.max_speed, "winch.max_speed");
  check_at_most(w.max_speed, limits::max_speed, "winch.max_speed");
  check_positive(w.max_acceleration, "winch.max_acceleration");
  check_positive(w.max_pull, "winch.max_pull");
  KELP_CHECK(w.remove_ratio >= Scalar(0.1) && w.remove_ratio < Scalar(1),
             "winch.remove_ratio must be in [0.1, 1)");
  KELP_CHECK(w.insert_ratio > Scalar(1) && w.insert_ratio <= Scalar(3),
             "winch.insert_ratio must be in (1, 3]");
  KELP_CHECK(w.insert_ratio - w.remove_ratio >= Scalar(1),
             "winch.insert_ratio − winch.remove_ratio must be at least 1");
}

/// \brief What the re-meshes of a winch step did: nodes inserted and removed, the line's
/// kinetic energy they took away (a merge of velocities loses kinetic energy, as an inelastic
/// collision does; ≥ 0 when the ends are at rest), and the momentum [N s] they handed to each
/// kinematic end (a removed node's share that goes to an end node whose velocity is
/// prescribed: the vehicle carrying that end takes it).
/// \tparam Scalar double or float.
template <typename Scalar>
struct RemeshReport {
  int inserted = 0;  ///< nodes inserted
  int removed = 0;   ///< nodes removed
  /// Kinetic energy of the line (structural masses) before minus after [J].
  Scalar kinetic_energy_lost = Scalar(0);
  /// Momentum handed to the start end's body [N s] (NED).
  Vector3<Scalar> impulse_on_start = Vector3<Scalar>::Zero();
  /// Momentum handed to the far end's body [N s] (NED).
  Vector3<Scalar> impulse_on_end = Vector3<Scalar>::Zero();
  /// \brief Accumulates another report.
  /// \param o the report added (counts, energy and impulses summed).
  /// \return `*this`.
  RemeshReport& operator+=(const RemeshReport& o) {
    inserted += o.inserted;
    removed += o.removed;
    kinetic_energy_lost += o.kinetic_energy_lost;
    impulse_on_start += o.impulse_on_start;
    impulse_on_end += o.impulse_on_end;
    return *this;
  }
};

/// \brief Structural mass of node i of `state` [kg] (TetherModel::node_mass with the winch
/// segment's share).
/// \tparam Scalar double or float.
/// \param model the line model that fits `state` (its node count).
/// \param state the state (its TetherState::winch_length; 0: no winch).
/// \param i the node, 0 ≤ i ≤ N (not checked).
/// \return m_i [kg], added mass excluded.
template <typename Scalar>
Scalar node_mass(const TetherModel<Scalar>& model, const TetherState<Scalar>& state, int i) {
  return model.node_mass(i) + model.parameters().mass_per_length *
                                  detail::winch_extra_length(model, state.winch_length, i);
}

/// \brief Unstretched length of the line [m]: (N − 1)·l + l_w with a winch, N·l without.
/// \tparam Scalar double or float.
/// \param model the line model that fits `state`.
/// \param state the state (its TetherState::winch_length l_w; 0: no winch).
/// \return the line out [m].
template <typename Scalar>
Scalar unstretched_length(const TetherModel<Scalar>& model, const TetherState<Scalar>& state) {
  const Scalar l = model.segment_length();
  return state.winch_length > Scalar(0) ? Scalar(model.segments() - 1) * l + state.winch_length
                                        : Scalar(model.segments()) * l;
}

/// \brief Structural mass of the line Σ m_i [kg] (point masses of free ends included).
/// \tparam Scalar double or float.
/// \param model the line model that fits `state`.
/// \param state the state (its winch length).
/// \return Σ m_i [kg], added mass excluded.
template <typename Scalar>
Scalar line_mass(const TetherModel<Scalar>& model, const TetherState<Scalar>& state) {
  Scalar m(0);
  for (int i = 0; i < model.nodes(); ++i) m += node_mass(model, state, i);
  return m;
}

/// \brief Linear momentum of the line Σ m_i v_i [kg m/s] (structural masses, NED).
/// \tparam Scalar double or float.
/// \param model the line model that fits `state`.
/// \param state the state (velocities NED [m/s], winch length).
/// \return Σ m_i v_i, NED [kg m/s] (kinematic end nodes included).
template <typename Scalar>
Vector3<Scalar> line_momentum(const TetherModel<Scalar>& model, const TetherState<Scalar>& state) {
  Vector3<Scalar> p = Vector3<Scalar>::Zero();
  for (int i = 0; i < model.nodes(); ++i) p += node_mass(model, state, i) * state.velocity.col(i);
  return p;
}

/// \brief Inserts a node in segment 0 of `in` (a line of N segments on `from`, segment 0 of
/// rest length l_w > l) into `out` (a state sized for N + 1 segments: buffers reused, nothing
/// allocated once sized). Segment 0 becomes l_w − l long, the new node 1 is at the point that
/// splits segment 0 in those proportions, x₁' = x₀ + (l_w − l)/l_w (x₁ − x₀), with the
/// mass-weighted velocity of the mass it takes over from nodes 0 and 1, v₁' = (l v₀ + (l_w − l)
/// v₁)/l_w: mass and momentum are conserved exactly, kinetic energy is lost (Jensen). The
/// integrator history restarts (see docs/equations.md: the BDF2 choice). Parted flags follow
/// their segments.
/// \tparam Scalar double or float.
/// \param from the model of N segments that fits `in`.
/// \param in the state before (its winch_length, or l when 0, must exceed l).
/// \param[out] out the state after, already sized for N + 1 segments (N + 2 columns): positions,
/// velocities, clock, winch fields and parted flags are written, the history, the kept Newton
/// matrix and the accelerations cleared (previous_position, previous_velocity and acceleration
/// keep their old content).
/// \param[in,out] report counts the insertion and adds the kinetic energy lost [J].
/// \throws kelp::invalid_argument when `out` has the wrong size or segment 0 is not longer
/// than l (nothing written then).
template <typename Scalar>
void insert_winch_node(const TetherModel<Scalar>& from, const TetherState<Scalar>& in,
                       TetherState<Scalar>& out, RemeshReport<Scalar>& report) {
  const int n = from.segments();
  const Scalar l = from.segment_length();
  const Scalar lw = in.winch_length > Scalar(0) ? in.winch_length : l;
  KELP_CHECK(out.position.cols() == n + 2 && out.velocity.cols() == n + 2,
             "insert_winch_node: out must have N + 2 columns");
  KELP_CHECK(lw > l, "insert_winch_node: segment 0 must be longer than l");
  const Scalar mu = from.parameters().mass_per_length;
  const Scalar a = (lw - l) / lw;  // the new node's place along segment 0, from node 0
  const Vector3<Scalar> x0 = in.position.col(0), x1 = in.position.col(1);
  const Vector3<Scalar> v0 = in.velocity.col(0), v1 = in.velocity.col(1);
  out.position.col(0) = x0;
  out.velocity.col(0) = v0;
  out.position.col(1) = x0 + a * (x1 - x0);
  out.velocity.col(1) = (l * v0 + (lw - l) * v1) / lw;
  out.position.rightCols(n) = in.position.rightCols(n);
  out.velocity.rightCols(n) = in.velocity.rightCols(n);
  // Kinetic energy of nodes 0..2 after minus before (nodes beyond keep theirs). Masses: before
  // m0 = μ l_w/2, m1 = μ(l_w + l)/2 (μ l_w/2 + end point mass if node 1 is a free far end);
  // after m0' = μ(l_w − l)/2, m1' = μ l_w/2, m2' = m1 − μ(l_w − l)/2.
  const Scalar m0 = node_mass(from, in, 0), m1 = node_mass(from, in, 1);
  const Scalar m0n = mu * (lw - l) / Scalar(2), m1n = mu * lw / Scalar(2);
  const Scalar m2n = (m0 + m1) - (m0n + m1n);  // μ l (μ l/2 plus a point mass at a free far end)
  const Vector3<Scalar> vk = out.velocity.col(1);
  const Scalar before = m0 * v0.squaredNorm() + m1 * v1.squaredNorm();
  const Scalar after = m0n * v0.squaredNorm() + m1n * vk.squaredNorm() + m2n * v1.squaredNorm();
  report.kinetic_energy_lost += Scalar(0.5) * (before - after);
  ++report.inserted;
  out.time = in.time;
  out.time_carry = in.time_carry;
  out.payout_rate = in.payout_rate;
  out.winch_length = lw - l;
  out.clear_history();
  // The parted flags (TetherState::parted) follow their segments: old segment 0 is new segments
  // 0 and 1, and a parting in it stays on the winch's side (new segment 0).
  out.parted.setZero(n + 1);
  if (in.parted.size() == n) {
    out.parted(0) = in.parted(0);
    out.parted.tail(n - 1) = in.parted.tail(n - 1);
  }
}

/// \brief Removes node 1 of `in` (a line of N ≥ 2 segments on `from`) into `out` (sized for
/// N − 1 segments). Segment 0 becomes l_w + l long. Node 1's mass μ(l_w + l)/2 goes to its
/// neighbours as the new segment 0 lumps it: μ l/2 to node 0, μ l_w/2 to node 2, with its
/// momentum in the same shares: a free node 2 gets v₂' = (m₂ v₂ + μ l_w/2 v₁)/(m₂ + μ l_w/2);
/// the share of a kinematic node (node 0 always, node 2 when it is a kinematic far end), whose
/// velocity is prescribed, goes to the body that carries it (report.impulse_on_start / _end).
/// Mass and momentum (line plus those impulses) are conserved exactly. The history restarts.
/// The start end must be kinematic (a winch sits on a body; WinchModel requires it): the share
/// of a free node 0 would be handed to a body that is not there.
/// \tparam Scalar double or float.
/// \param from the model of N ≥ 2 segments that fits `in`.
/// \param in the state before.
/// \param[out] out the state after, already sized for N − 1 segments (N columns), written as by
/// insert_winch_node().
/// \param[in,out] report counts the removal, adds the kinetic energy lost [J] and the impulses
/// handed to the ends, NED [N s].
/// \throws kelp::invalid_argument when the start end is not kinematic, N < 2 or `out` has the
/// wrong size (nothing written then).
template <typename Scalar>
void remove_winch_node(const TetherModel<Scalar>& from, const TetherState<Scalar>& in,
                       TetherState<Scalar>& out, RemeshReport<Scalar>& report) {
  const int n = from.segments();
  KELP_CHECK(from.parameters().start_mode == EndMode::kinematic,
             "remove_winch_node: the start end must be kinematic (the winch sits on a body)");
  KELP_CHECK(n >= 2, "remove_winch_node: the line must have at least two segments");
  KELP_CHECK(out.position.cols() == n && out.velocity.cols() == n,
             "remove_winch_node: out must have N columns");
  const Scalar l = from.segment_length();
  const Scalar lw = in.winch_length > Scalar(0) ? in.winch_length : l;
  const Scalar mu = from.parameters().mass_per_length;
  const Vector3<Scalar> v0 = in.velocity.col(0), v1 = in.velocity.col(1), v2 = in.velocity.col(2);
  const Scalar m0 = node_mass(from, in, 0), m1 = node_mass(from, in, 1),
               m2 = node_mass(from, in, 2);
  const Scalar to0 = mu * l / Scalar(2), to2 = m1 - to0;  // node 1's shares (μ l/2, μ l_w/2)
  const bool end_kinematic = n == 2 && from.parameters().end_mode == EndMode::kinematic;
  out.position.col(0) = in.position.col(0);
  out.velocity.col(0) = v0;
  out.position.rightCols(n - 1) = in.position.rightCols(n - 1);
  out.velocity.rightCols(n - 1) = in.velocity.rightCols(n - 1);
  Vector3<Scalar> v2n = v2;
  if (end_kinematic)
    report.impulse_on_end += to2 * (v1 - v2);
  else
    v2n = (m2 * v2 + to2 * v1) / (m2 + to2);
  out.velocity.col(1) = v2n;
  report.impulse_on_start += to0 * (v1 - v0);
  const Scalar before = m0 * v0.squaredNorm() + m1 * v1.squaredNorm() + m2 * v2.squaredNorm();
  const Scalar after = (m0 + to0) * v0.squaredNorm() + (m2 + to2) * v2n.squaredNorm();
  report.kinetic_energy_lost += Scalar(0.5) * (before - after);
  ++report.removed;
  out.time = in.time;
  out.time_carry = in.time_carry;
  out.payout_rate = in.payout_rate;
  out.winch_length = lw + l;
  out.clear_history();
  // The parted flags follow their segments: old segments 0 and 1 are new segment 0.
  out.parted.setZero(n - 1);
  if (in.parted.size() == n) {
    out.parted(0) = std::uint8_t(in.parted(0) || in.parted(1));
    out.parted.tail(n - 2) = in.parted.tail(n - 2);
  }
}

/// \brief The winch and the line at every segment count it can reach: one TetherModel per
/// count N in [min_segments, max_segments], all with the nominal segment length
/// l = line.length / line.segments (the line's initial length and count). Built once; constant.
/// \tparam Scalar double or float.
template <typename Scalar>
class WinchModel {
 public:
  /// \throws kelp::invalid_argument naming the field (validate(TetherParameters),
  /// validate(WinchParameters)); the start end must be kinematic (the winch sits on a body), and
  /// the line's initial length must be within [min_length, max_length].
  /// \param line the tether as it starts (its length and segment count set l and the initial
  /// count; every other parameter is shared by all counts).
  /// \param w the winch.
  WinchModel(const TetherParameters<Scalar>& line, const WinchParameters<Scalar>& w) : winch_(w) {
    validate(line);
    l_ = line.length / Scalar(line.segments);
    validate(w, l_);
    KELP_CHECK(line.start_mode == EndMode::kinematic,
               "winch: the tether's start end (the winch) must be kinematic");
    check_at_least(line.length, w.min_length, "tether.length (at least winch.min_length)");
    check_at_most(line.length, w.max_length, "tether.length (at most winch.max_length)");
    // L = (N − 1) l + l_w with l_w in [remove_ratio l, insert_ratio l].
    const double ll = double(value_of(l_));
    min_n_ = std::max(1, int(std::floor(double(value_of(w.min_length)) / ll + 1.0 -
                                        double(value_of(w.insert_ratio)))));
    max_n_ = int(
        std::ceil(double(value_of(w.max_length)) / ll + 1.0 - double(value_of(w.remove_ratio))));
    KELP_CHECK(max_n_ <= limits::max_segments, "winch.max_length / segment length: too many");
    models_.reserve(std::size_t(max_n_ - min_n_ + 1));
    for (int n = min_n_; n <= max_n_; ++n) {
      TetherParameters<Scalar> p = line;
      p.segments = n;
      p.length = l_ * Scalar(n);
      models_.emplace_back(p);
    }
    initial_n_ = line.segments;
  }
  /// \brief The winch's parameters.
  /// \return the parameters given to the constructor.
  const WinchParameters<Scalar>& winch() const { return winch_; }
  /// \brief Nominal segment length l [m].
  /// \return l [m], the same for every count.
  Scalar segment_length() const { return l_; }
  /// \brief Fewest segments the line can have (at min_length).
  /// \return the smallest count N ≥ 1.
  int min_segments() const { return min_n_; }
  /// \brief Most segments the line can have (at max_length).
  /// \return the largest count N.
  int max_segments() const { return max_n_; }
  /// \brief Segment count of the line as built.
  /// \return TetherParameters::segments of the constructor's line.
  int initial_segments() const { return initial_n_; }
  /// \brief The line with `segments` segments.
  /// \param segments the count N, in [min_segments(), max_segments()].
  /// \return its model (valid for the WinchModel's life).
  /// \throws kelp::invalid_argument outside [min_segments, max_segments].
  const TetherModel<Scalar>& line(int segments) const {
    KELP_CHECK(segments >= min_n_ && segments <= max_n_,
               "WinchModel::line: segment count outside the winch's range");
    return models_[std::size_t(segments - min_n_)];
  }
  /// \brief The line model that fits `state` (its column count).
  /// \param state a state of the winch line.
  /// \return line(columns − 1).
  /// \throws kelp::invalid_argument when the state's count is outside the winch's range.
  const TetherModel<Scalar>& line_of(const TetherState<Scalar>& state) const {
    return line(int(state.position.cols()) - 1);
  }

 private:
  WinchParameters<Scalar> winch_;
  Scalar l_;
  int min_n_ = 1, max_n_ = 1, initial_n_ = 1;
  std::vector<TetherModel<Scalar>> models_;
};

/// \brief Buffers for a winch line: one TetherWorkspace, one spare TetherState and one
/// StateBackup per segment count of the WinchModel, built once (about 1.6 kB per node and count
/// in double). The slot of the current count is lent out: its buffers are the caller's
/// (kelp::system keeps them in SystemWorkspace::tether and SystemState::tether) and
/// `lend` and advance_winch() move buffers by swapping, never by copying.
/// \tparam Scalar double or float.
template <typename Scalar>
struct WinchWorkspace {
  std::vector<TetherWorkspace<Scalar>> line;  ///< workspace per segment count
  std::vector<TetherState<Scalar>> spare;     ///< spare state per segment count
  std::vector<StateBackup<Scalar>> backup;    ///< state backup per segment count
  int min_n = 1;                              ///< segment count of slot 0

  WinchWorkspace() = default;
  /// \brief Buffers for every count of `model`.
  /// \param model the winch line (its range of counts; no reference kept).
  explicit WinchWorkspace(const WinchModel<Scalar>& model) : min_n(model.min_segments()) {
    const int k = model.max_segments() - model.min_segments() + 1;
    line.reserve(std::size_t(k));
    spare.reserve(std::size_t(k));
    backup.resize(std::size_t(k));
    for (int n = model.min_segments(); n <= model.max_segments(); ++n) {
      line.emplace_back(model.line(n));
      spare.emplace_back(model.line(n));
      backup[std::size_t(n - min_n)].resize(n + 1);
    }
  }
  /// \brief Slot index of `segments`.
  /// \param segments a count N ≥ min_n (not checked).
  /// \return N − min_n, the index into `line`, `spare` and `backup`.
  std::size_t slot(int segments) const { return std::size_t(segments - min_n); }

  /// \brief Makes `ws` (the line buffers lent out, sized for the count last stepped) the
  /// buffers of `segments` segments, and every spare state but that count's sized for its own
  /// count: for stepping a state of another count than the one these buffers followed (a state
  /// loaded from a file, or a copy restored after the winch re-meshed). The line buffers are
  /// swapped; a spare state is rebuilt (an allocation) only when it holds another count's
  /// buffers (at most one: the count lent before). Call it between steps.
  /// \throws kelp::invalid_argument when `segments` is outside the model's range or `ws` holds
  /// no count of it (nothing changed then).
  /// \param model the winch line the workspace was built for.
  /// \param[in,out] ws the line buffers lent out (sized for one of the model's counts); on
  /// return sized for `segments`.
  /// \param segments the count N of the state to be stepped next.
  void lend(const WinchModel<Scalar>& model, TetherWorkspace<Scalar>& ws, int segments) {
    KELP_CHECK(segments >= model.min_segments() && segments <= model.max_segments() &&
                   model.min_segments() == min_n &&
                   std::size_t(model.max_segments() - min_n + 1) == line.size(),
               "WinchWorkspace::lend: segment count outside the winch's range, or a workspace "
               "built for another winch");
    const int from = int(ws.force.cols()) - 1;
    KELP_CHECK(from >= model.min_segments() && from <= model.max_segments() && ws.fits(from + 1),
               "WinchWorkspace::lend: the lent buffers are not one of the winch's counts");
    if (from != segments) {
      using std::swap;
      swap(ws, line[slot(segments)]);
      swap(line[slot(segments)], line[slot(from)]);
    }
    for (int n = model.min_segments(); n <= model.max_segments(); ++n) {
      TetherState<Scalar>& s = spare[slot(n)];
      if (n != segments && (s.position.cols() != n + 1 || s.velocity.cols() != n + 1))
        s = TetherState<Scalar>(model.line(n));
    }
  }
};

/// \brief The payout rate [m/s] the winch reaches in a step of dt [s] from `rate` towards
/// `command`: at most max_acceleration·dt away, at most max_speed in magnitude, not reeling in
/// while the pull at the winch is at least max_pull, and neither past max_length nor below
/// min_length over the step from the unstretched length `length` [m].
/// \tparam Scalar double or float.
/// \param w the winch.
/// \param rate the payout rate now [m/s] (positive: paying out).
/// \param command the commanded payout rate [m/s].
/// \param pull the pull at the winch [N] (winch_pull()).
/// \param length the unstretched line out now [m].
/// \param dt the step [s], > 0 (not checked).
/// \return the payout rate over the step [m/s].
template <typename Scalar>
Scalar limited_payout_rate(const WinchParameters<Scalar>& w, Scalar rate, Scalar command,
                           Scalar pull, Scalar length, double dt) {
  const Scalar h(dt);
  const Scalar dv = w.max_acceleration * h;
  Scalar r = std::min(std::max(command, rate - dv), rate + dv);
  r = std::min(std::max(r, -w.max_speed), w.max_speed);
  if (r < Scalar(0) && pull >= w.max_pull) r = Scalar(0);
  r = std::min(r, (w.max_length - length) / h);
  r = std::max(r, (w.min_length - length) / h);
  return r;
}

/// \brief A payout rate [m/s] that brings the unstretched length from `length` to `target` [m]
/// as fast as the winch allows and stops there: ±√(2 a |e|), at most max_speed (the
/// time-optimal profile under the acceleration limit; limited_payout_rate limits it further).
/// \tparam Scalar double or float.
/// \param w the winch (max_speed, max_acceleration).
/// \param length the unstretched line out now [m].
/// \param target the line out wanted [m].
/// \return the payout rate [m/s], positive to pay out, 0 at the target.
template <typename Scalar>
Scalar payout_rate_for_length(const WinchParameters<Scalar>& w, Scalar length, Scalar target) {
  using std::abs;
  using std::sqrt;
  const Scalar e = target - length;
  const Scalar s = std::min(w.max_speed, sqrt(Scalar(2) * w.max_acceleration * abs(e)));
  return e >= Scalar(0) ? s : -s;
}

/// \brief Pull of the line at the winch [N]: the elastic tension of segment 0 in `state`,
/// EA·max(0, |x₁ − x₀| − l_w)/l_w (from the state alone, so that a restored state reproduces it).
/// \tparam Scalar double or float.
/// \param model the line model that fits `state` (EA, l).
/// \param state the state (nodes 0 and 1, winch_length; 0: l).
/// \return the pull [N], ≥ 0 (no dashpot term).
template <typename Scalar>
Scalar winch_pull(const TetherModel<Scalar>& model, const TetherState<Scalar>& state) {
  const Scalar lw = state.winch_length > Scalar(0) ? state.winch_length : model.segment_length();
  const Scalar ls = (state.position.col(1) - state.position.col(0)).norm();
  return ls > lw ? model.parameters().axial_stiffness * (ls - lw) / lw : Scalar(0);
}

namespace detail {
/// Moves the buffers of count `to` (spare[to] holding the new state) into `state` and `ws`, and
/// those of count `from` back into their slots: swaps only.
template <typename Scalar>
void winch_switch(WinchWorkspace<Scalar>& w, TetherState<Scalar>& state,
                  TetherWorkspace<Scalar>& ws, int from, int to) {
  using std::swap;
  const std::size_t a = w.slot(from), b = w.slot(to);
  swap(state, w.spare[b]);
  swap(w.spare[b], w.spare[a]);
  swap(ws, w.line[b]);
  swap(w.line[b], w.line[a]);
}
}  // namespace detail

/// \brief One step of the winch before the line's step of dt [s]: the payout rate moves towards
/// `command` [m/s] within the winch's limits (limited_payout_rate, with the pull winch_pull of
/// the state), segment 0's unstretched length changes by rate·dt, and nodes are inserted or
/// removed (insert_winch_node, remove_winch_node) until it is inside [remove_ratio·l,
/// insert_ratio·l]. `state` and `ws` are the line's current buffers (sized for its count N, the
/// WinchModel's line(N)); after a re-mesh they hold the buffers of the new count (swapped with
/// `w`'s slots, nothing allocated). Segment 0's length is constant over the line's step that
/// follows (the payout is explicit in time: the new line enters the step at rest relative to
/// nodes 0 and 1, whose masses grow or shrink with it).
/// \throws kelp::invalid_argument for a non-finite command, dt ≤ 0, a state whose winch_length
/// is negative or not finite or whose payout_rate is not finite, or when the state does not fit
/// the winch (nothing changed then).
/// \tparam Scalar double or float.
/// \param model the winch line.
/// \param[in,out] w the winch's buffers (built for `model`).
/// \param[in,out] state the line's state, of a count in the model's range; its winch_length
/// (finite, ≥ 0; 0 is read as l) and payout_rate (finite) are updated, and its buffers swapped on a
/// re-mesh.
/// \param[in,out] ws the line's workspace, sized for the state's count; swapped with it.
/// \param command the commanded payout rate [m/s] (positive: pay out).
/// \param dt the line's coming step [s], > 0.
/// \return the re-meshes done (nodes inserted and removed, energy lost, impulses to the ends).
template <typename Scalar>
RemeshReport<Scalar> advance_winch(const WinchModel<Scalar>& model, WinchWorkspace<Scalar>& w,
                                   TetherState<Scalar>& state, TetherWorkspace<Scalar>& ws,
                                   Scalar command, double dt) {
  check_finite(command, "winch command (payout rate)");
  check_positive(dt, "dt");
  // The line's steps check these too, but the winch may be advanced on a state no step has
  // seen: a NaN length would be read as l below, a NaN rate lose the acceleration limit.
  check_finite(state.winch_length, "state.winch_length");
  check_finite(state.payout_rate, "state.payout_rate");
  // 0 means l (no winch segment yet); a negative length is none (the line's step refuses it).
  if (state.winch_length < Scalar(0))
    ::kelp::detail::throw_invalid_argument("advance_winch: state.winch_length must be >= 0");
  const int n0 = int(state.position.cols()) - 1;
  const TetherModel<Scalar>& line0 = model.line(n0);
  KELP_CHECK(ws.fits(line0.nodes()), "advance_winch: workspace and state of different lines");
  const WinchParameters<Scalar>& wp = model.winch();
  const Scalar l = model.segment_length();
  if (!(state.winch_length > Scalar(0))) state.winch_length = l;
  const Scalar length = unstretched_length(line0, state);
  const Scalar rate =
      limited_payout_rate(wp, state.payout_rate, command, winch_pull(line0, state), length, dt);
  state.payout_rate = rate;
  state.winch_length += rate * Scalar(dt);
  RemeshReport<Scalar> report;
  for (;;) {
    const int n = int(state.position.cols()) - 1;
    const TetherModel<Scalar>& line = model.line(n);
    if (state.winch_length > wp.insert_ratio * l && n < model.max_segments()) {
      insert_winch_node(line, state, w.spare[w.slot(n + 1)], report);
      detail::winch_switch(w, state, ws, n, n + 1);
    } else if (state.winch_length < wp.remove_ratio * l && n > std::max(1, model.min_segments())) {
      remove_winch_node(line, state, w.spare[w.slot(n - 1)], report);
      detail::winch_switch(w, state, ws, n, n - 1);
    } else {
      break;
    }
  }
  return report;
}

/// \brief Double-precision winch parameters.
using WinchParametersd = WinchParameters<double>;
/// \brief Double-precision winch model.
using WinchModeld = WinchModel<double>;
/// \brief Double-precision winch buffers.
using WinchWorkspaced = WinchWorkspace<double>;
/// \brief Double-precision re-mesh report.
using RemeshReportd = RemeshReport<double>;
/// \brief Single-precision winch parameters.
using WinchParametersf = WinchParameters<float>;
/// \brief Single-precision winch model.
using WinchModelf = WinchModel<float>;
/// \brief Single-precision winch buffers.
using WinchWorkspacef = WinchWorkspace<float>;
/// \brief Single-precision re-mesh report.
using RemeshReportf = RemeshReport<float>;

}  // namespace kelp::tether
