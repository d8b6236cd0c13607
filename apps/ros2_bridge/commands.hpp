// What a ROS 2 node may command the tethered pair with, checked and turned into kelp's commands:
// /rov/cmd_wrench (geometry_msgs/Wrench), /rov/cmd_vel and /boat/cmd_vel (geometry_msgs/Twist),
// /tether/cmd_payout (std_msgs/Float64). No DDS here: the bridge (bridge.cpp) hands the values
// of each sample to a PairCommander, which refuses bad ones (counted by reason, as the SITL
// bridge counts malformed packets) and flies the vehicles through ClosedLoop's overrides.
//
// Frames: ROS's commands are in the body frames of REP 103 (x forward, y left, z up: FLU);
// kelp's body frame is FRD, so y and z (of forces, moments, velocities and rates) change sign
// (kelp::ros2::frd_to_flu, a half turn about x, is its own inverse).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>

#include "kelp/control/controllers.hpp"
#include "kelp/core/rotation.hpp"
#include "kelp/sim/closed_loop.hpp"

namespace kelp_ros2 {

/// Why a command was refused (or none).
enum class Refusal {
  none,          ///< accepted
  not_finite,    ///< a NaN or an infinity in the message
  out_of_range,  ///< beyond what the vehicle can do by more than the margin (CommandLimits)
  unavailable    ///< the run has nothing to command (e.g. /tether/cmd_payout without a winch)
};

/// What one subscription has received, accepted and refused (summary.json's `ros2`).
struct SubscriptionCounters {
  std::uint64_t received = 0, accepted = 0;
  std::uint64_t refused_not_finite = 0, refused_out_of_range = 0, refused_unavailable = 0;
  std::uint64_t refused() const {
    return refused_not_finite + refused_out_of_range + refused_unavailable;
  }
  void count(Refusal r) {
    ++received;
    switch (r) {
      case Refusal::none:
        ++accepted;
        break;
      case Refusal::not_finite:
        ++refused_not_finite;
        break;
      case Refusal::out_of_range:
        ++refused_out_of_range;
        break;
      case Refusal::unavailable:
        ++refused_unavailable;
        break;
    }
  }
  nlohmann::json to_json() const {
    return {{"received", received},
            {"accepted", accepted},
            {"refused", refused()},
            {"refused_not_finite", refused_not_finite},
            {"refused_out_of_range", refused_out_of_range},
            {"refused_unavailable", refused_unavailable}};
  }
};

/// Limits of what is accepted, and how long a command holds.
struct CommandLimits {
  /// A wrench is refused when its minimum-norm allocation asks some thruster for more than this
  /// many times what it can give (in that direction, at the controller's cap); up to that it is
  /// delivered saturated, as the ROV's controller saturates (control::allocate_wrench).
  double wrench_margin = 3.0;
  double max_speed = 5.0;  ///< largest |linear velocity| accepted [m/s] (BlueROV2: ~1.5)
  double max_rate = 5.0;   ///< largest |angular velocity| accepted [rad/s]
  /// A payout rate beyond this many times the winch's max_speed is refused (the winch limits
  /// the others itself: tether::limited_payout_rate).
  double payout_margin = 2.0;
  /// A vehicle returns to kelp's controller when its last accepted command is older than this
  /// (simulation time [s]); ROS's cmd_vel drivers stop on silence alike.
  double timeout = 0.5;
};

/// Gains of the velocity loops behind /rov/cmd_vel and /boat/cmd_vel (kelp's controllers track
/// positions; these are proportional loops on the body velocity over ground).
struct VelocityGains {
  /// ROV: body force per velocity error (surge, sway, heave) [N/(m/s)] and yaw moment per yaw
  /// rate error [N m/(rad/s)]; roll and pitch are kept level with the AUV controller's roll and
  /// pitch gains (control::AuvControllerSettings: 5 N m/rad, 2 N m/(rad/s)).
  double rov_linear[3] = {100.0, 100.0, 120.0};
  double rov_yaw = 20.0;
  double level_kp = 5.0, level_kd = 2.0;
  /// Boat: common thrust per surge speed error [N/(m/s)], differential per yaw rate error
  /// [N/(rad/s)], each side clipped at the scenario's asv_thrust_clip.
  double boat_surge = 40.0, boat_yaw = 20.0;
};

/// Turns accepted ROS 2 commands into ClosedLoop overrides, step by step. No allocation after
/// construction. Holds references into the loop: it must outlive this object.
class PairCommander {
 public:
  PairCommander(kelp::sim::ClosedLoop& loop, const CommandLimits& limits = {},
                const VelocityGains& gains = {})
      : loop_(loop), limits_(limits), gains_(gains) {
    const Eigen::Index n = loop.auv_controller().thruster_chain().allocation().size();
    force_ = Eigen::VectorXd::Zero(n);
    scratch_ = Eigen::VectorXd::Zero(n);
    rov_.thrust = Eigen::VectorXd::Zero(n);
    rov_.command = Eigen::VectorXd::Zero(n);
  }
  PairCommander(const PairCommander&) = delete;
  PairCommander& operator=(const PairCommander&) = delete;

