/// \file
/// \brief Navigation of the tethered pair from its sensors: the ROV fuses IMU, depth, DVL,
/// compass and USBL fixes (made on the boat from its own estimate); the boat fuses IMU, compass
/// and GPS. One call per simulation step samples every sensor that is due from the system's true
/// state and updates both filters; what the controllers see is read back as control::Navigation.
///
/// Each sensor draws from its own stream of the run's seed (kelp/nav/random.hpp), so the same
/// seed gives the same numbers, and changing one sensor's rate leaves the others' noise as it
/// was. No heap allocation in update().
#pragma once

#include <cmath>
#include <cstdint>

#include "kelp/control/controllers.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/types.hpp"
#include "kelp/nav/filter.hpp"
#include "kelp/nav/sensors.hpp"
#include "kelp/system/system.hpp"

namespace kelp::nav {

/// \brief The sensors of the pair (one IMU and compass model for both vehicles: each carries a
/// Navigator) and the filters' settings.
struct PairSensors {
  ImuParameters imu;          ///< on both vehicles
  DepthParameters depth;      ///< on the ROV
  DvlParameters dvl;          ///< on the ROV
  CompassParameters compass;  ///< on both vehicles
  GpsParameters gps;          ///< on the boat
  UsblParameters usbl;        ///< transceiver on the boat, locator on the ROV
  /// The ROV's filter (estimates the current when its DVL water-tracks).
  FilterSettings rov_filter = [] {
    FilterSettings s;
    s.estimate_current = true;
    return s;
  }();
  FilterSettings boat_filter;  ///< the boat's filter
  /// σ of the boat's "at the surface" depth pseudo-measurement (its heave in waves) [m].
  double boat_heave_sigma = 1.0;
};

/// \brief Checks every sensor's and filter's parameters. \throws kelp::invalid_argument naming
/// the field.
inline void validate(const PairSensors& p) {
  validate(p.imu);
  validate(p.depth);
  validate(p.dvl);
  validate(p.compass);
  validate(p.gps);
  validate(p.usbl);
  validate(p.rov_filter);
  validate(p.boat_filter);
  check_positive(p.boat_heave_sigma, "boat_heave_sigma");
}

/// \brief Running error statistics of one vehicle's estimate against the truth.
struct EstimateErrors {
  long samples = 0;                   ///< steps accumulated
  double position_squared_sum = 0;    ///< Σ |p̂ − p|² [m²]
  double heading_squared_sum = 0;     ///< Σ (ψ̂ − ψ)² [rad²]
  double velocity_squared_sum = 0;    ///< Σ |ν̂₁ − ν₁|² [m²/s²]
  double horizontal_squared_sum = 0;  ///< Σ |p̂ − p|² of the north and east parts [m²]
  double max_position = 0;            ///< largest |p̂ − p| [m]
  /// \brief RMS position error [m].
  double rms_position() const { return std::sqrt(position_squared_sum / count()); }
  /// \brief RMS horizontal position error [m].
  double rms_horizontal() const { return std::sqrt(horizontal_squared_sum / count()); }
  /// \brief RMS heading error [rad].
  double rms_heading() const { return std::sqrt(heading_squared_sum / count()); }
  /// \brief RMS body-velocity error [m/s].
  double rms_velocity() const { return std::sqrt(velocity_squared_sum / count()); }

 private:
  double count() const { return samples > 0 ? static_cast<double>(samples) : 1.0; }
};

/// \brief The pair's sensors and filters (see the file comment).
class PairNavigation {
 public:
  /// \param[in] p sensors and filters \param[in] seed the run's navigation seed
  /// \param[in] model the system \param[in] state its initial state (the filters start at the
  /// vehicles' launch positions and velocities, with the attitude from the first IMU and
  /// compass samples) \throws kelp::invalid_argument for bad parameters.
  PairNavigation(const PairSensors& p, std::uint64_t seed, const system::SystemModeld& model,
                 const system::SystemStated& state)
      : p_((validate(p), p)),
        rov_imu_(p.imu, seed, 0),
        boat_imu_(p.imu, seed, 1),
        depth_(p.depth, seed, 2),
        dvl_(p.dvl, seed, 3),
        rov_compass_(p.compass, seed, 4),
        boat_compass_(p.compass, seed, 5),
        gps_(p.gps, seed, 6),
        usbl_(p.usbl, seed, 7),
        rov_(p.imu, p.rov_filter, model.environment().gravity()),
        boat_(p.imu, p.boat_filter, model.environment().gravity()) {
    const double g = model.environment().gravity();
    const double t = state.time;
    ImuSample ri, bi;
    rov_imu_.sample(state.auv, state.auv_nu_dot, g, t, ri);
    boat_imu_.sample(state.asv, state.asv_nu_dot, g, t, bi);
    double rpsi = 0, bpsi = 0;
    rov_compass_.sample(state.auv.attitude, t, rpsi);
    boat_compass_.sample(state.asv.attitude, t, bpsi);
    rov_.initialize(state.auv.position,
                    state.auv.attitude * Vector3<double>(state.auv.nu.head<3>()), rpsi, ri);
    boat_.initialize(state.asv.position,
                     state.asv.attitude * Vector3<double>(state.asv.nu.head<3>()), bpsi, bi);
    last_ = t;
  }

