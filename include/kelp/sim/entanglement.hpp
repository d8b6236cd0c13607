/// \file
/// \brief Entanglement of the tether with cylinder-like obstacles (piles, mooring lines,
/// risers): per obstacle, the tether's winding angle about its axis over a run
/// (kelp::tether::winding_angle), and two events, `entangled` (the winding passes a threshold,
/// by default one full wrap) and `pinned` (friction at a contact holds the line while the ROV
/// pulls). Definitions and their reasons: docs/entanglement.md.
///
/// Part of kelp::sim (ClosedLoop keeps one beside its TurnCounter), but it needs only tether
/// states and the obstacles' axes.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/memory.hpp"
#include "kelp/core/types.hpp"
#include "kelp/tether/winding.hpp"

namespace kelp {
namespace sim {

/// \brief A cylinder-like obstacle as the entanglement monitor sees it: its axis (through `from`
/// and `to`, NED [m]) and its radius [m].
struct EntanglementAxis {
  std::string name;  ///< named in events and in the summary
  int index = 0;     ///< its index in the scenario's obstacles
  kelp::Vector3<double> from = kelp::Vector3<double>::Zero();  ///< one end of the axis
  kelp::Vector3<double> to = kelp::Vector3<double>::UnitZ();   ///< the other end
  double radius = 0.1;                                         ///< [m], > 0
};

/// \brief Thresholds of the entanglement events (defaults: docs/entanglement.md).
struct EntanglementSettings {
  /// |winding| [rad] at which `entangled` fires (one full wrap); it fires again only after
  /// |winding| has fallen below `wrap_threshold - wrap_hysteresis`.
  double wrap_threshold = 2.0 * kelp::pi;
  double wrap_hysteresis = 0.5 * kelp::pi;  ///< [rad], in [0, wrap_threshold]
  /// A node touches the obstacle when its distance from the axis segment is below the radius
  /// plus the tether's radius plus this margin [m].
  double contact_margin = 0.01;
  /// Pinned: the line's mean speed along itself at the contact nodes is below this [m/s]
  /// (it sticks: the regularised friction is below its Coulomb limit, which the tether's
  /// friction reaches above its friction_velocity, 0.01 m/s by default)...
  double pin_slip_speed = 0.02;
  /// ... while the axial force on the ROV's side of the contact exceeds the boat's side by at
  /// least this [N] (the ROV pulls and friction at the contact carries the difference) ...
  double pin_tension_difference = 20.0;
  /// ... for at least this long [s].
  double pin_hold_time = 0.5;
};

/// \brief Checks the settings. \throws kelp::invalid_argument naming the field.
/// \param s the settings: wrap_threshold > 0, wrap_hysteresis in [0, wrap_threshold],
/// contact_margin ≥ 0, pin_slip_speed > 0, pin_tension_difference > 0, pin_hold_time ≥ 0, all
/// finite
inline void validate(const EntanglementSettings& s) {
  KELP_CHECK(std::isfinite(s.wrap_threshold) && s.wrap_threshold > 0,
             "entanglement.wrap_threshold must be finite and > 0");
  KELP_CHECK(std::isfinite(s.wrap_hysteresis) && s.wrap_hysteresis >= 0 &&
                 s.wrap_hysteresis <= s.wrap_threshold,
             "entanglement.wrap_hysteresis must be in [0, wrap_threshold]");
  KELP_CHECK(std::isfinite(s.contact_margin) && s.contact_margin >= 0,
             "entanglement.contact_margin must be finite and >= 0");
  KELP_CHECK(std::isfinite(s.pin_slip_speed) && s.pin_slip_speed > 0,
             "entanglement.pin_slip_speed must be finite and > 0");
  KELP_CHECK(std::isfinite(s.pin_tension_difference) && s.pin_tension_difference > 0,
             "entanglement.pin_tension_difference must be finite and > 0");
  KELP_CHECK(std::isfinite(s.pin_hold_time) && s.pin_hold_time >= 0,
             "entanglement.pin_hold_time must be finite and >= 0");
}

/// \brief An entanglement event.
struct EntanglementEvent {
  /// What happened.
  enum class Kind {
    entangled,  ///< |winding| passed EntanglementSettings::wrap_threshold
    pinned      ///< friction has held the line at the contact while the ROV pulls
  };
  Kind kind = Kind::entangled;  ///< what happened
  double time = 0;              ///< [s]
  int obstacle = 0;             ///< index in the monitor's axes
  double value = 0;  ///< entangled: the winding [rad]; pinned: the tension difference [N]
  kelp::Vector3<double> position = kelp::Vector3<double>::Zero();  ///< mid contact node (NED [m])
};

/// \brief The name of an event kind as events.csv writes it ("entangled", "pinned").
/// \param k the kind \return its name (static storage)
inline const char* event_name(EntanglementEvent::Kind k) {
  return k == EntanglementEvent::Kind::entangled ? "entangled" : "pinned";
}

/// \brief What the monitor knows of one obstacle.
struct ObstacleWinding {
  double winding = 0;             ///< current winding angle [rad]
  double max_abs_winding = 0;     ///< largest |winding| so far [rad]
  int contact_nodes = 0;          ///< nodes touching it now
  double tension_difference = 0;  ///< ROV side minus boat side of the contact now [N]
  double slip_speed = 0;          ///< mean |speed along the line| at the contact nodes [m/s]
  bool entangled = false;         ///< |winding| is past the threshold (with hysteresis)
  bool pinned = false;            ///< pinned now (the hold time has passed)
  double pin_since = std::numeric_limits<double>::quiet_NaN();        ///< start of the current hold
  double first_entangled = std::numeric_limits<double>::quiet_NaN();  ///< time of the first
  double first_pinned = std::numeric_limits<double>::quiet_NaN();     ///< time of the first
};

/// \brief Follows the tether's winding about each axis and raises the events.
///
/// update() is called after every step with the tether's nodes (start end, the boat's, first)
/// and, for the `pinned` test, the axial force of every segment. It allocates nothing (the event
/// list has a capacity fixed at construction; events beyond it are counted, not kept).
class EntanglementMonitor {
 public:
  /// Events kept at most (further ones are counted in dropped_events()).
  static constexpr std::size_t max_events = 256;