  /// /rov/cmd_wrench: force [N] and torque [N m] in rov/base_link (FLU).
  Refusal rov_wrench(const double force[3], const double torque[3]) {
    if (!finite(force, 3) || !finite(torque, 3)) return Refusal::not_finite;
    kelp::Vector6<double> tau;
    tau << force[0], -force[1], -force[2], torque[0], -torque[1], -torque[2];
    // How far beyond the thrusters' reach: the unsaturated minimum-norm allocation against each
    // thruster's limit in the direction asked.
    const auto& chain = loop_.auv_controller().thruster_chain();
    chain.allocation().distribute(tau, force_);
    double worst = 0.0;
    for (Eigen::Index i = 0; i < force_.size(); ++i) {
      const double limit = std::min(max_thrust_, force_(i) >= 0.0 ? chain.max_positive_thrust(i)
                                                                  : chain.max_negative_thrust(i));
      worst = std::max(worst, std::abs(force_(i)) / limit);
    }
    if (!(worst <= limits_.wrench_margin)) return Refusal::out_of_range;
    rov_mode_ = RovMode::wrench;
    rov_wrench_ = tau;
    rov_since_ = loop_.time();
    return Refusal::none;
  }

  /// /rov/cmd_vel: linear [m/s] and angular [rad/s] velocity in rov/base_link (FLU).
  Refusal rov_velocity(const double linear[3], const double angular[3]) {
    if (!finite(linear, 3) || !finite(angular, 3)) return Refusal::not_finite;
    if (norm3(linear) > limits_.max_speed || norm3(angular) > limits_.max_rate)
      return Refusal::out_of_range;
    rov_mode_ = RovMode::velocity;
    rov_velocity_ << linear[0], -linear[1], -linear[2], angular[0], -angular[1], -angular[2];
    rov_since_ = loop_.time();
    return Refusal::none;
  }

  /// /boat/cmd_vel: linear.x is the surge speed [m/s], angular.z the yaw rate [rad/s]
  /// (boat/base_link, FLU); the boat cannot sway, heave, roll or pitch on command, so the other
  /// entries must be finite and are ignored.
  Refusal boat_velocity(const double linear[3], const double angular[3]) {
    if (!finite(linear, 3) || !finite(angular, 3)) return Refusal::not_finite;
    if (std::abs(linear[0]) > limits_.max_speed || std::abs(angular[2]) > limits_.max_rate)
      return Refusal::out_of_range;
    boat_active_ = true;
    boat_surge_ = linear[0];
    boat_rate_ = -angular[2];  // FLU z up → FRD z down
    boat_since_ = loop_.time();
    return Refusal::none;
  }

  /// /tether/cmd_payout: the winch's payout rate [m/s] (positive pays line out).
  Refusal payout(double rate) {
    const auto* winch = loop_.model().winch();
    if (!std::isfinite(rate)) return Refusal::not_finite;
    if (winch == nullptr) return Refusal::unavailable;
    if (std::abs(rate) > limits_.payout_margin * winch->winch().max_speed)
      return Refusal::out_of_range;
    payout_active_ = true;
    payout_rate_ = rate;
    payout_since_ = loop_.time();
    return Refusal::none;
  }

