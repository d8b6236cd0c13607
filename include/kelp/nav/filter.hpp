/// \file
/// \brief A navigation filter for one vehicle: the IMU drives it, aiding sensors (depth, DVL,
/// compass, GPS or USBL fixes, the latter possibly late) correct it, and it gives the
/// controllers a nav::Navigation (kelp/nav/estimate.hpp). The filter is a template on its scalar
/// (`NavigationFilterT<Scalar>`; `NavigationFilter` is the double one), so that a unit that
/// includes this header but runs no filter instantiates none of its Eigen code.
///
/// **Choice: a cascade of a complementary attitude filter and a linear Kalman filter.**
/// - Attitude: the explicit complementary filter on SO(3) of Mahony, Hamel and Pflimlin
///   ("Nonlinear complementary filters on the special orthogonal group", IEEE TAC 53(5), 2008):
///   the gyroscope, less its estimated bias, is integrated on the unit quaternion, corrected
///   towards the accelerometer's gravity direction (only while |f| is within 20 % of g, so that
///   the boat's heave in waves does not tilt it) and towards the compass heading; the bias
///   follows the same correction through an integral gain. It is globally convergent, costs a
///   few dozen flops per sample and has no linearisation to go wrong with large initial errors.
/// - Translation: a Kalman filter on x = (p_NED, v_NED, b_a (body), c_NE), 11 states: position,
///   velocity, accelerometer bias and (for a DVL in water track) the horizontal current. Given the
///   attitude estimate R̂, the model p' = v, v' = R̂ (f − b_a) + g e_z, b_a' = w, c' = w is linear,
///   so the Kalman filter is exact for it (no Jacobians of a rotation); the measurements are
///   linear too: depth p_z, bottom-lock velocity R̂ᵀ v, water-track velocity R̂ᵀ (v − c), position
///   fixes p.
/// Why not one error-state EKF with the attitude inside: it would couple attitude and position
/// errors (better with a very accurate IMU and long DVL dead reckoning), but at 15+ states with
/// rotation Jacobians for a gain that kelp's MEMS IMU and 0.5° compass do not show: the attitude
/// error (≈ 0.5°) costs g·sin(0.5°) ≈ 0.09 m/s² of apparent acceleration, which the accelerometer
/// bias state and the aiding sensors absorb. The cascade is what small ROV autopilots do in
/// spirit (an AHRS beside a position estimator) and costs a few hundred flops per IMU sample.
///
/// Late fixes (USBL): the filter keeps its position estimates of the last `history` seconds; a
/// fix measured at t_m is compared with the estimate at t_m and the innovation corrects the
/// current state (the usual cheap treatment of a delayed measurement, exact when the state
/// transition over the delay is a translation). No heap allocation after construction.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <vector>

#include "kelp/core/angles.hpp"
#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/memory.hpp"
#include "kelp/core/rotation.hpp"
#include "kelp/core/scalar.hpp"
#include "kelp/core/types.hpp"
#include "kelp/nav/estimate.hpp"
#include "kelp/nav/sensors.hpp"

