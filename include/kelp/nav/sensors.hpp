/// \file
/// \brief Simulated navigation sensors of the tethered pair: IMU, depth (pressure) sensor, DVL,
/// compass, the boat's GPS and USBL fixes of the ROV from the boat, each with its own rate,
/// noise from a reproducible stream (kelp/nav/random.hpp) and defaults from the parts' data.
///
/// Every sensor samples the true state when it is due (`SensorSchedule`, at most once per call)
/// and allocates nothing after construction. Frames as everywhere in kelp: body x forward, y
/// starboard, z down; world NED; angles in rad.
///
/// Default specifications and where they come from:
/// - **IMU**: the TDK InvenSense ICM-20602 of Blue Robotics' Navigator flight controller (the
///   BlueROV2's and the BlueBoat's autopilot board). ICM-20602 data sheet (DS-000176): gyroscope
///   rate noise spectral density 0.004 °/s/√Hz, accelerometer noise 100 µg/√Hz. The data sheet
///   gives no bias random walk; the defaults are those of the ADIS16448 of the EuRoC MAV datasets
///   (Burri et al., IJRR 35(10), 2016; their sensor.yaml, the example Kalibr's IMU noise model is
///   used with: gyroscope 1.9393e-5 rad/s²/√Hz, accelerometer 3.0e-3 m/s³/√Hz), a conservative
///   stand-in for a consumer part. Rate 100 Hz: kelp's closed loop steps at 10 ms.
///   The accelerometer measures the specific force f = (ν̇₁ + ω × ν₁) − Rᵀ (0, 0, g) in body
///   axes (the CO's acceleration minus gravity), so it needs the vehicle's last ν̇.
/// - **Depth**: Blue Robotics Bar30 (TE MS5837-30BA). Bar30 technical details
///   (bluerobotics/bar30-pressure-sensor): 0.2 mbar resolution, i.e. 2 mm of water, taken as the
///   noise σ; absolute accuracy ±50 mbar (0.5 m) over 0–6 bar, which the autopilot's zeroing at
///   the surface removes (a constant `bias`, 0 by default). Rate 20 Hz: a read (pressure and
///   temperature conversions at the highest oversampling) takes up to 40 ms (Blue Robotics'
///   MS5837 library). It reads the CO's depth (no wave pressure, no lever arm).
/// - **DVL**: Water Linked DVL A50. Bottom lock from 0.05 to 50 m altitude (Water Linked's A50
///   page: "0.05 – 50 meter range", ping rate 4–26 Hz altitude dependent; range-mode table: 5–6 Hz
///   between 1.5 and 14 m, the default 5 Hz; Water Linked's DVL protocol, docs/dvl/dvl-protocol.md
///   of waterlinked/waterlinked.github.io: a velocity report per ping at 2–26 Hz depending on the
///   altitude; its FAQ: up to 15 Hz close to the seabed, typically 2–4 Hz higher up). Velocity
///   noise σ = 0.001 m/s + 1 % of the speed:
///   ±0.1 cm/s long-term accuracy (A50 key specifications) and the 1 % accuracy of the standard
///   edition (Water Linked on Blue Robotics' forum, "DVL-A50 Accuracy"); per-ping noise is not
///   published. Beyond the bottom-lock range it water-tracks (Water Linked, "Water Tracking": the
///   A50 measures the velocity relative to the water 1.5–4.5 m below it, at 2 Hz; "dead reckoning
///   performance with water tracking is untested"): velocity relative to the water at 3 m below
///   the DVL (current plus wave orbital velocity there) with an assumed σ of 0.05 m/s; with
///   `water_track` off it gives no fix there.
/// - **Compass**: the Navigator's MEMSIC MMC5983MA magnetometer, heading accuracy ±0.5° (MMC5983MA
///   data sheet; likewise SparkFun's MMC5983MA breakout and library pages: 0.4 mG total RMS noise
///   "enabling a heading accuracy of ±0.5°"), taken as the heading noise σ; rate 50 Hz
///   (assumed; the part outputs up to 1000 Hz). A heading, not a field vector: the
///   hard- and soft-iron calibration is assumed done (`bias` models what it leaves).
/// - **GPS** (on the boat): a u-blox M8-class receiver (NEO-M8N data sheet, UBX-15031086:
///   horizontal accuracy 2.5 m CEP, 2.0 m with SBAS), at 5 Hz (ArduPilot's GPS1_RATE_MS,
///   formerly GPS_RATE_MS, default 200 ms: libraries/AP_GPS/AP_GPS_Params.cpp, "Lowering below
///   5Hz(default) is not allowed"). CEP 2.5 m is σ ≈ 2.1 m per axis (CEP = 1.1774 σ for a circular
///   Gaussian); it is split (an assumption: autonomous-fix errors are mostly slow, atmospheric and
///   orbital) into a first-order Gauss–Markov error of σ 2.0 m and 120 s correlation time plus 0.5
///   m white noise (√(2.0² + 0.5²) = 2.06 m). Vertical errors are `vertical_factor` (2) times the
///   horizontal.
/// - **USBL**: Water Linked Underwater GPS G2 with a locator on the ROV: σ per axis = 0.05 m + 1 %
///   of the slant range (Water Linked quote ±1 % of the range for the Underwater GPS; the 5 cm
///   floor is an assumption), 1 Hz, 0.5 s latency, 10 % of the fixes lost and none beyond 100 m:
///   the rate, latency, dropout, floor and range are assumptions, and the ±1 % is not in Water
///   Linked's online documentation as checked on 2026-11-25 (set them from your system's log).
///   Water Linked, "Underwater GPS G2" (docs/underwater-gps/introduction.md of
///   waterlinked/waterlinked.github.io): range up to 300 m in the R300 edition; the G2 is a
///   short-baseline (SBL) system, a locator heard by four receivers, rather than a USBL; kelp
///   models its fixes the same way. The fix is computed on the boat: its own position estimate
///   plus the measured relative position turned by its heading error, so the boat's GPS error
///   carries over into the ROV's fix.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>

