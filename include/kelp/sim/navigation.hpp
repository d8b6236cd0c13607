/// \file
/// \brief Navigation of the tethered pair from its sensors: the ROV fuses IMU, depth, DVL,
/// compass and USBL fixes (made on the boat from its own estimate); the boat fuses IMU, compass
/// and GPS. One call per simulation step samples every sensor that is due from the system's true
/// state and updates both filters; what the controllers see is read back as nav::Navigation.
///
/// Each sensor draws from its own stream of the run's seed (kelp/nav/random.hpp), so the same
/// seed gives the same numbers, and changing one sensor's rate leaves the others' noise as it
/// was. No heap allocation in update().
///
/// Part of the compiled kelp::sim layer (it reads the coupled system's state); the sensors and
/// filters it is made of are kelp::nav's (header-only).
#pragma once

#include <cmath>
#include <cstdint>

#include "kelp/core/memory.hpp"
#include "kelp/core/types.hpp"
#include "kelp/nav/filter.hpp"
#include "kelp/nav/sensors.hpp"
#include "kelp/sim/export.hpp"
#include "kelp/system/system.hpp"

namespace kelp {
namespace sim {

/// \brief The sensors of the pair (one IMU and compass model for both vehicles: each carries a
/// Navigator) and the filters' settings.
struct PairSensors {
  nav::ImuParameters imu;          ///< on both vehicles
  nav::DepthParameters depth;      ///< on the ROV
  nav::DvlParameters dvl;          ///< on the ROV
  nav::CompassParameters compass;  ///< on both vehicles
  nav::GpsParameters gps;          ///< on the boat
  nav::UsblParameters usbl;        ///< transceiver on the boat, locator on the ROV
  /// The ROV's filter (estimates the current when its DVL water-tracks).
  nav::FilterSettings auv_filter = [] {
    nav::FilterSettings s;
    s.estimate_current = true;
    return s;
  }();
  nav::FilterSettings asv_filter;  ///< the boat's filter
  /// σ of the boat's "at the surface" depth pseudo-measurement (its heave in waves) [m].
  double asv_heave_sigma = 1.0;
};

/// \brief Checks every sensor's and filter's parameters.
/// \param p the sensors and filters \throws kelp::invalid_argument naming the field.
KELP_SIM_API void validate(const PairSensors& p);

/// \brief Running error statistics of one vehicle's estimate against the truth.
struct EstimateErrors {
  long samples = 0;                   ///< steps accumulated
  double position_squared_sum = 0;    ///< Σ |p̂ − p|² [m²]
  double heading_squared_sum = 0;     ///< Σ (ψ̂ − ψ)² [rad²]
  double velocity_squared_sum = 0;    ///< Σ |ν̂₁ − ν₁|² [m²/s²]
  double horizontal_squared_sum = 0;  ///< Σ |p̂ − p|² of the north and east parts [m²]
  double max_position = 0;            ///< largest |p̂ − p| [m]
  /// \brief RMS position error (3-D). \return the RMS [m] (0 without samples)
  double rms_position() const { return std::sqrt(position_squared_sum / count()); }
  /// \brief RMS horizontal position error (north, east). \return the RMS [m]
  double rms_horizontal() const { return std::sqrt(horizontal_squared_sum / count()); }
  /// \brief RMS heading error. \return the RMS [rad]
  double rms_heading() const { return std::sqrt(heading_squared_sum / count()); }
  /// \brief RMS body-velocity error (linear part). \return the RMS [m/s]
  double rms_velocity() const { return std::sqrt(velocity_squared_sum / count()); }

 private:
  double count() const { return samples > 0 ? static_cast<double>(samples) : 1.0; }
};

/// \brief The pair's sensors and filters (see the file comment).
class KELP_SIM_API PairNavigation {
 public:
  /// \brief The sensors and filters of a run, started at `state`.
  /// \param[in] p sensors and filters \param[in] seed the run's navigation seed
  /// \param[in] model the system \param[in] state its initial state (the filters start at the
  /// vehicles' launch positions and velocities, with the attitude from the first IMU and
  /// compass samples) \throws kelp::invalid_argument for bad parameters.
  PairNavigation(const PairSensors& p, std::uint64_t seed, const system::SystemModeld& model,
                 const system::SystemStated& state);