  /// \brief Samples the sensors due at the state's time and updates both filters (call once
  /// per step, after the step). Errors against the truth are accumulated for t > 0.
  void update(const system::SystemModeld& model, const system::SystemStated& state) {
    const double t = state.time;
    if (t <= last_) return;
    last_ = t;
    const double g = model.environment().gravity();
    ImuSample imu;
    double psi = 0, z = 0;
    // The boat: IMU, compass, GPS.
    if (boat_imu_.sample(state.asv, state.asv_nu_dot, g, t, imu)) boat_.predict(imu);
    if (boat_compass_.sample(state.asv.attitude, t, psi))
      boat_.update_heading(psi, 1.0 / p_.compass.rate);
    Vector3<double> fix;
    if (gps_.sample(state.asv.position, t, fix)) {
      // Horizontal only: the boat floats, so its depth is the sea's (a pseudo-measurement z = 0
      // with the waves' heave as its σ) rather than a GPS altitude four times worse.
      boat_.update_horizontal_position(fix.head<2>(), gps_.sigma().x(), t);
      boat_.update_depth(0.0, p_.boat_heave_sigma);
    }
    // The USBL ping, computed on the boat from its own estimate.
    const double boat_heading_error = control::wrap_angle(
        control::heading_of(boat_.navigation().attitude) - control::heading_of(state.asv.attitude));
    // The transceiver's depth is known (mounted on the hull), its horizontal position is the
    // boat's estimate.
    const Vector3<double> transceiver(boat_.navigation().position.x(),
                                      boat_.navigation().position.y(), state.asv.position.z());
    usbl_.sample(state.auv.position, state.asv.position, transceiver, boat_heading_error, t);
    // The ROV: IMU, depth, DVL, compass, the USBL fixes delivered by now.
    if (rov_imu_.sample(state.auv, state.auv_nu_dot, g, t, imu)) rov_.predict(imu);
    if (depth_.sample(state.auv.position.z(), t, z)) rov_.update_depth(z, p_.depth.noise);
    DvlSample dvl;
    if (dvl_.sample(state.auv, model.environment(), t, dvl)) {
      ++dvl_counts_[static_cast<int>(dvl.mode)];
      if (dvl.mode == DvlMode::bottom) rov_.update_body_velocity(dvl.velocity, dvl.sigma);
      if (dvl.mode == DvlMode::water) rov_.update_water_velocity(dvl.velocity, dvl.sigma);
    }
    if (rov_compass_.sample(state.auv.attitude, t, psi))
      rov_.update_heading(psi, 1.0 / p_.compass.rate);
    UsblFix u;
    while (usbl_.poll(t, u)) {
      const double s = std::hypot(u.sigma, p_.gps.noise);
      rov_.update_position(u.position, Vector3<double>::Constant(s), u.measured_at);
      ++usbl_fixes_;
    }
    accumulate(rov_.navigation(), state.auv, auv_errors_);
    accumulate(boat_.navigation(), state.asv, asv_errors_);
  }

  /// \brief The ROV's estimate.
  const control::Navigation& auv() const { return rov_.navigation(); }
  /// \brief The boat's estimate.
  const control::Navigation& asv() const { return boat_.navigation(); }
  /// \brief The ROV's filter.
  const NavigationFilter& auv_filter() const { return rov_; }
  /// \brief The boat's filter.
  const NavigationFilter& asv_filter() const { return boat_; }
  /// \brief Error statistics of the ROV's estimate.
  const EstimateErrors& auv_errors() const { return auv_errors_; }
  /// \brief Error statistics of the boat's estimate.
  const EstimateErrors& asv_errors() const { return asv_errors_; }
  /// \brief USBL pings, lost pings and fixes used so far.
  long usbl_pings() const { return usbl_.pings(); }
  long usbl_dropouts() const { return usbl_.dropouts(); }  ///< see usbl_pings()
  long usbl_fixes() const { return usbl_fixes_; }          ///< see usbl_pings()
  /// \brief DVL pings so far in a mode.
  long dvl_pings(DvlMode m) const { return dvl_counts_[static_cast<int>(m)]; }
  /// \brief The parameters.
  const PairSensors& parameters() const { return p_; }

 private:
  static void accumulate(const control::Navigation& est, const vehicle::VehicleStated& x,
                         EstimateErrors& e) {
    const double dp = (est.position - x.position).norm();
    const double dpsi =
        control::wrap_angle(control::heading_of(est.attitude) - control::heading_of(x.attitude));
    e.position_squared_sum += dp * dp;
    e.horizontal_squared_sum += (est.position - x.position).head<2>().squaredNorm();
    e.heading_squared_sum += dpsi * dpsi;
    e.velocity_squared_sum += (est.nu.head<3>() - x.nu.head<3>()).squaredNorm();
    e.max_position = std::max(e.max_position, dp);
    ++e.samples;
  }

  PairSensors p_;
  ImuSensor rov_imu_, boat_imu_;
  DepthSensor depth_;
  Dvl dvl_;
  Compass rov_compass_, boat_compass_;
  Gps gps_;
  Usbl usbl_;
  NavigationFilter rov_, boat_;
  double last_ = 0.0;
  long usbl_fixes_ = 0;
  long dvl_counts_[3] = {0, 0, 0};
  EstimateErrors auv_errors_, asv_errors_;
};

}  // namespace kelp::nav