#include "kelp/core/angles.hpp"
#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/memory.hpp"
#include "kelp/core/rotation.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/environment/environment.hpp"
#include "kelp/nav/random.hpp"
#include "kelp/vehicle/state.hpp"

namespace kelp::nav {

/// \brief One degree [rad].
inline constexpr double degree = kelp::pi / 180.0;

namespace detail {
inline void check_rate(double rate, const std::string& field) {
  KELP_CHECK(std::isfinite(rate) && rate > 0 && rate <= 1e4,
             field + " must be a rate in (0, 10000] Hz");
}
inline void check_sigma(double x, const std::string& field) {
  KELP_CHECK(std::isfinite(x) && x >= 0, field + " must be finite and >= 0");
}
}  // namespace detail

/// \brief When a sensor of a given rate samples: at its first call, then every period (a call
/// between two due times samples nothing; a late call samples at once and keeps the phase).
class SensorSchedule {
 public:
  /// \brief A schedule of period 1 s.
  SensorSchedule() = default;
  /// \brief A schedule of the given rate.
  /// \param[in] rate samples per second [Hz] (> 0; not checked: the sensors validate it)
  explicit SensorSchedule(double rate) : period_(1.0 / rate) {}
  /// \brief True when a sample is due at time t [s] (then the next one is scheduled).
  /// \param t Time [s] (non-decreasing from call to call).
  /// \return True at the first call and when t has reached the next due time (within 1 ns).
  bool due(double t) {
    if (started_ && t < next_ - 1e-9) return false;
    next_ = started_ ? next_ + period_ : t + period_;
    if (next_ <= t + 1e-9) next_ = t + period_;
    started_ = true;
    return true;
  }
  /// \brief The sampling period [s].
  /// \return 1/rate [s] (or the last period given to reschedule).
  double period() const { return period_; }
  /// \brief Schedules the next sample one period `p` [s] after `t` [s] (and keeps that period).
  /// \param t Time of the sample just taken [s].
  /// \param p The new period [s] (> 0).
  void reschedule(double t, double p) {
    period_ = p;
    next_ = t + p;
  }
  /// \brief visit_memory(v): the period and the next due time (kelp/core/memory.hpp).
  /// \tparam V a memory visitor \param v the visitor
  KELP_MEMORY(period_, next_, started_)

