/// \file
/// \brief Controllers for the tethered pair: an AUV controller (depth, heading and position hold,
/// waypoint following) through an eight-thruster allocation and the thruster chain
/// (vehicle::ThrusterChain, the T200 curve by default), and an ASV
/// controller (station keeping, follow the AUV) through two skid-steering thrusters with the
/// PID gains of Buchholz et al. (2025, arXiv:2508.02264). Both can add the paper's
/// "disturbance-aware" feedforward.
///
/// What a controller sees (`Navigation`): the vehicle's own NED position, attitude and body
/// velocity over ground (a navigation solution: GNSS or USBL, AHRS, DVL), and for the ASV the
/// AUV's position (USBL). Never the true current, waves, wind or tether force. The disturbance
/// feedforward estimates the disturbance wrench from the vehicle's own model and what it senses
/// (a momentum-based disturbance observer): d̂ = LPF[M (ν_k − ν_{k−1})/T − M ν̇_model(τ_applied)],
/// where ν̇_model is the vehicle's forward dynamics in still water under the wrench it applied,
/// and feeds −d̂ forward. Everything it cannot explain with its model (current, waves, wind,
/// tether pull) ends up in d̂.
///
/// Controllers run at their own period (zero-order hold between updates) and allocate nothing
/// after construction. Every class and function here is a template on the scalar of the vehicle
/// model, navigation and thrust (`AuvControllerT<Scalar>`, …; the names without the T are the
/// double ones), so that a translation unit that includes this header but flies no controller
/// instantiates none of their Eigen code. The settings, the PIDs, time and the scalar
/// intermediate quantities (errors, distances, gains) are double for every Scalar.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <type_traits>
#include <vector>

#include "kelp/control/pid.hpp"
#include "kelp/core/angles.hpp"
#include "kelp/core/constants.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/memory.hpp"
#include "kelp/core/rotation.hpp"
#include "kelp/core/types.hpp"
#include "kelp/nav/estimate.hpp"
#include "kelp/vehicle/model.hpp"
#include "kelp/vehicle/state.hpp"
#include "kelp/vehicle/thrusters.hpp"

namespace kelp::control {

// What a controller sees: kelp::nav's estimate (kelp/nav/estimate.hpp), under its old names.
using nav::Navigation;
using nav::navigation_of;
using nav::NavigationT;
// The heading of an attitude and the controllers' angle wrap (kelp/core/angles.hpp).
using kelp::heading_of;
using kelp::wrap_angle;

/// \brief When a controller of period T runs: at its first call, then every T (zero-order hold
/// in between; a late call runs at once and the schedule restarts from it).
/// \tparam Time the clock's type (double).
template <typename Time>
class SampleClockT {
 public:
  /// \brief True when an update is due at time t [s]; `dt` is then the time since the last one
  /// (T on the first).
  /// \param t the time now [s]; calls must not go back in time.
  /// \param period the controller's period T [s], > 0 (not checked here).
  /// \param[out] dt set when due: the time since the last update [s], at least 1e-6 s (`period`
  /// on the first call); left unchanged otherwise.
  /// \return true when the controller should update now (within 1e-9 s of the schedule).
  bool due(Time t, Time period, Time& dt) {
    if (started_ && t < next_ - 1e-9) return false;
    dt = started_ ? std::max(t - last_, Time(1e-6)) : period;
    next_ = (started_ ? next_ : t) + period;
    if (next_ <= t) next_ = t + period;
    last_ = t;
    started_ = true;
    return true;
  }
  /// \brief visit_memory(v): the last and next update times (kelp/core/memory.hpp).
  /// \tparam V a memory visitor \param v the visitor
  KELP_MEMORY(last_, next_, started_)

 private:
  Time last_ = Time(0), next_ = Time(0);
  bool started_ = false;
};

/// \brief The controllers' clock (double seconds).
using SampleClock = SampleClockT<double>;

/// \brief Momentum-based disturbance observer (see the file comment).
/// \tparam Scalar the model's and the navigation's scalar (double or float).
template <typename Scalar>
class DisturbanceObserverT {
 public:
  DisturbanceObserverT() = default;
  /// \brief An observer of the vehicle `model`, estimate zero.
  /// \param[in] model the vehicle's own model (kept by reference: it must outlive the observer)
  /// \param[in] time_constant of the low-pass [s], finite and > 0
  /// \throws kelp::invalid_argument for a time constant not finite and > 0.
  DisturbanceObserverT(const vehicle::VehicleModel<Scalar>& model, double time_constant)
      : model_(&model), tau_(time_constant) {
    check_positive(time_constant, "observer time_constant");
  }
  /// \brief Updates the estimate from the navigation at this update, the wrench applied since
  /// the last one and the time since [s]. Returns d̂ (body wrench [N, N m]).
  /// \param nav the vehicle's navigation now (its body velocity ν [m/s, rad/s] is what is
  /// differentiated).
  /// \param applied the body wrench [N, N m] the vehicle applied since the last update.
  /// \param dt the time since the last update [s], > 0 (not checked).
  /// \return d̂, the low-passed body disturbance wrench [N, N m] (zero until the second update;
  /// unchanged for a default-constructed observer). The reference stays valid for the object's
  /// life.
  const Vector6<Scalar>& update(const NavigationT<Scalar>& nav, const Vector6<Scalar>& applied,
                                double dt) {
    if (model_ == nullptr) return estimate_;
    if (has_last_) {
      vehicle::VehicleState<Scalar> x;
      x.position = last_.position;
      x.attitude = last_.attitude;
      x.nu = last_.nu;
      const Vector6<Scalar> predicted =
          vehicle::forward_dynamics(*model_, ws_, x, applied, Vector6<Scalar>::Zero());
      const Vector6<Scalar> measured = (nav.nu - last_.nu) / Scalar(dt);
      const Vector6<Scalar> d = model_->mass_matrix() * (measured - predicted);
      const double a = dt / (tau_ + dt);
      estimate_ += Scalar(a) * (d - estimate_);
    }
    last_ = nav;
    has_last_ = true;
    return estimate_;
  }
  /// \brief The current estimate d̂.
  /// \return d̂, body wrench [N, N m].
  const Vector6<Scalar>& estimate() const { return estimate_; }
  /// \brief visit_memory(v): the last navigation and the estimate (kelp/core/memory.hpp).
  /// \tparam V a memory visitor \param v the visitor
  KELP_MEMORY(last_.position, last_.attitude, last_.nu, has_last_, estimate_)

