/// \file
/// \brief Tether management: the payout rate a boat's winch is commanded from what the operator
/// (or the boat's computer) sees — the pull on the winch, the line out, the ROV's depth and its
/// horizontal offset from the boat. Three strategies of ROV practice (a tether management system
/// keeps the tether off the ROV by paying out as it dives and reeling in as it returns):
///
/// - **constant tension**: keep the pull at the winch in a band [low, high]: pay out above it,
///   reel in below it, hold inside it (an auto-render / auto-tension winch);
/// - **slack**: keep the line out at (1 + slack) times the distance between the two attachment
///   points (a target slack fraction: the sag a catenary of that length has);
/// - **depth following**: line out = extra + k_d · depth + k_h · horizontal offset of the ROV
///   (the operator's rule of thumb of a few metres more than the ROV's range).
///
/// The length strategies command gain · (target − length), which the winch limits in speed and
/// acceleration (kelp::tether::limited_payout_rate). The strategies see measurements only (no
/// world state), as every controller here.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>

#include "kelp/core/error.hpp"

namespace kelp::control {

/// \brief A winch strategy.
enum class WinchStrategy {
  hold,              ///< no payout (the winch's brake holds the line)
  constant_tension,  ///< the pull in a band
  slack,             ///< a target slack fraction
  depth_following    ///< length from the ROV's depth and offset
};

/// \brief Name of a strategy ("hold", "constant_tension", "slack", "depth_following").
/// \param s the strategy.
/// \return its name, a string literal ("unknown" for a value outside the enum); never throws.
inline const char* winch_strategy_name(WinchStrategy s) {
  switch (s) {
    case WinchStrategy::hold:
      return "hold";
    case WinchStrategy::constant_tension:
      return "constant_tension";
    case WinchStrategy::slack:
      return "slack";
    case WinchStrategy::depth_following:
      return "depth_following";
  }
  return "unknown";
}

/// \brief The strategy of a name (see winch_strategy_name).
/// \param name the name, exactly as winch_strategy_name() spells it (case-sensitive).
/// \return the strategy.
/// \throws kelp::invalid_argument for another name.
inline WinchStrategy winch_strategy_from_name(const std::string& name) {
  for (WinchStrategy s : {WinchStrategy::hold, WinchStrategy::constant_tension,
                          WinchStrategy::slack, WinchStrategy::depth_following})
    if (name == winch_strategy_name(s)) return s;
  throw kelp::invalid_argument("unknown winch strategy \"" + name +
                               "\" (hold, constant_tension, slack, depth_following)");
}

/// \brief Settings of the tether management (all magnitudes positive).
struct TetherManagementSettings {
  WinchStrategy strategy = WinchStrategy::depth_following;  ///< the strategy winch_command() uses
  /// \brief Constant tension: the band [tension_low, tension_high] of the pull at the winch [N]
  /// (0 ≤ low < high).
  ///@{
  double tension_low = 5.0, tension_high = 25.0;
  ///@}
  /// Constant tension: payout rate per newton outside the band [m/s/N].
  double tension_gain = 0.02;
  /// Slack: line out over the distance between the attachment points, minus 1 [-].
  double slack = 0.3;
  /// \brief Depth following: line out = extra_length [m] + length_per_depth [m/m] · depth +
  /// length_per_offset [m/m] · horizontal offset (all ≥ 0).
  ///@{
  double extra_length = 3.0, length_per_depth = 1.0, length_per_offset = 1.0;
  ///@}
  /// Slack and depth following: payout rate per metre of length error [1/s].
  double length_gain = 0.5;
};

/// \brief Checks the settings.
/// \param s the settings: a known strategy, every magnitude finite and ≥ 0, tension_high >
/// tension_low.
/// \throws kelp::invalid_argument naming the field.
inline void validate(const TetherManagementSettings& s) {
  const auto finite_nonneg = [](double x, const char* name) {
    KELP_CHECK(std::isfinite(x) && x >= 0.0,
               std::string("tether management: ") + name + " must be finite and >= 0");
  };
  finite_nonneg(s.tension_low, "tension_low");
  finite_nonneg(s.tension_high, "tension_high");
  KELP_CHECK(s.tension_high > s.tension_low,
             "tether management: tension_high must be above tension_low");
  finite_nonneg(s.tension_gain, "tension_gain");
  finite_nonneg(s.slack, "slack");
  finite_nonneg(s.extra_length, "extra_length");
  finite_nonneg(s.length_per_depth, "length_per_depth");
  finite_nonneg(s.length_per_offset, "length_per_offset");
  finite_nonneg(s.length_gain, "length_gain");
  KELP_CHECK(std::string(winch_strategy_name(s.strategy)) != "unknown",
             "tether management: unknown strategy " + std::to_string(static_cast<int>(s.strategy)));
}

/// \brief What the strategies see.
struct TetherManagementInput {
  double pull = 0.0;               ///< pull of the line at the winch [N]
  double length = 0.0;             ///< unstretched line out [m]
  double depth = 0.0;              ///< ROV attachment's depth below the winch [m]
  double horizontal_offset = 0.0;  ///< ROV attachment's horizontal distance from the winch [m]
};

/// \brief The target line out of a length strategy [m] (the current length for the others).
/// \param s the settings (strategy and its parameters; not validated here).
/// \param in the measurements; slack uses the straight distance hypot(depth, horizontal_offset),
/// depth following a negative depth as 0.
/// \return the unstretched length the strategy aims at [m].
inline double target_length(const TetherManagementSettings& s, const TetherManagementInput& in) {
  switch (s.strategy) {
    case WinchStrategy::slack:
      return (1.0 + s.slack) * std::hypot(in.depth, in.horizontal_offset);
    case WinchStrategy::depth_following:
      return s.extra_length + s.length_per_depth * std::max(0.0, in.depth) +
             s.length_per_offset * in.horizontal_offset;
    default:
      return in.length;
  }
}

/// \brief The commanded payout rate [m/s] (positive: pay out); the winch limits it.
/// \param s the settings (strategy and its parameters; not validated here).
/// \param in the measurements (pull [N] for constant tension, length, depth and offset [m] for
/// the length strategies).
/// \return hold: 0; constant tension: tension_gain × the pull's distance outside the band
/// (signed, 0 inside it); slack and depth following: length_gain × (target_length − length).
inline double winch_command(const TetherManagementSettings& s, const TetherManagementInput& in) {
  switch (s.strategy) {
    case WinchStrategy::hold:
      return 0.0;
    case WinchStrategy::constant_tension:
      if (in.pull > s.tension_high) return s.tension_gain * (in.pull - s.tension_high);
      if (in.pull < s.tension_low) return s.tension_gain * (in.pull - s.tension_low);
      return 0.0;
    case WinchStrategy::slack:
    case WinchStrategy::depth_following:
      return s.length_gain * (target_length(s, in) - in.length);
  }
  return 0.0;
}

}  // namespace kelp::control