 private:
  double period_ = 1.0, next_ = 0.0;
  bool started_ = false;
};

// ---- IMU -----------------------------------------------------------------------------------

/// \brief IMU noise (continuous-time densities, as data sheets and Kalibr give them; the
/// discrete σ of one sample at rate f is density·√f for white noise and walk/√f per sample for
/// the bias random walk). Defaults: ICM-20602 (see the file comment).
struct ImuParameters {
  double rate = 100.0;                            ///< samples per second [Hz]
  double gyro_noise_density = 0.004 * degree;     ///< [rad/s/√Hz]
  double gyro_bias_walk = 1.9393e-5;              ///< [rad/s²/√Hz]
  double gyro_bias_initial = 0.0;                 ///< σ of the turn-on bias [rad/s]
  double accel_noise_density = 100e-6 * 9.80665;  ///< [m/s²/√Hz]
  double accel_bias_walk = 3.0e-3;                ///< [m/s³/√Hz]
  double accel_bias_initial = 0.0;                ///< σ of the turn-on bias [m/s²]
};

/// \brief Checks IMU parameters.
/// \param p Parameters: rate in (0, 1e4] Hz, every density, walk and σ finite ≥ 0.
/// \throws kelp::invalid_argument naming the field.
inline void validate(const ImuParameters& p) {
  detail::check_rate(p.rate, "imu.rate");
  detail::check_sigma(p.gyro_noise_density, "imu.gyro_noise_density");
  detail::check_sigma(p.gyro_bias_walk, "imu.gyro_bias_walk");
  detail::check_sigma(p.gyro_bias_initial, "imu.gyro_bias_initial");
  detail::check_sigma(p.accel_noise_density, "imu.accel_noise_density");
  detail::check_sigma(p.accel_bias_walk, "imu.accel_bias_walk");
  detail::check_sigma(p.accel_bias_initial, "imu.accel_bias_initial");
}

/// \brief One IMU sample (body axes).
struct ImuSample {
  double t = 0.0;                                   ///< time of the sample [s]
  Vector3<double> gyro = Vector3<double>::Zero();   ///< angular rate [rad/s]
  Vector3<double> accel = Vector3<double>::Zero();  ///< specific force [m/s²]
};

/// \brief The specific force an ideal accelerometer at the CO reads [m/s², body axes]:
/// f = ν̇₁ + ω × ν₁ − Rᵀ (0, 0, g) (at rest and level: (0, 0, −g)).
/// \param[in] x the vehicle's state \param[in] nu_dot its ν̇ (body) \param[in] gravity g [m/s²]
/// \return f, body axes [m/s²].
inline Vector3<double> specific_force(const vehicle::VehicleStated& x,
                                      const Vector6<double>& nu_dot, double gravity) {
  const Vector3<double> v = x.nu.head<3>(), w = x.nu.tail<3>();
  return nu_dot.head<3>() + w.cross(v) -
         x.attitude.conjugate() * Vector3<double>(0.0, 0.0, gravity);
}

/// \brief A 3-axis gyroscope and accelerometer with white noise and bias random walks.
class ImuSensor {
 public:
  /// \param[in] p parameters (validated) \param[in] seed run seed \param[in] stream the sensor's
  /// stream number \throws kelp::invalid_argument for bad parameters.
  ImuSensor(const ImuParameters& p, std::uint64_t seed, std::uint64_t stream)
      : p_((validate(p), p)), rng_(seed, stream), schedule_(p.rate) {
    for (int i = 0; i < 3; ++i) gyro_bias_(i) = p.gyro_bias_initial * rng_.normal();
    for (int i = 0; i < 3; ++i) accel_bias_(i) = p.accel_bias_initial * rng_.normal();
  }
  /// \brief Samples when due at time t [s]: returns true and fills `out`.
  /// \param x The vehicle's true state.
  /// \param nu_dot Its true body acceleration ν̇ [m/s², rad/s²].
  /// \param gravity g [m/s²].
  /// \param t Time [s].
  /// \param[out] out The sample, written only when due.
  /// \return True when a sample was due.
  bool sample(const vehicle::VehicleStated& x, const Vector6<double>& nu_dot, double gravity,
              double t, ImuSample& out) {
    if (!schedule_.due(t)) return false;
    out = measure(x.nu.tail<3>(), specific_force(x, nu_dot, gravity), t);
    return true;
  }
  /// \brief One sample of the given true angular rate and specific force (body) at time t,
  /// regardless of the schedule; advances the biases by one period.
  /// \param omega True angular rate, body axes [rad/s].
  /// \param force True specific force, body axes [m/s²] (see specific_force).
  /// \param t Time stamp of the sample [s].
  /// \return The sample: truth + bias + white noise of σ = density·√rate.
  ImuSample measure(const Vector3<double>& omega, const Vector3<double>& force, double t) {
    const double sg = p_.gyro_noise_density * std::sqrt(p_.rate);
    const double sa = p_.accel_noise_density * std::sqrt(p_.rate);
    const double wg = p_.gyro_bias_walk / std::sqrt(p_.rate);
    const double wa = p_.accel_bias_walk / std::sqrt(p_.rate);
    ImuSample s;
    s.t = t;
    for (int i = 0; i < 3; ++i) s.gyro(i) = omega(i) + gyro_bias_(i) + sg * rng_.normal();
    for (int i = 0; i < 3; ++i) s.accel(i) = force(i) + accel_bias_(i) + sa * rng_.normal();
    for (int i = 0; i < 3; ++i) gyro_bias_(i) += wg * rng_.normal();
    for (int i = 0; i < 3; ++i) accel_bias_(i) += wa * rng_.normal();
    return s;
  }
  /// \brief The gyroscope's true bias now [rad/s].
  /// \return The bias, body axes [rad/s].
  const Vector3<double>& gyro_bias() const { return gyro_bias_; }
  /// \brief The accelerometer's true bias now [m/s²].
  /// \return The bias, body axes [m/s²].
  const Vector3<double>& accel_bias() const { return accel_bias_; }
  /// \brief The parameters.
  /// \return The parameters the sensor was built with.
  const ImuParameters& parameters() const { return p_; }
  /// \brief visit_memory(v): the noise stream, the schedule and the biases
  /// (kelp/core/memory.hpp).
  /// \tparam V a memory visitor \param v the visitor
  KELP_MEMORY(rng_, schedule_, gyro_bias_, accel_bias_)