namespace kelp::nav {

/// \brief Gains and noise of a NavigationFilter (what the filter assumes, beside the sensors'
/// own σ it is given with each measurement).
struct FilterSettings {
  /// Attitude correction towards gravity [rad/s per unit error]: slow (50 s), so that the
  /// accelerations of waves (periods of seconds) average out; the gyroscope carries the rest.
  double tilt_gain = 0.02;
  double heading_gain = 0.5;       ///< attitude correction towards the compass [1/s]
  double gyro_bias_gain = 0.0005;  ///< integral gain of the gyroscope bias [1/s²]
  /// Unmodelled acceleration (attitude error × g, waves) [m/s²/√Hz].
  double acceleration_noise = 0.1;
  double accel_bias_walk = 3.0e-3;  ///< the accelerometer bias' random walk [m/s³/√Hz]
  bool estimate_current = false;    ///< estimate the current (for water-tracking DVL fixes)
  double current_walk = 0.01;       ///< the current's random walk [m/s/√s]
  /// σ assumed for a water-track fix besides the DVL's own (the waves' orbital velocity in the
  /// tracked layer, which the filter does not model) [m/s].
  double water_track_noise = 0.3;
  double history = 4.0;                    ///< seconds of past positions kept for late fixes [s]
  double initial_position_sigma = 1.0;     ///< [m]
  double initial_velocity_sigma = 0.2;     ///< [m/s]
  double initial_accel_bias_sigma = 0.05;  ///< [m/s²]
  double initial_current_sigma = 0.5;      ///< [m/s]
};

/// \brief Checks filter settings.
/// \param s Settings: gains and noises finite ≥ 0, history in (0, 600] s, initial σ finite > 0.
/// \throws kelp::invalid_argument naming the field.
inline void validate(const FilterSettings& s) {
  detail::check_sigma(s.tilt_gain, "filter.tilt_gain");
  detail::check_sigma(s.heading_gain, "filter.heading_gain");
  detail::check_sigma(s.gyro_bias_gain, "filter.gyro_bias_gain");
  detail::check_sigma(s.acceleration_noise, "filter.acceleration_noise");
  detail::check_sigma(s.accel_bias_walk, "filter.accel_bias_walk");
  detail::check_sigma(s.current_walk, "filter.current_walk");
  detail::check_sigma(s.water_track_noise, "filter.water_track_noise");
  KELP_CHECK(std::isfinite(s.history) && s.history > 0 && s.history <= 600,
             "filter.history must be in (0, 600] s");
  check_positive(s.initial_position_sigma, "filter.initial_position_sigma");
  check_positive(s.initial_velocity_sigma, "filter.initial_velocity_sigma");
  check_positive(s.initial_accel_bias_sigma, "filter.initial_accel_bias_sigma");
  check_positive(s.initial_current_sigma, "filter.initial_current_sigma");
}

/// \brief The navigation filter of one vehicle (see the file comment).
/// \tparam Scalar the scalar of the estimate (double or float); the sensors' samples, the
/// settings and time are double.
template <typename Scalar>
class NavigationFilterT {
 public:
  static constexpr int n = 11;                      ///< Kalman states
  using StateVector = Eigen::Matrix<Scalar, n, 1>;  ///< (p, v, b_a, c)
  using Covariance = Eigen::Matrix<Scalar, n, n>;   ///< its covariance

  /// \param[in] imu the IMU it integrates (its rate and noise) \param[in] s settings
  /// \param[in] gravity g [m/s²] \throws kelp::invalid_argument for bad parameters.
  NavigationFilterT(const ImuParameters& imu, const FilterSettings& s = {},
                    double gravity = kelp::standard_gravity)
      : imu_((validate(imu), imu)), s_((validate(s), s)), g_(gravity) {
    check_positive(gravity, "gravity");
    history_.resize(static_cast<std::size_t>(std::ceil(s.history * imu.rate)) + 2);
  }