  /// Before each step: drops commands older than the timeout and sets the loop's overrides from
  /// the ones that hold (velocity loops on the current state). No allocation.
  void apply() {
    const double t = loop_.time();
    if (rov_mode_ != RovMode::none && t - rov_since_ > limits_.timeout) rov_mode_ = RovMode::none;
    if (boat_active_ && t - boat_since_ > limits_.timeout) boat_active_ = false;
    if (payout_active_ && t - payout_since_ > limits_.timeout) payout_active_ = false;
    const auto& s = loop_.state();
    if (rov_mode_ == RovMode::none) {
      loop_.set_auv_override(nullptr);
    } else {
      kelp::Vector6<double> tau = rov_wrench_;
      if (rov_mode_ == RovMode::velocity) {
        const kelp::Vector6<double>& nu = s.auv.nu;
        const kelp::Vector3<double> rpy = kelp::euler_from_quaternion(s.auv.attitude);
        for (int i = 0; i < 3; ++i) tau(i) = gains_.rov_linear[i] * (rov_velocity_(i) - nu(i));
        tau(3) = -gains_.level_kp * rpy(0) - gains_.level_kd * nu(3);
        tau(4) = -gains_.level_kp * rpy(1) - gains_.level_kd * nu(4);
        tau(5) = gains_.rov_yaw * (rov_velocity_(5) - nu(5));
      }
      const auto& chain = loop_.auv_controller().thruster_chain();
      const kelp::control::AllocationScales sc =
          kelp::control::allocate_wrench(chain, tau, max_thrust_, true, force_, scratch_);
      chain.commands_for(force_, rov_.command, rov_.thrust);
      rov_.wrench = chain.wrench(rov_.thrust);
      rov_.saturated = sc.saturated();
      loop_.set_auv_override(&rov_);
    }
    if (!boat_active_) {
      loop_.set_asv_override(nullptr);
    } else {
      const kelp::Vector6<double>& nu = s.asv.nu;
      const double clip = loop_.scenario().asv_thrust_clip;
      const double common = gains_.boat_surge * (boat_surge_ - nu(0));
      const double differential = gains_.boat_yaw * (boat_rate_ - nu(5));
      // More thrust on the port side turns the bow to starboard (positive r in FRD), as in
      // control::AsvController.
      boat_.left = std::clamp(common + differential, -clip, clip);
      boat_.right = std::clamp(common - differential, -clip, clip);
      const Eigen::Vector2d wanted(boat_.left, boat_.right);
      const auto& chain = loop_.asv_controller().thruster_chain();
      chain.commands_for(wanted, boat_.command, boat_thrust_);
      boat_.wrench = chain.wrench(boat_thrust_);
      loop_.set_asv_override(&boat_);
    }
    loop_.set_winch_override(payout_active_ ? &payout_rate_ : nullptr);
  }

  /// True while a ROS 2 command flies the ROV (else kelp's controller does).
  bool rov_commanded() const { return rov_mode_ != RovMode::none; }
  /// True while a ROS 2 command drives the boat.
  bool boat_commanded() const { return boat_active_; }
  /// True while a ROS 2 command drives the winch.
  bool payout_commanded() const { return payout_active_; }

 private:
  enum class RovMode { none, wrench, velocity };
  static bool finite(const double* v, int n) {
    for (int i = 0; i < n; ++i)
      if (!std::isfinite(v[i])) return false;
    return true;
  }
  static double norm3(const double* v) {
    return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  }

  kelp::sim::ClosedLoop& loop_;
  CommandLimits limits_;
  VelocityGains gains_;
  double max_thrust_ = kelp::control::AuvControllerSettings{}.max_thrust;  // the controller's cap
  RovMode rov_mode_ = RovMode::none;
  kelp::Vector6<double> rov_wrench_ = kelp::Vector6<double>::Zero();
  kelp::Vector6<double> rov_velocity_ = kelp::Vector6<double>::Zero();
  double rov_since_ = 0, boat_since_ = 0, payout_since_ = 0;
  bool boat_active_ = false, payout_active_ = false;
  double boat_surge_ = 0, boat_rate_ = 0, payout_rate_ = 0;
  kelp::control::AuvCommand rov_;
  kelp::control::AsvCommand boat_;
  Eigen::Vector2d boat_thrust_ = Eigen::Vector2d::Zero();
  Eigen::VectorXd force_, scratch_;
};

}  // namespace kelp_ros2