 private:
  ImuParameters p_;
  RandomStream rng_;
  SensorSchedule schedule_;
  Vector3<double> gyro_bias_ = Vector3<double>::Zero(), accel_bias_ = Vector3<double>::Zero();
};

// ---- depth ---------------------------------------------------------------------------------

/// \brief Depth sensor: Bar30 by default (see the file comment).
struct DepthParameters {
  double rate = 20.0;    ///< [Hz]
  double noise = 0.002;  ///< σ [m]
  double bias = 0.0;     ///< constant offset [m]
};

/// \brief Checks depth-sensor parameters.
/// \param p Parameters: rate in (0, 1e4] Hz, noise finite ≥ 0, bias finite.
/// \throws kelp::invalid_argument naming the field.
inline void validate(const DepthParameters& p) {
  detail::check_rate(p.rate, "depth.rate");
  detail::check_sigma(p.noise, "depth.noise");
  KELP_CHECK(std::isfinite(p.bias), "depth.bias must be finite");
}

/// \brief A pressure depth sensor at the CO: z + bias + white noise.
class DepthSensor {
 public:
  /// \brief A depth sensor with its own noise stream.
  /// \param[in] p parameters \param[in] seed run seed \param[in] stream the sensor's stream
  /// number \throws kelp::invalid_argument for bad parameters.
  DepthSensor(const DepthParameters& p, std::uint64_t seed, std::uint64_t stream)
      : p_((validate(p), p)), rng_(seed, stream), schedule_(p.rate) {}
  /// \brief Samples the depth z [m] when due at time t: true and `out` [m].
  /// \param z True depth of the CO, NED z [m].
  /// \param t Time [s].
  /// \param[out] out The reading [m], written only when due.
  /// \return True when a sample was due.
  bool sample(double z, double t, double& out) {
    if (!schedule_.due(t)) return false;
    out = measure(z);
    return true;
  }
  /// \brief One reading of depth z [m], regardless of the schedule.
  /// \param z True depth, NED z [m].
  /// \return z + bias + noise [m].
  double measure(double z) { return z + p_.bias + p_.noise * rng_.normal(); }
  /// \brief The parameters.
  /// \return The parameters the sensor was built with.
  const DepthParameters& parameters() const { return p_; }
  /// \brief visit_memory(v): the noise stream and the schedule (kelp/core/memory.hpp).
  /// \tparam V a memory visitor \param v the visitor
  KELP_MEMORY(rng_, schedule_)