 private:
  const vehicle::VehicleModel<Scalar>* model_ = nullptr;
  vehicle::VehicleWorkspace<Scalar> ws_;
  double tau_ = 1.0;
  NavigationT<Scalar> last_;
  bool has_last_ = false;
  Vector6<Scalar> estimate_ = Vector6<Scalar>::Zero();
};

/// \brief The observer in double precision.
using DisturbanceObserver = DisturbanceObserverT<double>;

namespace detail {
/// `T` in a parameter that takes no part in template argument deduction (std::type_identity).
template <typename T>
struct NonDeduced {
  using type = T;
};
}  // namespace detail

/// \brief The factors (each in (0, 1]) by which allocate_wrench() scaled the thrust down to keep
/// every thruster within its limit; all 1 when nothing saturated.
struct AllocationScales {
  double horizontal = 1.0;  ///< the horizontal group (X, Y, N); split saturation only
  double vertical = 1.0;    ///< the vertical group (Z, K, M); split saturation only
  double total = 1.0;       ///< the whole (the sum of the groups with split saturation)
  /// \brief True when any factor is below 1 (the wrench was not delivered in full).
  /// \return whether horizontal, vertical or total is below 1.
  bool saturated() const { return horizontal < 1.0 || vertical < 1.0 || total < 1.0; }
};

/// \brief Allocates a desired body wrench to a thruster set and saturates it, as AuvController
/// does (and so kelp::sim's gym-style environment, whose action is such a wrench): minimum-norm
/// forces f = B⁺ τ (vehicle::ThrusterAllocation::distribute), then scaled so that no thruster
/// exceeds its limit, min(max_thrust, its largest forward or reverse thrust at the chain's supply
/// voltage). With `split_saturation` the horizontal (X, Y, N) and vertical (Z, K, M) parts are
/// allocated and scaled apart, then the sum uniformly if it still exceeds a limit; otherwise the
/// whole is scaled uniformly. No allocation.
/// \param[in] chain the thrusters (allocation, curve, facing, voltage)
/// \param[in] tau desired body wrench [N, N m] \param[in] max_thrust cap on every thruster [N]
/// \param[in] split_saturation see above
/// \param[out] force the thrusters' forces [N] (one entry per thruster, already sized)
/// \param[out] scratch a buffer of the same size (the vertical part's forces)
/// \returns the scale factors applied.
/// \throws kelp::invalid_argument for a non-finite `tau` or wrongly sized buffers.
/// \tparam Scalar the chain's scalar (deduced from `chain` only).
template <typename Scalar>
AllocationScales allocate_wrench(const vehicle::ThrusterChain<Scalar>& chain,
                                 const typename detail::NonDeduced<Vector6<Scalar>>::type& tau,
                                 double max_thrust, bool split_saturation, VectorX<Scalar>& force,
                                 VectorX<Scalar>& scratch) {
  KELP_CHECK(scratch.size() == force.size(), "allocate_wrench: scratch must be sized as force");
  // fit(f) is the largest factor ≤ 1 that keeps every thruster of f within its limit.
  const auto fit = [&](const VectorX<Scalar>& f) {
    double scale = 1.0;
    for (Eigen::Index i = 0; i < f.size(); ++i) {
      const double l = std::min(
          max_thrust, f(i) >= 0.0 ? chain.max_positive_thrust(i) : chain.max_negative_thrust(i));
      if (std::abs(f(i)) * scale > l) scale = l / std::abs(f(i));
    }
    return scale;
  };
  AllocationScales s;
  if (split_saturation) {
    // A depth correction that saturates the vertical thrusters does not shrink the horizontal
    // thrust (on a vehicle whose thrusters split so, e.g. the BlueROV2 Heavy, the groups are
    // independent).
    Vector6<Scalar> part = tau;
    part(2) = part(3) = part(4) = 0.0;
    chain.allocation().distribute(part, force);
    s.horizontal = fit(force);
    force *= Scalar(s.horizontal);
    part = tau - part;
    chain.allocation().distribute(part, scratch);
    s.vertical = fit(scratch);
    scratch *= Scalar(s.vertical);
    force += scratch;
    s.total = fit(force);
    force *= Scalar(s.total);
  } else {
    chain.allocation().distribute(tau, force);
    s.total = fit(force);
    if (s.total < 1.0) force *= Scalar(s.total);
  }
  return s;
}

/// \brief Settings of the AUV controller. Force PIDs act on position errors in the heading frame
/// [m → N], the yaw PID on the heading error [rad → N m], roll and pitch PIDs keep the vehicle
/// level. Defaults tuned for the BlueROV2 Heavy preset (surge mass with added mass ≈ 20 kg, heave
/// ≈ 32 kg): natural frequencies ≈ 1.4 rad/s, about critically damped.
struct AuvControllerSettings {
  PidGains surge{40.0, 4.0, 56.0, 80.0, 10.0};   ///< x error → X [N]
  PidGains sway{40.0, 4.0, 56.0, 80.0, 10.0};    ///< y error → Y [N]
  PidGains heave{60.0, 8.0, 88.0, 100.0, 10.0};  ///< z error → Z [N]
  PidGains roll{5.0, 0.0, 2.0, 10.0};            ///< roll → K [N m]
  PidGains pitch{5.0, 0.0, 2.0, 10.0};           ///< pitch → M [N m]
  PidGains yaw{5.0, 0.2, 3.4, 15.0, 2.0};        ///< heading error → N [N m]
  double period = 0.02;                          ///< update period [s] (50 Hz)
  /// Cap on every thruster's force [N], both ways; the thrusters' own limits at the supply
  /// voltage (forward and reverse, with their facing) apply as well. Default: the T200's largest
  /// forward thrust at the nominal 16 V (vehicle::t200_max_thrust, 51.6 N).
  double max_thrust = vehicle::t200_max_thrust(vehicle::t200_nominal_voltage);
  /// The thrusters' curve (the chain command → thrust; vehicle::ThrusterChain).
  vehicle::ThrusterModel thruster_model = vehicle::t200_model;
  /// ±1 per thruster (vehicle::VehiclePreset::thruster_facing); empty: all +1.
  Eigen::VectorXd thruster_facing;
  /// Supply voltage at the ESCs [V] the inverse uses until set_voltage() changes it.
  double voltage = vehicle::t200_nominal_voltage;
  /// Largest horizontal error fed to the PIDs [m]: a far waypoint is approached at a steady
  /// pace instead of with the full error (a carrot on the line to it).
  double max_horizontal_error = 2.0;
  double acceptance_radius = 0.5;  ///< a waypoint is reached within this distance [m]
  /// Follow the legs between waypoints, not just head for the next one: the position target is
  /// a reference point that moves along the leg at `leg_speed` (from the vehicle's projection on
  /// the leg when the leg begins; the first leg starts where the vehicle was at its first update
  /// after follow()), never more than `max_horizontal_error` ahead of the vehicle's projection.
  /// The PIDs then track a trajectory: a cross-track error (the current's set) is fed back in
  /// full instead of as a fraction of a capped error towards the waypoint, the integrals learn
  /// what the current costs along and across the leg, the reference's velocity is fed to the
  /// derivative terms, and the vehicle faces along the leg. Off: the waypoint itself, capped.
  bool follow_legs = false;
  double leg_speed = 0.5;  ///< speed of the reference along a leg (follow_legs) [m/s]
  /// Saturation: allocate and scale the horizontal (X, Y, N) and vertical (Z, K, M) demands
  /// apart (then the sum uniformly if needed) instead of scaling the whole wrench uniformly, so
  /// that heave saturation does not slow the vehicle down.
  bool split_saturation = false;
  bool compensate = false;              ///< feed the estimated disturbance forward
  double observer_time_constant = 1.0;  ///< [s]
};

/// \brief One AUV controller output.
/// \tparam Scalar the controller's scalar (double or float).
template <typename Scalar>
struct AuvCommandT {
  Vector6<Scalar> wrench = Vector6<Scalar>::Zero();  ///< body wrench the thrusters deliver
  VectorX<Scalar> thrust;                            ///< per thruster [N], after saturation
  VectorX<Scalar> command;  ///< normalised commands (the thruster model's inverse of thrust)
  Vector3<Scalar> position_error = Vector3<Scalar>::Zero();  ///< target − position, NED [m]
  double heading_error = 0.0;                                ///< [rad]
  bool saturated = false;  ///< the allocation had to scale the thrust down
};

/// \brief An AUV controller output in double precision.
using AuvCommand = AuvCommandT<double>;

/// \brief Depth, heading and position hold and waypoint following for an AUV with a fully
/// actuated thruster set (e.g. vehicle::bluerov2_heavy).
/// \tparam Scalar the scalar of the model, the navigation, the thrust and the wrench (double or
/// float); the settings, the PIDs and the errors are double.
template <typename Scalar>
class AuvControllerT {
 public:
  /// \brief A controller holding the origin at heading 0 until hold() or follow().
  /// \param[in] model the AUV's own model (for the disturbance observer; kept by reference)
  /// \param[in] thrusters its allocation \param[in] s settings
  /// \throws kelp::invalid_argument for bad settings (PID gains, a period, max_thrust,
  /// max_horizontal_error, acceptance_radius or observer time constant not finite and > 0) or a
  /// thruster chain the settings do not fit (thruster_facing's size, the voltage).
  AuvControllerT(const vehicle::VehicleModel<Scalar>& model,
                 const vehicle::ThrusterAllocation<Scalar>& thrusters,
                 const AuvControllerSettings& s = {})
      : settings_(s),
        thrusters_(thrusters, s.thruster_model, vehicle::PwmMapping<Scalar>(), s.thruster_facing,
                   s.voltage),
        surge_(s.surge, "surge"),
        sway_(s.sway, "sway"),
        heave_(s.heave, "heave"),
        roll_(s.roll, "roll"),
        pitch_(s.pitch, "pitch"),
        yaw_(s.yaw, "yaw"),
        observer_(model, s.observer_time_constant) {
    check_positive(s.period, "period");
    check_positive(s.max_thrust, "max_thrust");
    check_positive(s.max_horizontal_error, "max_horizontal_error");
    check_positive(s.acceptance_radius, "acceptance_radius");
    command_.thrust = VectorX<Scalar>::Zero(thrusters.size());
    command_.command = VectorX<Scalar>::Zero(thrusters.size());
    force_ = VectorX<Scalar>::Zero(thrusters.size());
    vertical_ = VectorX<Scalar>::Zero(thrusters.size());
  }

