/// \file
/// \brief The core of a gym-style environment over the tethered pair: a scenario's ClosedLoop
/// whose ROV (and optionally boat) is flown by an action instead of its controller, with a fixed
/// observation, a documented reward and the episode's end.
///
/// The action goes through the same thrust allocation and saturation as the ROV's controller
/// (control::allocate_wrench on the controller's own thruster chain, at its battery's voltage),
/// so an agent and the controller command the vehicle alike. Python's `kelp.TetheredPairEnv`
/// (gymnasium's API: reset → (obs, info), step → (obs, reward, terminated, truncated, info)) and
/// `kelp.Batch` sit on it. Part of the optional `kelp::sim` component.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>

#include "kelp/control/controllers.hpp"
#include "kelp/core/error.hpp"
#include "kelp/core/rotation.hpp"
#include "kelp/sim/closed_loop.hpp"
#include "kelp/sim/export.hpp"
#include "kelp/sim/scenario.hpp"

namespace kelp {
namespace sim {

/// \brief Options of a TetheredPairEnv.
struct PairEnvOptions {
  /// Time between two actions [s]: a multiple of ClosedLoop::dt (10 ms), the action held
  /// over it (zero-order hold).
  double control_period = 0.1;
  /// The action also drives the boat (two more entries: port and starboard thrust); false: the
  /// boat's controller follows the ROV as in the scenario's runs.
  bool asv_action = false;
  /// The episode terminates when the ROV is farther than this from the survey path [m].
  double max_path_error = 20.0;
  /// Reward per metre of path error, per control period (see TetheredPairEnv).
  double path_weight = 1.0;
  /// Reward per joule the ROV's battery delivers (see TetheredPairEnv) [1/J].
  double energy_weight = 0.01;
};

/// \brief The tethered pair of a scenario as a reinforcement-learning environment (the core of
/// Python's `kelp.TetheredPairEnv`).
///
/// **Episode.** reset(seed) builds the scenario's world with `seed` as its sea's seed (waves,
/// gusts): the same seed gives the same episode, bit for bit. step(action) holds the action for
/// `control_period` (k = control_period / 10 ms system steps of the ClosedLoop); the episode is
/// *truncated* when the scenario's duration is reached and *terminated* when the ROV is farther
/// than `max_path_error` from the survey path or a step fails (kelp::numerical_error: the world
/// stays as it was before the failing step; error() says why).
///
/// **Action** (action_size() = 6, or 8 with `asv_action`), each entry in [−1, 1] (clipped):
/// the ROV's desired body wrench [X, Y, Z, K, M, N] as fractions of (80 N, 80 N, 100 N, 10 N m,
/// 10 N m, 15 N m) — the output limits of the ROV controller's PIDs
/// (control::AuvControllerSettings) — allocated to its eight thrusters by
/// control::allocate_wrench with split saturation, as the controller's "kelp" preset does; with
/// `asv_action`, then the boat's port and starboard thrust as fractions of the scenario's
/// `asv_thrust_clip` (25 N by default), through its controller's thruster chain.
///
/// **Observation** (observation_size() = 20 doubles, unbounded): [0, 3) the ROV's position
/// minus its current waypoint (NED [m]); [3, 6) its roll, pitch, yaw (ZYX Euler [rad]); [6, 12)
/// its body velocity ν (u, v, w [m/s], p, q, r [rad/s]); [12, 15) the boat's position minus the
/// ROV's (NED [m]); [15] the boat's yaw [rad]; [16, 19) the tether's force on the ROV (NED [N]);
/// [19] the ROV's path error e (its distance from the survey leg it flies, as in the run's
/// metrics [m]).
///
/// **Reward** per step: r = −path_weight · e − energy_weight · ΔE, with e the path error after
/// the step [m] and ΔE the energy the ROV's battery delivered during it [J] (0 in a scenario
/// without propulsion). The defaults (1 /m, 0.01 /J) make 1 m of error cost as much as 100 J
/// (the ROV's thrusters hovering and cruising draw ~50–300 W, i.e. 5–30 J per 0.1 s).
///
/// No heap allocation in step(). The environment holds references into itself: it can be
/// neither copied nor moved.
class KELP_SIM_API TetheredPairEnv {
 public:
  /// Observation entries.
  static constexpr int observation_size = 20;
  /// ROV action entries (the boat's two follow with PairEnvOptions::asv_action).
  static constexpr int auv_action_size = 6;
  /// \brief The wrench an action entry of 1 asks for [N, N m] (see the class).
  static constexpr std::array<double, 6> action_scale{80.0, 80.0, 100.0, 10.0, 10.0, 15.0};