 private:
  DepthParameters p_;
  RandomStream rng_;
  SensorSchedule schedule_;
};

// ---- DVL -----------------------------------------------------------------------------------

/// \brief DVL: Water Linked A50 by default (see the file comment).
struct DvlParameters {
  double bottom_rate = 5.0;           ///< bottom-lock rate [Hz]
  double water_rate = 2.0;            ///< water-track rate [Hz]
  double min_altitude = 0.05;         ///< bottom lock from this altitude [m]
  double max_altitude = 50.0;         ///< to this one [m]
  double noise_floor = 0.001;         ///< σ at rest [m/s]
  double noise_fraction = 0.01;       ///< σ growth with the speed [-]
  bool water_track = true;            ///< water-track beyond the bottom-lock range
  double water_noise = 0.05;          ///< water-track σ [m/s]
  double water_track_distance = 3.0;  ///< the tracked water's distance below the DVL [m]
};

/// \brief Checks DVL parameters.
/// \param p Parameters: rates in (0, 1e4] Hz, max_altitude finite > min_altitude, the others
/// finite ≥ 0.
/// \throws kelp::invalid_argument naming the field.
inline void validate(const DvlParameters& p) {
  detail::check_rate(p.bottom_rate, "dvl.bottom_rate");
  detail::check_rate(p.water_rate, "dvl.water_rate");
  detail::check_sigma(p.min_altitude, "dvl.min_altitude");
  KELP_CHECK(std::isfinite(p.max_altitude) && p.max_altitude > p.min_altitude,
             "dvl.max_altitude must be finite and > dvl.min_altitude");
  detail::check_sigma(p.noise_floor, "dvl.noise_floor");
  detail::check_sigma(p.noise_fraction, "dvl.noise_fraction");
  detail::check_sigma(p.water_noise, "dvl.water_noise");
  detail::check_sigma(p.water_track_distance, "dvl.water_track_distance");
}

/// \brief What a DVL ping gives.
enum class DvlMode {
  none,    ///< no fix (out of range, water tracking off)
  bottom,  ///< bottom lock: velocity over ground
  water,   ///< water track: velocity relative to the water below
};

/// \brief One DVL fix (body axes).
struct DvlSample {
  double t = 0.0;                                      ///< time [s]
  DvlMode mode = DvlMode::none;                        ///< what it measured
  Vector3<double> velocity = Vector3<double>::Zero();  ///< [m/s], body axes
  double altitude = 0.0;                               ///< above the seabed [m] (inf: none)
  double sigma = 0.0;                                  ///< noise σ of this fix [m/s]
};

/// \brief A DVL at the CO looking down: bottom lock within its altitude range, else water track
/// (or nothing).
class Dvl {
 public:
  /// \brief A DVL with its own noise stream.
  /// \param[in] p parameters \param[in] seed run seed \param[in] stream the sensor's stream
  /// number \throws kelp::invalid_argument for bad parameters.
  Dvl(const DvlParameters& p, std::uint64_t seed, std::uint64_t stream)
      : p_((validate(p), p)), rng_(seed, stream), schedule_(p.bottom_rate) {}

  /// \brief The mode at an altitude [m] (+inf: no seabed).
  /// \param altitude Height of the DVL above the seabed [m].
  /// \return bottom within [min_altitude, max_altitude], else water (or none when water
  /// tracking is off).
  DvlMode mode_at(double altitude) const {
    if (altitude >= p_.min_altitude && altitude <= p_.max_altitude) return DvlMode::bottom;
    return p_.water_track ? DvlMode::water : DvlMode::none;
  }

  /// \brief Pings when due at time t: true and `out` (whose mode may be `none`). The rate
  /// follows the mode of the ping.
  /// \param x The vehicle's true state.
  /// \param env The environment: its seabed depth gives the altitude, its current and waves the
  /// tracked water's velocity.
  /// \param t Time [s].
  /// \param[out] out The fix, written only when due.
  /// \return True when a ping was due.
  bool sample(const vehicle::VehicleStated& x, const environment::Environmentd& env, double t,
              DvlSample& out) {
    if (!schedule_.due(t)) return false;
    const double altitude = env.seabed_depth() - x.position.z();
    const DvlMode mode = mode_at(altitude);
    Vector3<double> water = Vector3<double>::Zero();
    if (mode == DvlMode::water) {
      const Vector3<double> below =
          x.point_position(Vector3<double>(0.0, 0.0, p_.water_track_distance));
      const auto s = env.sample(below, t, false);
      water = s.current + s.wave_velocity;
    }
    out = measure(x, mode, water, t);
    out.altitude = altitude;
    schedule_.reschedule(t, 1.0 / (mode == DvlMode::bottom ? p_.bottom_rate : p_.water_rate));
    return true;
  }
  /// \brief One fix in `mode` given the water's NED velocity below [m/s], regardless of the
  /// schedule.
  /// \param x The vehicle's true state.
  /// \param mode The mode of the fix (none: an empty fix, no noise drawn).
  /// \param water Velocity of the tracked water, NED [m/s] (used in water mode only).
  /// \param t Time stamp [s].
  /// \return The fix, body axes (its altitude is left 0: sample fills it).
  DvlSample measure(const vehicle::VehicleStated& x, DvlMode mode, const Vector3<double>& water,
                    double t) {
    DvlSample s;
    s.t = t;
    s.mode = mode;
    if (mode == DvlMode::none) return s;
    Vector3<double> v = x.nu.head<3>();
    if (mode == DvlMode::water) v -= x.attitude.conjugate() * water;
    s.sigma =
        mode == DvlMode::bottom ? p_.noise_floor + p_.noise_fraction * v.norm() : p_.water_noise;
    for (int i = 0; i < 3; ++i) s.velocity(i) = v(i) + s.sigma * rng_.normal();
    return s;
  }
  /// \brief The parameters.
  /// \return The parameters the sensor was built with.
  const DvlParameters& parameters() const { return p_; }
  /// \brief visit_memory(v): the noise stream and the schedule (kelp/core/memory.hpp).
  /// \tparam V a memory visitor \param v the visitor
  KELP_MEMORY(rng_, schedule_)