  /// \brief A monitor of `axes` with `settings`; `tether_radius` [m] widens the contact test and
  /// the chord's blend radius (kelp::tether::winding_angle's b = obstacle radius + tether radius).
  /// \param axes the obstacles' axes (NED [m]; the events' obstacle indices index it)
  /// \param settings the events' thresholds \param tether_radius the tether's radius [m], ≥ 0
  /// \throws kelp::invalid_argument for bad settings or axes (non-finite, from == to, radius ≤ 0).
  explicit EntanglementMonitor(std::vector<EntanglementAxis> axes,
                               const EntanglementSettings& settings = {},
                               double tether_radius = 0.0)
      : axes_(std::move(axes)), settings_(settings), tether_radius_(tether_radius) {
    validate(settings_);
    KELP_CHECK(std::isfinite(tether_radius) && tether_radius >= 0,
               "EntanglementMonitor: tether_radius must be finite and >= 0");
    for (const EntanglementAxis& a : axes_) {
      KELP_CHECK(a.from.allFinite() && a.to.allFinite() && (a.to - a.from).norm() > 0,
                 "EntanglementMonitor: obstacle '" + a.name + "' needs two distinct finite points");
      KELP_CHECK(std::isfinite(a.radius) && a.radius > 0,
                 "EntanglementMonitor: obstacle '" + a.name + "' needs a radius > 0");
    }
    state_.resize(axes_.size());
    events_.reserve(max_events);
  }

  /// \brief Updates every obstacle's winding and contact at time `t` [s] from the node positions
  /// and velocities (3×n, NED, start end first) and the segments' axial forces `tension`
  /// (n − 1 entries [N], or empty: no `pinned` test; any other size also skips it).
  /// \tparam P, V, T Eigen expressions of doubles
  /// \param t the time [s] \param position the node positions, 3×n, NED [m]
  /// \param velocity the node velocities, 3×n, NED [m/s]
  /// \param tension the segments' axial forces [N]
  /// \returns the number of events this update raised and kept (the last ones of events()).
  /// \throws kelp::invalid_argument when `velocity` has not n columns.
  template <typename P, typename V, typename T>
  int update(double t, const Eigen::MatrixBase<P>& position, const Eigen::MatrixBase<V>& velocity,
             const Eigen::MatrixBase<T>& tension) {
    const Eigen::Index n = position.cols();
    KELP_CHECK(velocity.cols() == n, "EntanglementMonitor::update: velocity must match position");
    const bool with_tension = tension.size() == n - 1 && n >= 2;
    int raised = 0;
    for (std::size_t k = 0; k < axes_.size(); ++k) {
      const EntanglementAxis& a = axes_[k];
      ObstacleWinding& s = state_[k];
      s.winding =
          kelp::tether::winding_angle(position, a.from, a.to, a.radius + tether_radius_).angle;
      s.max_abs_winding = std::max(s.max_abs_winding, std::abs(s.winding));
      if (!s.entangled && std::abs(s.winding) >= settings_.wrap_threshold) {
        s.entangled = true;
        if (std::isnan(s.first_entangled)) s.first_entangled = t;
        raised += push(
            {EntanglementEvent::Kind::entangled, t, int(k), s.winding, contact_point(position, a)});
      } else if (s.entangled &&
                 std::abs(s.winding) < settings_.wrap_threshold - settings_.wrap_hysteresis) {
        s.entangled = false;
      }
      // Contact nodes: the first and last node within reach of the axis segment.
      const double reach = a.radius + tether_radius_ + settings_.contact_margin;
      Eigen::Index first = -1, last = -1;
      double slip = 0;
      int count = 0;
      for (Eigen::Index i = 0; i < n; ++i) {
        if (distance_to_axis(position.col(i), a) > reach) continue;
        if (first < 0) first = i;
        last = i;
        ++count;
        // Speed along the line (the tangent from its neighbours).
        const Eigen::Index i0 = std::max<Eigen::Index>(0, i - 1);
        const Eigen::Index i1 = std::min<Eigen::Index>(n - 1, i + 1);
        const kelp::Vector3<double> d = position.col(i1) - position.col(i0);
        const double dn = d.norm();
        if (dn > 0) slip += std::abs(velocity.col(i).dot(d) / dn);
      }
      s.contact_nodes = count;
      s.slip_speed = count > 0 ? slip / count : 0.0;
      s.tension_difference = 0;
      bool holding = false;
      if (with_tension && count > 0 && first > 0 && last < n - 1) {
        // The ROV's side is the far end (last node); segment `last` leaves the contact towards
        // it, segment `first - 1` towards the boat.
        s.tension_difference = double(tension(last)) - double(tension(first - 1));
        holding = s.slip_speed < settings_.pin_slip_speed &&
                  s.tension_difference > settings_.pin_tension_difference;
      }
      if (!holding) {
        s.pin_since = std::numeric_limits<double>::quiet_NaN();
        s.pinned = false;
      } else {
        if (std::isnan(s.pin_since)) s.pin_since = t;
        if (!s.pinned && t - s.pin_since >= settings_.pin_hold_time) {
          s.pinned = true;
          if (std::isnan(s.first_pinned)) s.first_pinned = t;
          raised += push({EntanglementEvent::Kind::pinned, t, int(k), s.tension_difference,
                          position.col((first + last) / 2)});
        }
      }
    }
    return raised;
  }