  /// \brief Starts the filter at a known NED position and velocity [m, m/s], with the attitude
  /// from an IMU sample at rest-like conditions (roll and pitch from gravity) and a heading [rad].
  /// May be called again to restart: it resets the covariance, biases and history.
  /// \param position NED position [m].
  /// \param velocity NED velocity over ground [m/s].
  /// \param heading Yaw ψ [rad].
  /// \param imu An IMU sample, its time, angular rate and specific force finite: its specific
  /// force gives roll and pitch, its time the filter's clock, its angular rate the first body
  /// rate.
  /// \throws kelp::invalid_argument when position, velocity, heading or the IMU sample's time,
  /// angular rate or specific force is not finite (the filter is then unchanged).
  void initialize(const Vector3<Scalar>& position, const Vector3<Scalar>& velocity, double heading,
                  const ImuSample& imu) {
    check_all_finite(position, "initialize: position");
    check_all_finite(velocity, "initialize: velocity");
    check_finite(heading, "initialize: heading");
    check_finite(imu.t, "initialize: imu.t");
    check_all_finite(imu.gyro, "initialize: imu.gyro");
    check_all_finite(imu.accel, "initialize: imu.accel");
    const Vector3<double>& f = imu.accel;
    const double roll = std::atan2(-f.y(), -f.z());
    const double pitch = std::atan2(f.x(), std::hypot(f.y(), f.z()));
    q_ = quaternion_from_euler(Scalar(roll), Scalar(pitch), Scalar(heading));
    x_.setZero();
    x_.template segment<3>(0) = position;
    x_.template segment<3>(3) = velocity;
    P_.setZero();
    P_.diagonal().template segment<3>(0).setConstant(Scalar(sq(s_.initial_position_sigma)));
    P_.diagonal().template segment<3>(3).setConstant(Scalar(sq(s_.initial_velocity_sigma)));
    P_.diagonal().template segment<3>(6).setConstant(Scalar(sq(s_.initial_accel_bias_sigma)));
    P_.diagonal().template segment<2>(9).setConstant(
        Scalar(s_.estimate_current ? sq(s_.initial_current_sigma) : 0.0));
    gyro_bias_.setZero();
    t_ = imu.t;
    omega_ = imu.gyro.template cast<Scalar>();
    count_ = 0;
    head_ = 0;
    shift_.setZero();
    push_history();
    initialized_ = true;
    refresh();
  }
  /// \brief True once initialize() was called.
  /// \return Whether the filter has been initialized.
  bool initialized() const { return initialized_; }

  /// \brief Integrates an IMU sample (attitude, then position and velocity over the time since
  /// the last one).
  /// \param m The sample: its time, angular rate and specific force finite, its time not earlier
  /// than the last sample's. One at the last sample's time (dt = 0) integrates nothing: it only
  /// sets the body rate.
  /// \throws kelp::invalid_argument when the filter was not initialized, or when the sample's
  /// time, angular rate or specific force is not finite, or its time is earlier than the last
  /// sample's (samples come in time order: one taken back would integrate the span between
  /// them twice) or so far from it that dt is not finite (the filter is then unchanged).
  void predict(const ImuSample& m) {
    KELP_CHECK(initialized_, "NavigationFilter::predict: call initialize() first");
    check_finite(m.t, "NavigationFilter::predict: m.t");
    check_all_finite(m.gyro, "NavigationFilter::predict: m.gyro");
    check_all_finite(m.accel, "NavigationFilter::predict: m.accel");
    const double dt = m.t - t_;
    check_finite(dt, "NavigationFilter::predict: dt (m.t less the last sample's time)");
    KELP_CHECK(dt >= 0,
               "NavigationFilter::predict: m.t is earlier than the last sample's time "
               "(IMU samples must come in time order)");
    t_ = m.t;
    omega_ = m.gyro.template cast<Scalar>();
    if (!(dt > 0)) return;
    // Attitude: gyro less bias, corrected towards gravity when the accelerometer sees about g.
    Vector3<Scalar> w = m.gyro.template cast<Scalar>() - gyro_bias_;
    const double fn = m.accel.norm();
    if (s_.tilt_gain > 0 && std::abs(fn - g_) < 0.2 * g_) {
      const Vector3<Scalar> measured = (-m.accel / fn).template cast<Scalar>();
      const Vector3<Scalar> predicted = q_.conjugate() * Vector3<Scalar>::UnitZ();
      const Vector3<Scalar> e = measured.cross(predicted);
      w += Scalar(s_.tilt_gain) * e;
      gyro_bias_ -= Scalar(s_.gyro_bias_gain) * e * Scalar(dt);
    }
    rotate(w * Scalar(dt));
    // Translation: the Kalman prediction with the new attitude.
    const Matrix3<Scalar> R = q_.toRotationMatrix();
    const Vector3<Scalar> a = R * (m.accel.template cast<Scalar>() - x_.template segment<3>(6)) +
                              Vector3<Scalar>(Scalar(0), Scalar(0), Scalar(g_));
    x_.template segment<3>(0) +=
        x_.template segment<3>(3) * Scalar(dt) + Scalar(0.5) * a * Scalar(dt) * Scalar(dt);
    x_.template segment<3>(3) += a * Scalar(dt);
    // P ← F P Fᵀ with F = I + [0 dt·I A; 0 0 B; 0 0 0] on (p, v, b_a) (A = −½dt² R̂,
    // B = −dt R̂), written out by blocks: a few hundred flops instead of two dense 11³ products.
    const Matrix3<Scalar> A = Scalar(-0.5 * dt * dt) * R, B = Scalar(-dt) * R;
    P_.template middleRows<3>(0) +=
        Scalar(dt) * P_.template middleRows<3>(3) + A * P_.template middleRows<3>(6);
    P_.template middleRows<3>(3) += B * P_.template middleRows<3>(6);
    P_.template middleCols<3>(0) +=
        Scalar(dt) * P_.template middleCols<3>(3) + P_.template middleCols<3>(6) * A.transpose();
    P_.template middleCols<3>(3) += P_.template middleCols<3>(6) * B.transpose();
    const double qv = (sq(s_.acceleration_noise) + sq(imu_.accel_noise_density)) * dt;
    P_.diagonal().template segment<3>(0).array() += Scalar(qv * dt * dt / 3.0);
    P_.diagonal().template segment<3>(3).array() += Scalar(qv);
    P_.diagonal().template segment<3>(6).array() += Scalar(sq(s_.accel_bias_walk) * dt);
    if (s_.estimate_current)
      P_.diagonal().template segment<2>(9).array() += Scalar(sq(s_.current_walk) * dt);
    push_history();
    refresh();
  }