 private:
  DvlParameters p_;
  RandomStream rng_;
  SensorSchedule schedule_;
};

// ---- compass -------------------------------------------------------------------------------

/// \brief Compass heading: MMC5983MA by default (see the file comment).
struct CompassParameters {
  double rate = 50.0;           ///< [Hz]
  double noise = 0.5 * degree;  ///< σ [rad]
  double bias = 0.0;            ///< constant offset [rad]
};

/// \brief Checks compass parameters.
/// \param p Parameters: rate in (0, 1e4] Hz, noise finite ≥ 0, bias finite.
/// \throws kelp::invalid_argument naming the field.
inline void validate(const CompassParameters& p) {
  detail::check_rate(p.rate, "compass.rate");
  detail::check_sigma(p.noise, "compass.noise");
  KELP_CHECK(std::isfinite(p.bias), "compass.bias must be finite");
}

/// \brief A heading sensor: ψ + bias + white noise, wrapped to (−π, π].
class Compass {
 public:
  /// \brief A compass with its own noise stream.
  /// \param[in] p parameters \param[in] seed run seed \param[in] stream the sensor's stream
  /// number \throws kelp::invalid_argument for bad parameters.
  Compass(const CompassParameters& p, std::uint64_t seed, std::uint64_t stream)
      : p_((validate(p), p)), rng_(seed, stream), schedule_(p.rate) {}
  /// \brief Samples the heading of attitude `q` when due at time t: true and `out` [rad].
  /// \param q True attitude, body → NED.
  /// \param t Time [s].
  /// \param[out] out The heading [rad] in (−π, π], written only when due.
  /// \return True when a sample was due.
  bool sample(const Quaternion<double>& q, double t, double& out) {
    if (!schedule_.due(t)) return false;
    out = measure(heading_of(q));
    return true;
  }
  /// \brief One reading of heading ψ [rad], regardless of the schedule.
  /// \param psi True heading [rad].
  /// \return ψ + bias + noise, wrapped to (−π, π] [rad].
  double measure(double psi) {
    const double a = psi + p_.bias + p_.noise * rng_.normal();
    return std::atan2(std::sin(a), std::cos(a));
  }
  /// \brief The parameters.
  /// \return The parameters the sensor was built with.
  const CompassParameters& parameters() const { return p_; }
  /// \brief visit_memory(v): the noise stream and the schedule (kelp/core/memory.hpp).
  /// \tparam V a memory visitor \param v the visitor
  KELP_MEMORY(rng_, schedule_)