  /// \brief An environment over `scenario` (its seed replaced by reset()'s); built at seed
  /// `scenario.seed`.
  /// \throws kelp::invalid_argument for a control period that is not a positive multiple of
  /// 10 ms, non-positive weights or max_path_error; scenario_error, kelp::invalid_argument from
  /// the world (world_setup()).
  /// \param scenario the scenario (copied; its duration, controllers and mission are used)
  /// \param options the control period, the boat action, the termination and the reward
  explicit TetheredPairEnv(const Scenario& scenario, const PairEnvOptions& options = {});

  TetheredPairEnv(const TetheredPairEnv&) = delete;
  TetheredPairEnv& operator=(const TetheredPairEnv&) = delete;

  /// \brief Entries of an action. \return 6, or 8 with PairEnvOptions::asv_action
  int action_size() const { return options_.asv_action ? 8 : 6; }
  /// \brief System steps (10 ms) per step(). \return control_period / ClosedLoop::dt, ≥ 1
  long substeps() const { return substeps_; }
  /// \brief The options. \return the options the environment was built with
  const PairEnvOptions& options() const { return options_; }

  /// \brief Starts a new episode: the scenario's world with `seed` as its sea's seed, at rest
  /// (the scenario's start), the action zero. Allocates (it builds the world).
  /// \param seed the sea's seed (waves, gusts) of the new episode
  /// \throws as the constructor; the environment is then as it was.
  void reset(std::uint64_t seed);

  /// \brief Sets the action held from the next step on: `action` points to action_size()
  /// entries, each clipped to [−1, 1]. No allocation.
  /// \param action action_size() entries (see the class), not null
  /// \throws kelp::invalid_argument for a non-finite entry (the action is then unchanged).
  void apply(const double* action);

  /// \brief Lets the scenario's controllers fly the vehicles (true) or the action (false, the
  /// default) from the next step on; the controllers run all along, so switching is seamless.
  /// kelp::sim::Batch flies by the controllers when it is given no actions.
  /// \param yes true: the controllers fly; false: the action does
  void fly_by_controllers(bool yes);
  /// \brief Who flies the vehicles (fly_by_controllers()).
  /// \return true when the scenario's controllers do, false when the action does
  bool flown_by_controllers() const { return controllers_; }

  /// \brief One control period: applies `action` (see apply()) and advances the world by
  /// substeps() system steps, then observes it. Does nothing once the episode has ended
  /// (terminated() or truncated()) but return 0. No allocation.
  /// \param action action_size() entries (see apply()), not null
  /// \returns the reward of the step (see the class).
  /// \throws kelp::invalid_argument for a bad action (nothing is stepped).
  double step(const double* action);

  /// \brief As step() with the action set earlier (apply()), e.g. by kelp::sim::Batch.
  /// \return the reward of the step (0 once the episode has ended). A failed system step does
  /// not throw: it terminates the episode (error()).
  double advance();

  /// \brief Writes the observation of the current state (observation_size entries) to `out`.
  /// \param out room for observation_size doubles (layout: see the class)
  void observe(double* out) const;

  /// \brief The observation after the last reset() or step().
  /// \return observation_size entries (layout and units: see the class)
  const std::array<double, observation_size>& observation() const { return obs_; }
  /// \brief The reward of the last step. \return the reward (0 after reset())
  double reward() const { return reward_; }
  /// \brief Whether the episode terminated.
  /// \return true when the ROV left the path by more than max_path_error or a step failed
  bool terminated() const { return terminated_; }
  /// \brief Whether the episode was truncated.
  /// \return true when the scenario's duration has been simulated (and not terminated)
  bool truncated() const { return !terminated_ && loop_->done(); }
  /// \brief Why the episode terminated on a failed step.
  /// \return the failure's message (empty otherwise)
  const std::string& error() const { return error_; }
  /// \brief The world (state, metrics, summary; its ROV is flown by the action).
  /// \return the closed loop of the current episode
  const ClosedLoop& loop() const { return *loop_; }
  /// \brief The ROV's command of the current action (thrusts, commands, wrench, saturation).
  /// \return the command (body axes; [N], [N m])
  const control::AuvCommand& auv_command() const { return auv_; }
  /// \brief The energy the ROV's battery has delivered since reset().
  /// \return the energy [J] (0 without propulsion)
  double energy_drawn() const;

 private:
  Scenario scenario_;
  PairEnvOptions options_;
  long substeps_ = 1;
  double max_thrust_ = control::AuvControllerSettings{}.max_thrust;  // the controller's cap [N]
  std::unique_ptr<ClosedLoop> loop_;
  control::AuvCommand auv_;
  control::AsvCommand asv_;
  Eigen::Vector2d asv_thrust_ = Eigen::Vector2d::Zero();
  Eigen::VectorXd force_, scratch_;
  std::array<double, observation_size> obs_{};
  double reward_ = 0.0;
  bool terminated_ = false, controllers_ = false;
  std::string error_;
};

}  // namespace sim
}  // namespace kelp