  /// \brief Samples the sensors due at the state's time and updates both filters (call once
  /// per step, after the step). Errors against the truth are accumulated for t > 0.
  /// A state whose time is not after the last update's is ignored.
  /// \param model the system (its environment: gravity, seabed, current)
  /// \param state the true state after the step (NED, body velocities, time [s])
  void update(const system::SystemModeld& model, const system::SystemStated& state);

  /// \brief The ROV's estimate. \return position NED [m], attitude, body velocity
  const nav::Navigation& auv() const { return auv_.navigation(); }
  /// \brief The boat's estimate. \return position NED [m], attitude, body velocity
  const nav::Navigation& asv() const { return asv_.navigation(); }
  /// \brief The ROV's filter. \return the filter (state and covariance)
  const nav::NavigationFilter& auv_filter() const { return auv_; }
  /// \brief The boat's filter. \return the filter (state and covariance)
  const nav::NavigationFilter& asv_filter() const { return asv_; }
  /// \brief Error statistics of the ROV's estimate. \return the statistics (t > 0)
  const EstimateErrors& auv_errors() const { return auv_errors_; }
  /// \brief Error statistics of the boat's estimate. \return the statistics (t > 0)
  const EstimateErrors& asv_errors() const { return asv_errors_; }
  /// \brief USBL pings so far. \return the count
  long usbl_pings() const { return usbl_.pings(); }
  /// \brief USBL pings lost so far. \return the count
  long usbl_dropouts() const { return usbl_.dropouts(); }
  /// \brief USBL fixes used by the ROV's filter so far. \return the count
  long usbl_fixes() const { return usbl_fixes_; }
  /// \brief DVL pings so far in a mode.
  /// \param m the mode (bottom track, water track, none) \return the count
  long dvl_pings(nav::DvlMode m) const { return dvl_counts_[static_cast<int>(m)]; }
  /// \brief The parameters. \return the sensors and filters it was built with
  const PairSensors& parameters() const { return p_; }

  /// \brief Visits every sensor's and filter's memory and the counts and error statistics
  /// (kelp/core/memory.hpp). For a run's checkpoint.
  /// \tparam V a memory visitor \param v the visitor
  KELP_MEMORY_BY(memory)

 private:
  template <class Self, class V>
  static void memory(Self& s, V& v) {
    v(s.auv_imu_, s.asv_imu_, s.depth_, s.dvl_, s.auv_compass_, s.asv_compass_, s.gps_, s.usbl_,
      s.auv_, s.asv_, s.last_, s.usbl_fixes_, s.dvl_counts_[0], s.dvl_counts_[1], s.dvl_counts_[2]);
    for (auto* e : {&s.auv_errors_, &s.asv_errors_})
      v(e->samples, e->position_squared_sum, e->heading_squared_sum, e->velocity_squared_sum,
        e->horizontal_squared_sum, e->max_position);
  }

  static void accumulate(const nav::Navigation& est, const vehicle::VehicleStated& x,
                         EstimateErrors& e);

  PairSensors p_;
  nav::ImuSensor auv_imu_, asv_imu_;
  nav::DepthSensor depth_;
  nav::Dvl dvl_;
  nav::Compass auv_compass_, asv_compass_;
  nav::Gps gps_;
  nav::Usbl usbl_;
  nav::NavigationFilter auv_, asv_;
  double last_ = 0.0;
  long usbl_fixes_ = 0;
  long dvl_counts_[3] = {0, 0, 0};
  EstimateErrors auv_errors_, asv_errors_;
};

}  // namespace sim
}  // namespace kelp