  /// \brief Hold this NED position and heading [rad].
  /// \param position the position to hold, NED [m]; clears the waypoints.
  /// \param heading the heading to hold [rad] (yaw about NED down, 0 = north).
  /// \throws kelp::invalid_argument for a non-finite position or heading (nothing changes).
  void hold(const Vector3<Scalar>& position, double heading) {
    check_all_finite(position, "hold position");
    check_finite(heading, "hold heading");
    waypoints_.clear();
    target_ = position;
    heading_ = heading;
  }
  /// \brief Follow these NED waypoints in order, facing the direction of travel; hold the last.
  /// \param waypoints the points, NED [m], at least one; copied. The first leg starts where the
  /// vehicle is at the next update.
  /// \throws kelp::invalid_argument for an empty list or a non-finite point.
  void follow(const std::vector<Vector3<Scalar>>& waypoints) {
    KELP_CHECK(!waypoints.empty(), "follow: the waypoint list is empty");
    for (const auto& w : waypoints) check_all_finite(w, "waypoint");
    waypoints_ = waypoints;
    next_ = 0;
    target_ = waypoints_.front();
    has_leg_start_ = false;
    leg_ = static_cast<std::size_t>(-1);
  }
  /// \brief Index of the waypoint being flown to (== count when all are reached).
  /// \return the index into the list given to follow() (0 when holding).
  std::size_t next_waypoint() const { return waypoints_.empty() ? 0 : next_; }
  /// \brief The current target position, NED [m].
  /// \return the held position or the waypoint being flown to, NED [m].
  const Vector3<Scalar>& target() const { return target_; }