  /// \brief A depth fix z [m] of noise σ [m].
  /// \param z Depth, NED z [m] (positive down), finite.
  /// \param sigma Its standard deviation [m], finite and ≥ 0 (at least 1e-4 m is assumed).
  /// Ignored before initialize().
  /// \throws kelp::invalid_argument when z is not finite or σ is not finite and ≥ 0 (the
  /// filter is then unchanged).
  void update_depth(double z, double sigma) {
    check_finite(z, "NavigationFilter::update_depth: z");
    check_non_negative(sigma, "NavigationFilter::update_depth: sigma");
    Eigen::Matrix<Scalar, 1, n> H = Eigen::Matrix<Scalar, 1, n>::Zero();
    H(0, 2) = Scalar(1);
    Eigen::Matrix<Scalar, 1, 1> y, R;
    y(0) = Scalar(z - x_(2));
    R(0) = Scalar(sq(std::max(sigma, 1e-4)));
    correct<1>(y, H, R);
  }

  /// \brief A bottom-lock velocity (body axes, over ground) [m/s] of noise σ [m/s] per axis.
  /// \param v Velocity over ground in body axes [m/s], finite.
  /// \param sigma Its standard deviation per axis [m/s], finite and ≥ 0 (at least 1e-4 m/s is
  /// assumed).
  /// Ignored before initialize().
  /// \throws kelp::invalid_argument when v is not finite or σ is not finite and ≥ 0 (the
  /// filter is then unchanged).
  void update_body_velocity(const Vector3<Scalar>& v, double sigma) {
    check_all_finite(v, "NavigationFilter::update_body_velocity: v");
    check_non_negative(sigma, "NavigationFilter::update_body_velocity: sigma");
    const Matrix3<Scalar> Rt = q_.toRotationMatrix().transpose();
    Eigen::Matrix<Scalar, 3, n> H = Eigen::Matrix<Scalar, 3, n>::Zero();
    H.template block<3, 3>(0, 3) = Rt;
    const Vector3<Scalar> y = v - Rt * x_.template segment<3>(3);
    correct<3>(y, H, Matrix3<Scalar>::Identity() * Scalar(sq(std::max(sigma, 1e-4))));
  }