  /// \brief The axes watched. \return the axes, in the order the constructor got them
  const std::vector<EntanglementAxis>& axes() const { return axes_; }
  /// \brief The state of obstacle `k` (0 ≤ k < axes().size()).
  /// \param k the obstacle's index in axes() \return its winding and contact now
  /// \throws std::out_of_range for k ≥ axes().size()
  const ObstacleWinding& obstacle(std::size_t k) const { return state_.at(k); }
  /// \brief The events so far, in time order (at most max_events). \return the events
  const std::vector<EntanglementEvent>& events() const { return events_; }
  /// \brief Events raised beyond max_events (not kept). \return the count
  long dropped_events() const { return dropped_; }
  /// \brief The obstacle with the largest |winding| now.
  /// \return its index in axes() (the first of equals), or −1 without obstacles
  int most_wound() const {
    int best = -1;
    for (std::size_t k = 0; k < state_.size(); ++k)
      if (best < 0 || std::abs(state_[k].winding) > std::abs(state_[std::size_t(best)].winding))
        best = int(k);
    return best;
  }
  /// \brief The settings. \return the thresholds the monitor was built with
  const EntanglementSettings& settings() const { return settings_; }

  /// \brief Visits what the monitor knows (kelp/core/memory.hpp): every obstacle's winding and
  /// contact, the events and the dropped count. For a run's checkpoint.
  /// \tparam V a memory visitor \param v the visitor
  KELP_MEMORY_BY(memory)

 private:
  template <class Self, class V>
  static void memory(Self& s, V& v) {
    for (auto& w : s.state_)
      v(w.winding, w.max_abs_winding, w.contact_nodes, w.tension_difference, w.slip_speed,
        w.entangled, w.pinned, w.pin_since, w.first_entangled, w.first_pinned);
    v.list(s.events_, max_events, [&](auto& e) {
      v.choice(e.kind, 2);
      v(e.time);
      v.bounded(e.obstacle, int(s.axes_.size()) - 1);
      v(e.value, e.position);
    });
    v(s.dropped_);
  }

  static double distance_to_axis(const kelp::Vector3<double>& p, const EntanglementAxis& a) {
    const kelp::Vector3<double> ab = a.to - a.from;
    const double s = std::clamp((p - a.from).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
    return (a.from + s * ab - p).norm();
  }
  template <typename P>
  static kelp::Vector3<double> contact_point(const Eigen::MatrixBase<P>& position,
                                             const EntanglementAxis& a) {
    Eigen::Index best = 0;
    double d = std::numeric_limits<double>::infinity();
    for (Eigen::Index i = 0; i < position.cols(); ++i) {
      const double di = distance_to_axis(position.col(i), a);
      if (di < d) {
        d = di;
        best = i;
      }
    }
    return position.col(best);
  }
  int push(const EntanglementEvent& e) {
    if (events_.size() < max_events) {
      events_.push_back(e);
      return 1;
    }
    ++dropped_;
    return 0;
  }

  std::vector<EntanglementAxis> axes_;
  EntanglementSettings settings_;
  double tether_radius_ = 0;
  std::vector<ObstacleWinding> state_;
  std::vector<EntanglementEvent> events_;
  long dropped_ = 0;
};

}  // namespace sim
}  // namespace kelp