  /// \brief The command at time t [s] for navigation `nav`: recomputed every `period`, held in
  /// between. No allocation.
  /// \param nav the AUV's navigation (NED position, attitude, body velocity over ground).
  /// \param t the time [s], non-decreasing from call to call.
  /// \return the command (recomputed or held); the reference stays valid for the object's
  /// life.
  /// \throws kelp::invalid_argument when a PID's error, or the wrench or thrust computed from
  /// the navigation, is not finite (a non-finite navigation).
  const AuvCommandT<Scalar>& update(const NavigationT<Scalar>& nav, double t) {
    double dt = 0.0;
    if (!clock_.due(t, settings_.period, dt)) return command_;
    if (settings_.compensate) observer_.update(nav, command_.wrench, dt);
    // Waypoints: advance when within the acceptance radius; face the direction of travel.
    Vector3<Scalar> aim = target_;                           // where the PIDs steer to
    Vector3<Scalar> aim_velocity = Vector3<Scalar>::Zero();  // its velocity, NED
    bool held = false;  // the reference waits for the vehicle (max_horizontal_error ahead)
    if (!waypoints_.empty()) {
      if (!has_leg_start_) {
        leg_start_ = nav.position;
        has_leg_start_ = true;
      }
      while (next_ < waypoints_.size() &&
             (waypoints_[next_] - nav.position).norm() < settings_.acceptance_radius)
        ++next_;
      target_ = waypoints_[std::min(next_, waypoints_.size() - 1)];
      aim = target_;
      const Vector3<Scalar> d = target_ - nav.position;
      const Vector3<Scalar> a =
          next_ == 0 ? leg_start_ : waypoints_[std::min(next_, waypoints_.size()) - 1];
      const Vector3<Scalar> leg = target_ - a;
      const double length = leg.norm();
      if (settings_.follow_legs && next_ < waypoints_.size() &&
          length > settings_.acceptance_radius) {
        const Vector3<Scalar> u = leg / Scalar(length);
        const double along = std::clamp(double((nav.position - a).dot(u)), 0.0, length);
        if (leg_ != next_) {  // a new leg: the reference starts level with the vehicle
          leg_ = next_;
          progress_ = along;
        }
        const double ahead = along + settings_.max_horizontal_error;
        const double wanted = progress_ + settings_.leg_speed * dt;
        held = wanted > ahead;
        progress_ = std::min({wanted, ahead, length});
        progress_ = std::max(progress_, 0.0);
        aim = a + Scalar(progress_) * u;
        if (!held && progress_ < length) aim_velocity = Scalar(settings_.leg_speed) * u;
        if (leg.template head<2>().norm() > 2.0 * settings_.acceptance_radius)
          heading_ = std::atan2(leg.y(), leg.x());
      } else if (d.template head<2>().norm() > 2.0 * settings_.acceptance_radius) {
        heading_ = std::atan2(d.y(), d.x());
      }
    }
    const double psi = heading_of(nav.attitude);
    Vector3<Scalar> e = aim - nav.position;
    command_.position_error = target_ - nav.position;
    const double h = e.template head<2>().norm();
    // Capped (a far waypoint); following legs, the reference is already near, and its
    // cross-track part is kept whole up to twice the cap.
    const double cap = (settings_.follow_legs ? 2.0 : 1.0) * settings_.max_horizontal_error;
    if (h > cap) e.template head<2>() *= Scalar(cap / h);
    // Error in the heading frame (yaw only); its rate is minus the body velocity (level flight).
    const double c = std::cos(psi), s = std::sin(psi);
    const Vector3<Scalar> eb(Scalar(c * e.x() + s * e.y()), Scalar(-s * e.x() + c * e.y()), e.z());
    const Vector3<Scalar> vb(Scalar(c * aim_velocity.x() + s * aim_velocity.y()),
                             Scalar(-s * aim_velocity.x() + c * aim_velocity.y()),
                             aim_velocity.z());
    const Vector3<Scalar> rpy = euler_from_quaternion(nav.attitude);
    const double e_psi = wrap_angle(heading_ - psi);
    command_.heading_error = e_psi;
    const double i_saved[4] = {surge_.integral(), sway_.integral(), heave_.integral(),
                               yaw_.integral()};
    Vector6<Scalar> tau;
    tau << surge_.update(eb.x(), dt, vb.x() - nav.nu(0)),
        sway_.update(eb.y(), dt, vb.y() - nav.nu(1)), heave_.update(eb.z(), dt, vb.z() - nav.nu(2)),
        roll_.update(-rpy(0), dt, -nav.nu(3)), pitch_.update(-rpy(1), dt, -nav.nu(4)),
        yaw_.update(e_psi, dt, -nav.nu(5));
    if (settings_.compensate) tau -= observer_.estimate();
    const AllocationScales sc = allocate_wrench(thrusters_, tau, settings_.max_thrust,
                                                settings_.split_saturation, force_, vertical_);
    command_.saturated = sc.saturated();
    if (settings_.split_saturation) {
      // Anti-windup per group: what a group could not deliver is not integrated.
      if (sc.horizontal < 1.0 || sc.total < 1.0) {
        surge_.set_integral(i_saved[0]);
        sway_.set_integral(i_saved[1]);
        yaw_.set_integral(i_saved[3]);
      }
      if (sc.vertical < 1.0 || sc.total < 1.0) heave_.set_integral(i_saved[2]);
    } else if (command_.saturated) {
      // Anti-windup: the allocation could not deliver: keep the integrals where they were.
      surge_.set_integral(i_saved[0]);
      sway_.set_integral(i_saved[1]);
      heave_.set_integral(i_saved[2]);
      yaw_.set_integral(i_saved[3]);
    }
    // The thrust the thrusters deliver for these commands (the curve saturates at its peak).
    thrusters_.commands_for(force_, command_.command, command_.thrust);
    command_.wrench = thrusters_.wrench(command_.thrust);
    return command_;
  }
  /// \brief The last command.
  /// \return what update() last returned (zero thrust before the first update).
  const AuvCommandT<Scalar>& command() const { return command_; }
  /// \brief Sets the thrusters' supply voltage [V] (e.g. the battery's, each step): the inverse
  /// and the saturation use it from the next update on.
  /// \param volts the supply voltage [V], finite, in [0, 20].
  /// \throws kelp::invalid_argument outside [0, 20] V or not finite (nothing changes).
  void set_voltage(double volts) { thrusters_.set_voltage(volts); }
  /// \brief The thrusters' supply voltage [V].
  /// \return the voltage [V] the inverse uses (AsvControllerSettings / AuvControllerSettings
  /// `voltage` until set_voltage()).
  double voltage() const { return thrusters_.voltage(); }
  /// \brief The thruster chain (curve, facing, voltage) the inverse uses.
  /// \return the controller's own chain (valid for the object's life).
  const vehicle::ThrusterChain<Scalar>& thruster_chain() const { return thrusters_; }
  /// \brief The disturbance estimate (zero unless compensating).
  /// \return d̂, body wrench [N, N m].
  const Vector6<Scalar>& disturbance_estimate() const { return observer_.estimate(); }