  /// \brief A water-track velocity (body axes, relative to the water) [m/s] of noise σ [m/s]
  /// (the filter adds its `water_track_noise`). Used only when the filter estimates the current.
  /// \param v Velocity relative to the water in body axes [m/s], finite.
  /// \param sigma The DVL's standard deviation per axis [m/s], finite and ≥ 0.
  /// Ignored before initialize().
  /// \throws kelp::invalid_argument when v is not finite or σ is not finite and ≥ 0, whether
  /// the filter estimates the current or not (the filter is then unchanged).
  void update_water_velocity(const Vector3<Scalar>& v, double sigma) {
    check_all_finite(v, "NavigationFilter::update_water_velocity: v");
    check_non_negative(sigma, "NavigationFilter::update_water_velocity: sigma");
    if (!s_.estimate_current) return;
    const Matrix3<Scalar> Rt = q_.toRotationMatrix().transpose();
    Eigen::Matrix<Scalar, 3, n> H = Eigen::Matrix<Scalar, 3, n>::Zero();
    H.template block<3, 3>(0, 3) = Rt;
    H.template block<3, 2>(0, 9) = -Rt.template leftCols<2>();
    const Vector3<Scalar> c(x_(9), x_(10), Scalar(0));
    const Vector3<Scalar> y = v - Rt * (x_.template segment<3>(3) - c);
    const double s2 = sq(sigma) + sq(s_.water_track_noise);
    correct<3>(y, H, Matrix3<Scalar>::Identity() * Scalar(std::max(s2, 1e-8)));
  }

  /// \brief A compass heading ψ [rad]; `dt` [s] is the time since the last one (the correction
  /// is a rate).
  /// \param psi Measured heading ψ [rad] (any finite value; the error is wrapped to (−π, π]).
  /// \param dt Time since the last heading update [s], finite and ≥ 0; the correction is
  /// heading_gain·e·dt.
  /// Ignored before initialize(), as the other updates.
  /// \throws kelp::invalid_argument when ψ is not finite or dt is not finite and ≥ 0 (the
  /// filter is then unchanged).
  void update_heading(double psi, double dt) {
    check_finite(psi, "NavigationFilter::update_heading: psi");
    check_non_negative(dt, "NavigationFilter::update_heading: dt");
    if (!initialized_) return;
    const double e = kelp::wrap_angle(psi - kelp::heading_of(q_));
    const Vector3<Scalar> axis = q_.conjugate() * Vector3<Scalar>::UnitZ();  // NED z in body
    rotate(Scalar(s_.heading_gain * e * dt) * axis);
    gyro_bias_ -= Scalar(s_.gyro_bias_gain * e * dt) * axis;
    refresh();
  }

  /// \brief A horizontal position fix (north, east) [m] of noise σ per axis [m] (e.g. a GPS fix,
  /// whose altitude is much worse than its horizontal position).
  /// \param p North, east [m], finite.
  /// \param sigma Standard deviation per axis [m], finite and ≥ 0 (at least 1e-4 m is
  /// assumed).
  /// \param measured_at Time of the measurement [s], finite (see update_position).
  /// Ignored before initialize().
  /// \throws kelp::invalid_argument when p or the time is not finite or σ is not finite and ≥ 0
  /// (the filter is then unchanged).
  void update_horizontal_position(const Eigen::Matrix<Scalar, 2, 1>& p, double sigma,
                                  double measured_at) {
    check_all_finite(p, "NavigationFilter::update_horizontal_position: p");
    check_non_negative(sigma, "NavigationFilter::update_horizontal_position: sigma");
    check_finite(measured_at, "NavigationFilter::update_horizontal_position: measured_at");
    Eigen::Matrix<Scalar, 2, n> H = Eigen::Matrix<Scalar, 2, n>::Zero();
    H.template block<2, 2>(0, 0).setIdentity();
    const Eigen::Matrix<Scalar, 2, 1> y = p - position_at(measured_at).template head<2>();
    correct<2>(y, H, Eigen::Matrix<Scalar, 2, 2>::Identity() * Scalar(sq(std::max(sigma, 1e-4))));
  }

