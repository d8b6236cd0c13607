/// \file
/// \brief The tether turn counter: the accumulated yaw of the ROV relative to the tether's
/// direction at its attachment, in turns, as ROV operators watch it to keep the tether from
/// twisting (OpenROV issue #472 asks for one for that reason).
///
/// Part of kelp::sim (ClosedLoop keeps one: every program on kelp::sim logs it), but it needs
/// only a vehicle state and a tether state.
#pragma once

#include <algorithm>
#include <cmath>

#include "kelp/core/angles.hpp"
#include "kelp/core/constants.hpp"
#include "kelp/core/memory.hpp"
#include "kelp/core/types.hpp"
#include "kelp/tether/state.hpp"
#include "kelp/vehicle/state.hpp"

namespace kelp {
namespace sim {

/// \brief Counts the turns of a vehicle about the tether at its attachment.
///
/// At every update: the vehicle's heading ψ (the azimuth of its body x axis in NED, atan2 of the
/// rotation matrix's (1,0) and (0,0) entries, so that it is defined at any roll and pitch short of
/// the body x axis pointing straight up or down) and the tether's azimuth α at the attachment: the
/// horizontal direction from the attachment node to the first node at least `reference_length`
/// of line away from it (or the line's other end). The relative angle φ = ψ − α is unwrapped
/// continuously: each update adds its change wrapped to (−π, π], so the count is signed
/// (positive: the vehicle turned clockwise seen from above, NED's positive yaw, relative to the
/// tether) and continuous through any number of turns, as long as φ changes by less than half a
/// turn between two updates (the sim updates at every 10 ms step).
///
/// Why a reference length rather than the last segment: the lumped-mass line has no torsion, so a
/// vehicle spinning on the spot drags its last segment round with the attachment point (a 0.2 m
/// lever on a 0.5 m segment), and the last segment's azimuth would follow the vehicle's heading;
/// a metre or two of line away the line's direction is where the line goes, which is what the
/// tether twists (or wraps) against.
///
/// A tether within `vertical_angle` of the vertical at the attachment has no meaningful azimuth:
/// α is then held at its last value (at the first update, the vehicle's heading, so φ starts at 0),
/// and the vehicle's own yaw counts in full, which is the twist about a vertical tether. Each
/// piece of a parted line still has its segments at the vehicle, whose direction is used.
class TurnCounter {
 public:
  /// Angle from the vertical [rad] within which the tether's azimuth is held (0.1 rad ≈ 5.7°).
  static constexpr double vertical_angle = 0.1;

  /// \brief A counter that takes the tether's direction over `reference_length` [m] of line
  /// (default 2 m; 0: the attachment's own segment).
  /// \param reference_length the length of line [m], ≥ 0.
  explicit TurnCounter(double reference_length = 2.0) : reference_(reference_length) {}

  /// \brief Updates the count with the vehicle state `vehicle` and the tether state `tether`,
  /// whose node `node` is the vehicle's attachment (0 or the last node).
  /// \param vehicle the vehicle's state (NED attitude). \param tether the tether's state (NED
  /// node positions [m]). \param node the attachment node's index.
  void update(const vehicle::VehicleStated& vehicle, const tether::TetherStated& tether, int node) {
    const Matrix3<double> r = vehicle.attitude.toRotationMatrix();
    const double heading = std::atan2(r(1, 0), r(0, 0));
    const int last = int(tether.position.cols()) - 1;
    const int step = node == 0 ? 1 : -1;
    // The first node at least reference_ of line away (along the nodes), or the other end.
    int other = node;
    double along = 0.0;
    while (other + step >= 0 && other + step <= last) {
      along += (tether.position.col(other + step) - tether.position.col(other)).norm();
      other += step;
      if (along >= reference_) break;
    }
    const Vector3<double> d = tether.position.col(other) - tether.position.col(node);
    const double horizontal = d.head<2>().norm();
    if (horizontal > std::sin(vertical_angle) * d.norm() && horizontal > 0.0)
      azimuth_ = std::atan2(d.y(), d.x());
    else if (!started_)
      azimuth_ = heading;
    const double phi = heading - azimuth_;
    if (started_) {
      turns_ += kelp::wrap_angle_exact(phi - phi_) / (2.0 * kelp::pi);
      max_abs_ = std::max(max_abs_, std::abs(turns_));
    }
    phi_ = phi;
    started_ = true;
  }

  /// \brief Net turns since the first update (signed; clockwise seen from above is positive).
  /// \return turns [-] (1 = 2π rad).
  double turns() const { return turns_; }
  /// \brief Largest |turns()| so far. \return turns [-].
  double max_abs_turns() const { return max_abs_; }
  /// \brief visit_memory(v): the azimuth, the angle and the counts (kelp/core/memory.hpp).
  /// \tparam V a memory visitor \param v the visitor
  KELP_MEMORY(azimuth_, phi_, turns_, max_abs_, started_)

 private:
  double reference_ = 2.0, azimuth_ = 0.0, phi_ = 0.0, turns_ = 0.0, max_abs_ = 0.0;
  bool started_ = false;
};

}  // namespace sim
}  // namespace kelp