  /// \brief Visits what the controller remembers between updates (kelp/core/memory.hpp): the
  /// PIDs, the observer, the waypoints and the progress along them, the last command, the clock
  /// and the thrusters' supply voltage. For a run's checkpoint.
  /// \tparam V a memory visitor \param v the visitor
  KELP_MEMORY_BY(memory)

 private:
  template <class Self, class V>
  static void memory(Self& s, V& v) {
    v(s.surge_, s.sway_, s.heave_, s.roll_, s.pitch_, s.yaw_, s.observer_);
    v.list(s.waypoints_, std::size_t(1) << 20, [&](auto& w) { v(w); });
    v.bounded(s.next_, s.waypoints_.size());
    v(s.target_, s.leg_start_, s.has_leg_start_, s.leg_, s.progress_, s.heading_);
    v(s.command_.wrench, s.command_.thrust, s.command_.command, s.command_.position_error,
      s.command_.heading_error, s.command_.saturated, s.force_, s.vertical_, s.clock_);
    double volts = s.thrusters_.voltage();
    v(volts);
    if constexpr (!std::is_const_v<Self>) s.thrusters_.set_voltage(volts);
  }

  AuvControllerSettings settings_;
  vehicle::ThrusterChain<Scalar> thrusters_;
  Pid surge_, sway_, heave_, roll_, pitch_, yaw_;
  DisturbanceObserverT<Scalar> observer_;
  std::vector<Vector3<Scalar>> waypoints_;
  std::size_t next_ = 0;
  Vector3<Scalar> target_ = Vector3<Scalar>::Zero();
  Vector3<Scalar> leg_start_ = Vector3<Scalar>::Zero();  // where the first leg begins
  bool has_leg_start_ = false;
  std::size_t leg_ = static_cast<std::size_t>(-1);  // the leg `progress_` belongs to
  double progress_ = 0.0;                           // the reference's distance along its leg [m]
  double heading_ = 0.0;
  AuvCommandT<Scalar> command_;
  VectorX<Scalar> force_, vertical_;
  SampleClock clock_;
};

/// \brief The AUV controller in double precision.
using AuvController = AuvControllerT<double>;

/// \brief How the ASV follows its target.
enum class AsvLaw {
  /// The paper's pursuit (Buchholz et al. 2025): a PID on the distance pushes forward as far as the
  /// bow points at the target, a PID on the bearing turns it; inside `arrive_radius` only the
  /// heading is held (so a current carries the boat off until it turns back): keeping station,
  /// the station's heading; following, the heading the boat had when it arrived inside the
  /// radius.
  pursuit,
  /// Velocity tracking (kelp's default): the boat is commanded the target's velocity over ground
  /// (estimated from its successive positions, e.g. USBL fixes of the AUV, low-passed over
  /// `target_velocity_time_constant`) plus `position_gain` × the position error, capped at
  /// `max_speed`; the bow is turned to that velocity (`heading` PID) and the surge speed over
  /// ground along the bow is held by the `speed` PID, whose integral learns the thrust that
  /// current, wind and tether cost. Holding station, the commanded velocity points back up the
  /// current, so the boat faces into it and stems it instead of drifting off and turning round.
  track
};

/// \brief Settings of the ASV controller. Defaults: the paper's gains (Buchholz et al. 2025):
/// follow the AUV with a linear PID (0.5, 0.1, 0.05) on the distance and an angular PID
/// (4.0, 2.0, 1.0) on the bearing error at 10 Hz, thrust clipped at 15; yaw PID (2.0, 0, 0.5)
/// for the heading once there. Read here (the paper gives no units) as thrust per side [N]:
/// port = linear + angular, starboard = linear − angular (a positive bearing error, target to
/// starboard, turns the bow to starboard), each clipped to ±thrust_clip.
struct AsvControllerSettings {
  PidGains linear{0.5, 0.1, 0.05, 15.0, 100.0};  ///< distance [m] → common thrust [N]
  PidGains angular{4.0, 2.0, 1.0, 15.0, 5.0};    ///< bearing error [rad] → differential [N]
  PidGains yaw{2.0, 0.0, 0.5, 15.0};             ///< heading error [rad] → differential [N]
  double period = 0.1;                           ///< update period [s] (10 Hz)
  double thrust_clip = 15.0;                     ///< per thruster [N]
  /// Within this distance the boat only holds its heading (AsvLaw::pursuit: the station's, or,
  /// following, the one it arrived with) [m].
  double arrive_radius = 1.0;
  /// Follow offset: the boat's target is the AUV's horizontal position plus this NED offset [m].
  Vector3<double> follow_offset = Vector3<double>::Zero();
  bool compensate = false;              ///< feed the estimated disturbance forward
  double observer_time_constant = 2.0;  ///< [s]
  /// The thrusters' curve (the chain command → thrust; vehicle::ThrusterChain).
  vehicle::ThrusterModel thruster_model = vehicle::t200_model;
  /// ±1 per thruster (vehicle::VehiclePreset::thruster_facing); empty: both +1.
  Eigen::VectorXd thruster_facing;
  /// Supply voltage at the ESCs [V] the inverse uses until set_voltage() changes it.
  double voltage = vehicle::t200_nominal_voltage;
  /// The law (`pursuit`: the paper's, with `linear`, `angular`, `yaw`; `track`: the settings
  /// below). The default is the paper's; kelp::sim's "kelp" preset is `track_settings()`.
  AsvLaw law = AsvLaw::pursuit;
  /// \name Velocity tracking (AsvLaw::track). Defaults sized for vehicle::blueboat (surge mass
  /// with added mass ≈ 17 kg, yaw inertia ≈ 5.6 kg m², half track 0.295 m): heading loop
  /// ω_n ≈ 1.9 rad/s, ζ ≈ 0.8; speed loop bandwidth ≈ 1.7 rad/s.
  ///@{
  PidGains speed{15.0, 6.0, 0.0, 30.0, 4.0};  ///< surge speed error [m/s] → common thrust [N]
  PidGains heading{20.0, 0.0, 6.0, 30.0};     ///< heading error [rad] → differential [N]
  double position_gain = 0.5;                 ///< position error → velocity [1/s]
  double max_speed = 1.5;                     ///< cap of the commanded speed [m/s]
  /// Below this commanded speed the heading is held rather than turned to it [m/s].
  double turn_speed = 0.15;
  double target_velocity_time_constant = 1.0;  ///< low-pass of the target's velocity [s]
  ///@}
};

/// \brief One ASV controller output.
/// \tparam Scalar the controller's scalar (double or float).
template <typename Scalar>
struct AsvCommandT {
  /// \brief Thrust asked of the port (left) and starboard (right) thrusters [N], each within
  /// ±thrust_clip (before the thruster curve's own saturation).
  ///@{
  double left = 0.0, right = 0.0;
  ///@}
  Eigen::Matrix<Scalar, 2, 1> command = Eigen::Matrix<Scalar, 2, 1>::Zero();  ///< normalised
  Vector6<Scalar> wrench = Vector6<Scalar>::Zero();          ///< body wrench delivered
  Vector3<Scalar> position_error = Vector3<Scalar>::Zero();  ///< target − position, NED [m]
  double heading_error = 0.0;  ///< bearing (or heading, once there) error [rad]
};

/// \brief An ASV controller output in double precision.
using AsvCommand = AsvCommandT<double>;

/// \brief Station keeping and follow-the-AUV for a skid-steered ASV (vehicle::blueboat).
/// \tparam Scalar the scalar of the model, the navigation, the thrust and the wrench (double or
/// float); the settings, the PIDs and the errors are double.
template <typename Scalar>
class AsvControllerT {
 public:
  /// \brief A controller keeping station at the origin, heading 0, until station() or
  /// follow_auv().
  /// \param[in] model the ASV's own model (for the observer; kept by reference)
  /// \param[in] thrusters its two thrusters (port first) \param[in] s settings
  /// \throws kelp::invalid_argument for bad settings (PID gains; period, thrust_clip,
  /// arrive_radius, max_speed, target_velocity_time_constant, observer time constant not finite
  /// and > 0; position_gain, turn_speed negative; a non-finite follow_offset), a thruster count
  /// other than two, thrusters not side by side, or a chain the settings do not fit.
  AsvControllerT(const vehicle::VehicleModel<Scalar>& model,
                 const vehicle::ThrusterAllocation<Scalar>& thrusters,
                 const AsvControllerSettings& s = {})
      : settings_(s),
        thrusters_(thrusters, s.thruster_model, vehicle::PwmMapping<Scalar>(), s.thruster_facing,
                   s.voltage),
        linear_(s.linear, "linear"),
        angular_(s.angular, "angular"),
        yaw_(s.yaw, "yaw"),
        speed_(s.speed, "speed"),
        heading_pid_(s.heading, "heading"),
        observer_(model, s.observer_time_constant) {
    KELP_CHECK(thrusters.size() == 2, "AsvController: needs two thrusters (port, starboard)");
    check_positive(s.max_speed, "max_speed");
    check_non_negative(s.position_gain, "position_gain");
    check_non_negative(s.turn_speed, "turn_speed");
    check_positive(s.target_velocity_time_constant, "target_velocity_time_constant");
    check_positive(s.period, "period");
    check_positive(s.thrust_clip, "thrust_clip");
    check_positive(s.arrive_radius, "arrive_radius");
    check_all_finite(s.follow_offset, "follow_offset");
    // Lever arm of the differential thrust: half the thrusters' lateral distance.
    half_track_ = 0.5 * std::abs(thrusters.positions()(1, 1) - thrusters.positions()(1, 0));
    KELP_CHECK(half_track_ > 0.0, "AsvController: the thrusters must be side by side");
  }