  /// \brief A position fix (NED) [m] of noise σ per axis [m], measured at time `measured_at`
  /// [s] (earlier than now for a late fix; compared with the estimate of then).
  /// \param p NED position [m], finite.
  /// \param sigma Standard deviation per axis [m], each finite and ≥ 0 (each at least 1e-4 m is
  /// assumed).
  /// \param measured_at Time of the measurement [s], finite; times older than the kept history
  /// use its oldest estimate.
  /// Ignored before initialize().
  /// \throws kelp::invalid_argument when p or the time is not finite or a σ is not finite and
  /// ≥ 0 (the filter is then unchanged).
  void update_position(const Vector3<Scalar>& p, const Vector3<Scalar>& sigma, double measured_at) {
    check_all_finite(p, "NavigationFilter::update_position: p");
    for (int i = 0; i < 3; ++i)
      check_non_negative(sigma(i), "NavigationFilter::update_position: sigma");
    check_finite(measured_at, "NavigationFilter::update_position: measured_at");
    Eigen::Matrix<Scalar, 3, n> H = Eigen::Matrix<Scalar, 3, n>::Zero();
    H.template block<3, 3>(0, 0).setIdentity();
    const Vector3<Scalar> y = p - position_at(measured_at);
    Matrix3<Scalar> R = Matrix3<Scalar>::Zero();
    for (int i = 0; i < 3; ++i) R(i, i) = Scalar(sq(std::max(double(sigma(i)), 1e-4)));
    correct<3>(y, H, R);
  }

  /// \brief The estimate as the controllers take it: NED position, attitude, body velocity
  /// over ground (linear from the Kalman velocity, angular from the gyroscope less its bias).
  /// \return The estimate (valid once initialized).
  const NavigationT<Scalar>& navigation() const { return nav_; }
  /// \brief The Kalman state (p, v, b_a, c).
  /// \return p NED [m], v NED [m/s], b_a body [m/s²], c north, east [m/s].
  const StateVector& state() const { return x_; }
  /// \brief Its covariance.
  /// \return The 11×11 covariance of state(), in the squares of its units.
  const Covariance& covariance() const { return P_; }
  /// \brief The gyroscope bias estimate [rad/s].
  /// \return The bias, body axes [rad/s].
  const Vector3<Scalar>& gyro_bias() const { return gyro_bias_; }
  /// \brief The position estimate at time t [s] (within the kept history; clamped to it).
  /// \param t Time [s].
  /// \return NED position [m], interpolated between kept estimates and moved by the corrections
  /// since; the current estimate for t at or after the last sample.
  Vector3<Scalar> position_at(double t) const {
    if (count_ == 0) return x_.template segment<3>(0);
    const std::size_t cap = history_.size();
    const std::size_t kept = std::min(count_, cap);
    // Newest first: find the first entry at or before t.
    for (std::size_t i = 0; i < kept; ++i) {
      const Entry& e = history_[(head_ + cap - 1 - i) % cap];
      if (e.t <= t + 1e-9) {
        if (i == 0) return e.p + shift_;
        const Entry& later = history_[(head_ + cap - i) % cap];
        const double s = later.t > e.t ? (t - e.t) / (later.t - e.t) : 0.0;
        return e.p + Scalar(s) * (later.p - e.p) + shift_;
      }
    }
    return history_[(head_ + cap - kept) % cap].p + shift_;  // older than the history: its oldest
  }

