#include "kelp/sim/navigation.hpp"

#include "kelp/sim/instantiation.hpp"  // the wave kernels: instantiated once, in instantiation.cpp

#include <algorithm>
#include <cmath>

#include "kelp/core/angles.hpp"
#include "kelp/core/error.hpp"

namespace kelp {
namespace sim {

using namespace kelp::nav;  // NOLINT(google-build-using-namespace): the sensors and filters

void validate(const PairSensors& p) {
  validate(p.imu);
  validate(p.depth);
  validate(p.dvl);
  validate(p.compass);
  validate(p.gps);
  validate(p.usbl);
  validate(p.auv_filter);
  validate(p.asv_filter);
  check_positive(p.asv_heave_sigma, "asv_heave_sigma");
}

PairNavigation::PairNavigation(const PairSensors& p, std::uint64_t seed,
                               const system::SystemModeld& model, const system::SystemStated& state)
    : p_((validate(p), p)),
      auv_imu_(p.imu, seed, 0),
      asv_imu_(p.imu, seed, 1),
      depth_(p.depth, seed, 2),
      dvl_(p.dvl, seed, 3),
      auv_compass_(p.compass, seed, 4),
      asv_compass_(p.compass, seed, 5),
      gps_(p.gps, seed, 6),
      usbl_(p.usbl, seed, 7),
      auv_(p.imu, p.auv_filter, model.environment().gravity()),
      asv_(p.imu, p.asv_filter, model.environment().gravity()) {
  const double g = model.environment().gravity();
  const double t = state.time;
  ImuSample ri, bi;
  auv_imu_.sample(state.auv, state.auv_nu_dot, g, t, ri);
  asv_imu_.sample(state.asv, state.asv_nu_dot, g, t, bi);
  double rpsi = 0, bpsi = 0;
  auv_compass_.sample(state.auv.attitude, t, rpsi);
  asv_compass_.sample(state.asv.attitude, t, bpsi);
  auv_.initialize(state.auv.position, state.auv.attitude * Vector3<double>(state.auv.nu.head<3>()),
                  rpsi, ri);
  asv_.initialize(state.asv.position, state.asv.attitude * Vector3<double>(state.asv.nu.head<3>()),
                  bpsi, bi);
  last_ = t;
}

void PairNavigation::update(const system::SystemModeld& model, const system::SystemStated& state) {
  const double t = state.time;
  if (t <= last_) return;
  last_ = t;
  const double g = model.environment().gravity();
  ImuSample imu;
  double psi = 0, z = 0;
  // The boat: IMU, compass, GPS.
  if (asv_imu_.sample(state.asv, state.asv_nu_dot, g, t, imu)) asv_.predict(imu);
  if (asv_compass_.sample(state.asv.attitude, t, psi))
    asv_.update_heading(psi, 1.0 / p_.compass.rate);
  Vector3<double> fix;
  if (gps_.sample(state.asv.position, t, fix)) {
    // Horizontal only: the boat floats, so its depth is the sea's (a pseudo-measurement z = 0
    // with the waves' heave as its σ) rather than a GPS altitude four times worse.
    asv_.update_horizontal_position(fix.head<2>(), gps_.sigma().x(), t);
    asv_.update_depth(0.0, p_.asv_heave_sigma);
  }
  // The USBL ping, computed on the boat from its own estimate.
  const double asv_heading_error = kelp::wrap_angle(kelp::heading_of(asv_.navigation().attitude) -
                                                    kelp::heading_of(state.asv.attitude));
  // The transceiver's depth is known (mounted on the hull), its horizontal position is the
  // boat's estimate.
  const Vector3<double> transceiver(asv_.navigation().position.x(), asv_.navigation().position.y(),
                                    state.asv.position.z());
  usbl_.sample(state.auv.position, state.asv.position, transceiver, asv_heading_error, t);
  // The ROV: IMU, depth, DVL, compass, the USBL fixes delivered by now.
  if (auv_imu_.sample(state.auv, state.auv_nu_dot, g, t, imu)) auv_.predict(imu);
  if (depth_.sample(state.auv.position.z(), t, z)) auv_.update_depth(z, p_.depth.noise);
  DvlSample dvl;
  if (dvl_.sample(state.auv, model.environment(), t, dvl)) {
    ++dvl_counts_[static_cast<int>(dvl.mode)];
    if (dvl.mode == DvlMode::bottom) auv_.update_body_velocity(dvl.velocity, dvl.sigma);
    if (dvl.mode == DvlMode::water) auv_.update_water_velocity(dvl.velocity, dvl.sigma);
  }
  if (auv_compass_.sample(state.auv.attitude, t, psi))
    auv_.update_heading(psi, 1.0 / p_.compass.rate);
  UsblFix u;
  while (usbl_.poll(t, u)) {
    const double s = std::hypot(u.sigma, p_.gps.noise);
    auv_.update_position(u.position, Vector3<double>::Constant(s), u.measured_at);
    ++usbl_fixes_;
  }
  accumulate(auv_.navigation(), state.auv, auv_errors_);
  accumulate(asv_.navigation(), state.asv, asv_errors_);
}
void PairNavigation::accumulate(const nav::Navigation& est, const vehicle::VehicleStated& x,
                                EstimateErrors& e) {
  const double dp = (est.position - x.position).norm();
  const double dpsi =
      kelp::wrap_angle(kelp::heading_of(est.attitude) - kelp::heading_of(x.attitude));
  e.position_squared_sum += dp * dp;
  e.horizontal_squared_sum += (est.position - x.position).head<2>().squaredNorm();
  e.heading_squared_sum += dpsi * dpsi;
  e.velocity_squared_sum += (est.nu.head<3>() - x.nu.head<3>()).squaredNorm();
  e.max_position = std::max(e.max_position, dp);
  ++e.samples;
}
}  // namespace sim
}  // namespace kelp