  /// \brief Keep station at this NED point (z ignored) and heading [rad].
  /// \param point the station, NED [m].
  /// \param heading the heading held within arrive_radius (pursuit law) [rad].
  /// \throws kelp::invalid_argument for a non-finite point or heading (nothing changes).
  void station(const Vector3<Scalar>& point, double heading) {
    check_all_finite(point, "station point");
    check_finite(heading, "station heading");
    follow_ = false;
    arrived_ = false;
    target_ = point;
    heading_ = heading;
  }
  /// \brief Follow the AUV (its position given to each update) at `follow_offset`. Within
  /// arrive_radius the pursuit law holds the heading the boat had when it arrived there (taken
  /// anew at each arrival).
  void follow_auv() {
    follow_ = true;
    arrived_ = false;
  }

  /// \brief The command at time t [s] from the boat's navigation and the AUV's position (USBL).
  /// Recomputed every `period`, held in between.
  /// \param nav the boat's navigation (NED position, attitude, body velocity over ground).
  /// \param auv_position the AUV's position, NED [m] (used when following, see follow_auv()).
  /// \param t the time [s], non-decreasing from call to call.
  /// \return the command (recomputed or held); the reference stays valid for the object's
  /// life.
  /// \throws kelp::invalid_argument when a PID's error, or the wrench or thrust computed from
  /// the navigation, is not finite (a non-finite navigation).
  const AsvCommandT<Scalar>& update(const NavigationT<Scalar>& nav,
                                    const Vector3<Scalar>& auv_position, double t) {
    double dt = 0.0;
    if (!clock_.due(t, settings_.period, dt)) return command_;
    if (settings_.compensate) observer_.update(nav, command_.wrench, dt);
    if (follow_) target_ = auv_position + settings_.follow_offset.template cast<Scalar>();
    const double psi = heading_of(nav.attitude);
    Vector3<Scalar> e = target_ - nav.position;
    e.z() = Scalar(0);
    command_.position_error = e;
    const double distance = e.norm();
    double common = 0.0, differential = 0.0;
    if (settings_.law == AsvLaw::track) {
      track(nav, e, psi, dt, common, differential);
    } else if (distance > settings_.arrive_radius) {
      const double bearing = wrap_angle(std::atan2(e.y(), e.x()) - psi);
      command_.heading_error = bearing;
      // Push forward only as far as the bow points at the target.
      common = linear_.update(distance, dt) * std::max(0.0, std::cos(bearing));
      differential = angular_.update(bearing, dt, -nav.nu(5));
      yaw_.reset();
      arrived_ = false;
    } else {
      // Following, the heading held is the one the boat arrives with (keeping station, the
      // station's).
      if (follow_ && !arrived_) heading_ = psi;
      arrived_ = true;
      const double e_psi = wrap_angle(heading_ - psi);
      command_.heading_error = e_psi;
      differential = yaw_.update(e_psi, dt, -nav.nu(5));
      linear_.reset();
      angular_.reset();
    }
    if (settings_.compensate) {
      // Feed forward −d̂ through the same mix: surge and yaw moment.
      const Vector6<Scalar>& d = observer_.estimate();
      common -= 0.5 * d(0);
      differential -= 0.5 * d(5) / half_track_;
    }
    const double clip = settings_.thrust_clip;
    // More thrust on the port side turns the bow to starboard (positive yaw, NED).
    command_.left = std::clamp(common + differential, -clip, clip);
    command_.right = std::clamp(common - differential, -clip, clip);
    const Eigen::Matrix<Scalar, 2, 1> wanted(Scalar(command_.left), Scalar(command_.right));
    Eigen::Matrix<Scalar, 2, 1> f;
    thrusters_.commands_for(wanted, command_.command, f);
    command_.wrench = thrusters_.wrench(f);
    return command_;
  }
  /// \brief The last command.
  /// \return what update() last returned (zero before the first update).
  const AsvCommandT<Scalar>& command() const { return command_; }
  /// \brief Sets the thrusters' supply voltage [V] (e.g. the battery's, each step): the inverse
  /// uses it from the next update on.
  /// \param volts the supply voltage [V], finite, in [0, 20].
  /// \throws kelp::invalid_argument outside [0, 20] V or not finite (nothing changes).
  void set_voltage(double volts) { thrusters_.set_voltage(volts); }
  /// \brief The thrusters' supply voltage [V].
  /// \return the voltage [V] the inverse uses (AsvControllerSettings / AuvControllerSettings
  /// `voltage` until set_voltage()).
  double voltage() const { return thrusters_.voltage(); }
  /// \brief The thruster chain (curve, facing, voltage) the inverse uses.
  /// \return the controller's own chain (valid for the object's life).
  const vehicle::ThrusterChain<Scalar>& thruster_chain() const { return thrusters_; }
  /// \brief The current target position, NED [m].
  /// \return the station, or the AUV's position plus follow_offset at the last update [m].
  const Vector3<Scalar>& target() const { return target_; }
  /// \brief The target's estimated velocity over ground (AsvLaw::track; zero until two updates
  /// have seen it), NED [m/s].
  /// \return the low-passed velocity, NED [m/s], z = 0.
  const Vector3<Scalar>& target_velocity() const { return target_velocity_; }