  /// \brief Visits what the filter knows (kelp/core/memory.hpp): attitude, biases, Kalman state
  /// and covariance, clock, the kept positions and the estimate. For a run's checkpoint.
  /// \tparam V a memory visitor \param v the visitor
  KELP_MEMORY_BY(memory)

 private:
  template <class Self, class V>
  static void memory(Self& s, V& v) {
    v(s.q_, s.gyro_bias_, s.omega_, s.x_, s.P_, s.t_);
    for (auto& e : s.history_) v(e.t, e.p);
    v(s.shift_);
    v.bounded(s.head_, s.history_.size() - 1);
    v(s.count_, s.initialized_, s.nav_.position, s.nav_.attitude, s.nav_.nu);
  }

  /// \cond PRIVATE
  struct Entry {
    double t = 0.0;
    Vector3<Scalar> p = Vector3<Scalar>::Zero();
  };
  static double sq(double x) { return x * x; }

  void rotate(const Vector3<Scalar>& phi) {
    const Scalar a = phi.norm();
    if (a > 0) q_ = q_ * Quaternion<Scalar>(Eigen::AngleAxis<Scalar>(a, phi / a));
    q_.normalize();
  }
  void push_history() {
    history_[head_] = Entry{t_, x_.template segment<3>(0) - shift_};
    head_ = (head_ + 1) % history_.size();
    ++count_;
  }
  void refresh() {
    nav_.position = x_.template segment<3>(0);
    nav_.attitude = q_;
    nav_.nu.template head<3>() = q_.conjugate() * Vector3<Scalar>(x_.template segment<3>(3));
    nav_.nu.template tail<3>() = omega_ - gyro_bias_;
  }
  template <int M>
  void correct(const Eigen::Matrix<Scalar, M, 1>& y, const Eigen::Matrix<Scalar, M, n>& H,
               const Eigen::Matrix<Scalar, M, M>& R) {
    if (!initialized_) return;
    // Coefficient-wise products and the closed-form inverse of the (at most 3×3) innovation
    // covariance S, rather than Eigen's general product kernels and an LLT solve (the same
    // result up to rounding; cheaper to compile too, now only where a filter is used).
    const Eigen::Matrix<Scalar, n, M> PHt = P_.lazyProduct(H.transpose());
    const Eigen::Matrix<Scalar, M, M> S = H.lazyProduct(PHt) + R;
    const Eigen::Matrix<Scalar, n, M> K = (S.inverse() * PHt.transpose()).transpose();
    const StateVector dx = K.lazyProduct(y);
    x_ += dx;
    shift_ += dx.template segment<3>(0);  // the kept estimates move with the correction
    // P ← (I − K H) P, kept symmetric (cheaper than Joseph's form: n·M·n flops).
    P_.noalias() -= K.lazyProduct(PHt.transpose());
    P_ = (0.5 * (P_ + P_.transpose())).eval();
    refresh();
  }

  ImuParameters imu_;
  FilterSettings s_;
  double g_;
  Quaternion<Scalar> q_ = Quaternion<Scalar>::Identity();
  Vector3<Scalar> gyro_bias_ = Vector3<Scalar>::Zero(), omega_ = Vector3<Scalar>::Zero();
  StateVector x_ = StateVector::Zero();
  Covariance P_ = Covariance::Identity();
  double t_ = 0.0;
  std::vector<Entry> history_;
  // Kept positions are stored less the corrections applied so far (`shift_`), so that every
  // correction moves all of them at once: a late fix is compared with the estimate of its time
  // as corrected since.
  Vector3<Scalar> shift_ = Vector3<Scalar>::Zero();
  std::size_t head_ = 0, count_ = 0;
  bool initialized_ = false;
  NavigationT<Scalar> nav_;
  /// \endcond
};

/// \brief The navigation filter in double precision.
using NavigationFilter = NavigationFilterT<double>;

}  // namespace kelp::nav