 private:
  CompassParameters p_;
  RandomStream rng_;
  SensorSchedule schedule_;
};

// ---- GPS -----------------------------------------------------------------------------------

/// \brief GPS: u-blox M8 class by default (see the file comment). Horizontal error per axis:
/// Gauss–Markov (σ `bias_sigma`, correlation time `bias_time`) plus white noise `noise`; the
/// vertical ones are `vertical_factor` times larger.
struct GpsParameters {
  double rate = 5.0;             ///< [Hz]
  double noise = 0.5;            ///< white σ per horizontal axis [m]
  double bias_sigma = 2.0;       ///< stationary σ of the slow error per horizontal axis [m]
  double bias_time = 120.0;      ///< its correlation time [s]
  double vertical_factor = 2.0;  ///< vertical σ / horizontal σ [-]
};

/// \brief Checks GPS parameters.
/// \param p Parameters: rate in (0, 1e4] Hz, bias_time finite > 0, the others finite ≥ 0.
/// \throws kelp::invalid_argument naming the field.
inline void validate(const GpsParameters& p) {
  detail::check_rate(p.rate, "gps.rate");
  detail::check_sigma(p.noise, "gps.noise");
  detail::check_sigma(p.bias_sigma, "gps.bias_sigma");
  KELP_CHECK(std::isfinite(p.bias_time) && p.bias_time > 0, "gps.bias_time must be > 0");
  detail::check_sigma(p.vertical_factor, "gps.vertical_factor");
}

/// \brief A GPS antenna at the CO: position + Gauss–Markov error + white noise.
class Gps {
 public:
  /// \brief A GPS with its own noise stream; the slow error starts at a draw of its stationary
  /// distribution.
  /// \param[in] p parameters \param[in] seed run seed \param[in] stream the sensor's stream
  /// number \throws kelp::invalid_argument for bad parameters.
  Gps(const GpsParameters& p, std::uint64_t seed, std::uint64_t stream)
      : p_((validate(p), p)), rng_(seed, stream), schedule_(p.rate) {
    scale_ << 1.0, 1.0, p.vertical_factor;
    for (int i = 0; i < 3; ++i) bias_(i) = p.bias_sigma * scale_(i) * rng_.normal();
  }
  /// \brief Samples the NED position `p` when due at time t: true and `out` [m].
  /// \param p True NED position of the antenna [m].
  /// \param t Time [s].
  /// \param[out] out The fix, NED [m], written only when due.
  /// \return True when a sample was due.
  bool sample(const Vector3<double>& p, double t, Vector3<double>& out) {
    if (!schedule_.due(t)) return false;
    out = measure(p);
    return true;
  }
  /// \brief One fix of NED position `p` [m], regardless of the schedule; advances the slow
  /// error by one period (exact discretisation of the first-order Gauss–Markov process).
  /// \param p True NED position [m].
  /// \return p + slow error + white noise, NED [m].
  Vector3<double> measure(const Vector3<double>& p) {
    const double a = std::exp(-1.0 / (p_.rate * p_.bias_time));
    const double b = p_.bias_sigma * std::sqrt(1.0 - a * a);
    Vector3<double> out;
    for (int i = 0; i < 3; ++i) out(i) = p(i) + bias_(i) + p_.noise * scale_(i) * rng_.normal();
    for (int i = 0; i < 3; ++i) bias_(i) = a * bias_(i) + b * scale_(i) * rng_.normal();
    return out;
  }
  /// \brief The slow error now [m].
  /// \return The Gauss–Markov error, NED [m].
  const Vector3<double>& bias() const { return bias_; }
  /// \brief σ of one fix per axis (white and slow parts together) [m].
  /// \return √(noise² + bias_sigma²) times (1, 1, vertical_factor) [m].
  Vector3<double> sigma() const { return std::hypot(p_.noise, p_.bias_sigma) * scale_; }
  /// \brief The parameters.
  /// \return The parameters the sensor was built with.
  const GpsParameters& parameters() const { return p_; }
  /// \brief visit_memory(v): the noise stream, the schedule and the slow error
  /// (kelp/core/memory.hpp).
  /// \tparam V a memory visitor \param v the visitor
  KELP_MEMORY(rng_, schedule_, bias_)

 private:
  GpsParameters p_;
  RandomStream rng_;
  SensorSchedule schedule_;
  Vector3<double> scale_, bias_ = Vector3<double>::Zero();
};

// ---- USBL ----------------------------------------------------------------------------------

/// \brief USBL fixes of the ROV from the boat: Water Linked Underwater GPS G2 by default (see the
/// file comment).
struct UsblParameters {
  double rate = 1.0;             ///< fixes per second [Hz]
  double noise_floor = 0.05;     ///< σ per axis at zero range [m]
  double noise_fraction = 0.01;  ///< σ growth per metre of slant range [-]
  double latency = 0.5;          ///< from the measurement to its delivery [s]
  double dropout = 0.1;          ///< probability that a fix is lost [-]
  double max_range = 100.0;      ///< no fix beyond this slant range [m]
};

/// \brief The most fixes in flight at once (latency × rate must stay below it).
inline constexpr int usbl_queue_capacity = 64;

/// \brief Checks USBL parameters.
/// \param p Parameters: rate in (0, 1e4] Hz, noise and latency finite ≥ 0, latency × rate below
/// usbl_queue_capacity − 2, dropout in [0, 1), max_range finite > 0.
/// \throws kelp::invalid_argument naming the field.
inline void validate(const UsblParameters& p) {
  detail::check_rate(p.rate, "usbl.rate");
  detail::check_sigma(p.noise_floor, "usbl.noise_floor");
  detail::check_sigma(p.noise_fraction, "usbl.noise_fraction");
  detail::check_sigma(p.latency, "usbl.latency");
  KELP_CHECK(p.latency * p.rate < usbl_queue_capacity - 2,
             "usbl.latency × usbl.rate must be < " + std::to_string(usbl_queue_capacity - 2) +
                 " (fixes in flight)");
  KELP_CHECK(std::isfinite(p.dropout) && p.dropout >= 0 && p.dropout < 1,
             "usbl.dropout must be in [0, 1)");
  KELP_CHECK(std::isfinite(p.max_range) && p.max_range > 0, "usbl.max_range must be > 0");
}

/// \brief One USBL fix of the ROV, NED.
struct UsblFix {
  double measured_at = 0.0;                            ///< when the ping was measured [s]
  double delivered_at = 0.0;                           ///< when the fix is available [s]
  Vector3<double> position = Vector3<double>::Zero();  ///< the ROV's position [m]
  double range = 0.0;                                  ///< slant range [m]
  double sigma = 0.0;                                  ///< σ per axis of the acoustic part [m]
};

/// \brief A USBL transceiver at the boat's CO tracking a locator at the ROV's CO.
///
/// Each due ping is lost with probability `dropout` (or beyond `max_range`); otherwise the fix,
/// boat position estimate + Rz(heading error) (p_rov − p_boat) + noise(σ = floor + fraction·range
/// per NED axis), is delivered `latency` later. Fixes wait in a fixed queue (no allocation) of
/// usbl_queue_capacity, which validate() keeps above latency × rate when poll() is called as
/// often as sample(); a queue never polled keeps its newest fixes.
class Usbl {
 public:
  /// \brief A USBL with its own noise stream and an empty queue.
  /// \param[in] p parameters \param[in] seed run seed \param[in] stream the sensor's stream
  /// number \throws kelp::invalid_argument for bad parameters.
  Usbl(const UsblParameters& p, std::uint64_t seed, std::uint64_t stream)
      : p_((validate(p), p)), rng_(seed, stream), schedule_(p.rate) {}