  /// \brief Visits what the controller remembers between updates (kelp/core/memory.hpp): the
  /// PIDs, the observer, the target and its velocity, the course, the last command, the clock and
  /// the thrusters' supply voltage. For a run's checkpoint.
  /// \tparam V a memory visitor \param v the visitor
  KELP_MEMORY_BY(memory)

 private:
  template <class Self, class V>
  static void memory(Self& s, V& v) {
    v(s.linear_, s.angular_, s.yaw_, s.speed_, s.heading_pid_, s.last_target_, s.target_velocity_,
      s.course_, s.has_last_target_, s.has_course_, s.observer_, s.target_, s.heading_, s.follow_,
      s.arrived_);
    v(s.command_.left, s.command_.right, s.command_.command, s.command_.wrench,
      s.command_.position_error, s.command_.heading_error, s.clock_);
    double volts = s.thrusters_.voltage();
    v(volts);
    if constexpr (!std::is_const_v<Self>) s.thrusters_.set_voltage(volts);
  }

  // AsvLaw::track: velocity command from the target's velocity and the position error, heading
  // to it, surge speed along the bow.
  void track(const NavigationT<Scalar>& nav, const Vector3<Scalar>& e, double psi, double dt,
             double& common, double& differential) {
    if (has_last_target_) {
      const Vector3<Scalar> v = (target_ - last_target_) / Scalar(dt);
      const double a = dt / (settings_.target_velocity_time_constant + dt);
      target_velocity_ += Scalar(a) * (v - target_velocity_);
      target_velocity_.z() = Scalar(0);
    }
    last_target_ = target_;
    has_last_target_ = true;
    Vector3<Scalar> v_cmd = target_velocity_ + Scalar(settings_.position_gain) * e;
    const double speed = v_cmd.norm();
    if (speed > settings_.max_speed) v_cmd *= Scalar(settings_.max_speed / speed);
    if (speed > settings_.turn_speed || !has_course_) {
      course_ = speed > settings_.turn_speed ? double(std::atan2(v_cmd.y(), v_cmd.x())) : psi;
      has_course_ = true;
    }
    const double e_psi = wrap_angle(course_ - psi);
    command_.heading_error = e_psi;
    // Surge speed over ground wanted along the bow (negative: back up).
    const double u_wanted = v_cmd.x() * std::cos(psi) + v_cmd.y() * std::sin(psi);
    const double clip = settings_.thrust_clip;
    differential = std::clamp(heading_pid_.update(e_psi, dt, -nav.nu(5)), -clip, clip);
    // Turning first: the common thrust gets what the differential leaves of the clip.
    const double room = clip - std::abs(differential);
    common = std::clamp(speed_.update(u_wanted - nav.nu(0), dt), -room, room);
  }

  AsvControllerSettings settings_;
  vehicle::ThrusterChain<Scalar> thrusters_;
  Pid linear_, angular_, yaw_, speed_, heading_pid_;
  Vector3<Scalar> last_target_ = Vector3<Scalar>::Zero();
  Vector3<Scalar> target_velocity_ = Vector3<Scalar>::Zero();
  double course_ = 0.0;
  bool has_last_target_ = false, has_course_ = false;
  DisturbanceObserverT<Scalar> observer_;
  Vector3<Scalar> target_ = Vector3<Scalar>::Zero();
  double heading_ = 0.0, half_track_ = 0.0;
  bool follow_ = false;
  // Inside arrive_radius at the last update (pursuit): following, heading_ is then the heading
  // the boat arrived with.
  bool arrived_ = false;
  AsvCommandT<Scalar> command_;
  SampleClock clock_;
};

/// \brief The ASV controller in double precision.
using AsvController = AsvControllerT<double>;

}  // namespace kelp::control