  /// \brief Pings when due at time t [s]; a fix not lost is queued for poll().
  /// \param[in] rov true NED position of the ROV [m]
  /// \param[in] boat true NED position of the boat [m]
  /// \param[in] boat_estimate the boat's own position estimate [m] \param[in] heading_error the
  /// boat's heading estimate minus its true heading [rad]. \param[in] t time [s]
  /// \returns true when a ping was due (even if its fix was lost).
  bool sample(const Vector3<double>& rov, const Vector3<double>& boat,
              const Vector3<double>& boat_estimate, double heading_error, double t) {
    if (!schedule_.due(t)) return false;
    ++pings_;
    const Vector3<double> r = rov - boat;
    const double range = r.norm();
    if (range > p_.max_range || rng_.bernoulli(p_.dropout)) {
      ++dropouts_;
      return true;
    }
    const double c = std::cos(heading_error), s = std::sin(heading_error);
    const Vector3<double> turned(c * r.x() - s * r.y(), s * r.x() + c * r.y(), r.z());
    UsblFix f;
    f.measured_at = t;
    f.delivered_at = t + p_.latency;
    f.range = range;
    f.sigma = p_.noise_floor + p_.noise_fraction * range;
    for (int i = 0; i < 3; ++i)
      f.position(i) = boat_estimate(i) + turned(i) + f.sigma * rng_.normal();
    if (size_ == usbl_queue_capacity) {  // never polled: the oldest fix is dropped
      head_ = (head_ + 1) % usbl_queue_capacity;
      --size_;
    }
    queue_[(head_ + size_) % usbl_queue_capacity] = f;
    ++size_;
    return true;
  }
  /// \brief Takes the oldest fix delivered by time t [s]: true and `out`.
  /// \param t Time [s].
  /// \param[out] out The fix, written only when one was delivered by t.
  /// \return True when a fix was taken (call again for more).
  bool poll(double t, UsblFix& out) {
    if (size_ == 0 || queue_[head_].delivered_at > t + 1e-9) return false;
    out = queue_[head_];
    head_ = (head_ + 1) % usbl_queue_capacity;
    --size_;
    return true;
  }
  /// \brief Pings so far.
  /// \return The number of due pings, lost ones included.
  long pings() const { return pings_; }
  /// \brief Pings lost so far.
  /// \return The pings lost to dropout or range.
  long dropouts() const { return dropouts_; }
  /// \brief The parameters.
  /// \return The parameters the sensor was built with.
  const UsblParameters& parameters() const { return p_; }

  /// \brief Visits the noise stream, the schedule, the fixes in flight and the counts
  /// (kelp/core/memory.hpp).
  /// \tparam V a memory visitor \param v the visitor
  KELP_MEMORY_BY(memory)

 private:
  template <class Self, class V>
  static void memory(Self& s, V& v) {
    v(s.rng_, s.schedule_);
    for (auto& f : s.queue_) v(f.measured_at, f.delivered_at, f.position, f.range, f.sigma);
    v.bounded(s.head_, usbl_queue_capacity - 1);
    v.bounded(s.size_, usbl_queue_capacity);
    v(s.pings_, s.dropouts_);
  }

  UsblParameters p_;
  RandomStream rng_;
  SensorSchedule schedule_;
  std::array<UsblFix, usbl_queue_capacity> queue_{};
  int head_ = 0, size_ = 0;
  long pings_ = 0, dropouts_ = 0;
};

}  // namespace kelp::nav
