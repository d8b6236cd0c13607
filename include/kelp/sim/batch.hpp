/// \file
/// \brief Many independent worlds of one scenario stepped together on a small thread pool: Monte
/// Carlo over seeds, and a vectorised environment for learning (Python's `kelp.Batch`).
///
/// World i is a TetheredPairEnv of the scenario with sea seed `seed + i`. The worlds are split
/// into one contiguous block per thread, and each world is only ever stepped by one thread at a
/// time with no state shared with the others, so the numbers of every world are the same bit for
/// bit whatever the thread count (the thread count changes only who steps it). Uses std::thread:
/// a program using it links `Threads::Threads`. Part of the optional `kelp::sim` component.
#pragma once

#include <Eigen/Core>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "kelp/core/error.hpp"
#include "kelp/sim/export.hpp"
#include "kelp/sim/pair_env.hpp"
#include "kelp/sim/scenario.hpp"

namespace kelp {
namespace sim {

/// \brief Options of a Batch.
struct BatchOptions {
  /// Worker threads (the calling thread is one of them); 0: std::thread::hardware_concurrency().
  /// At most one per world.
  unsigned threads = 0;
  /// The worlds' environment options: the control period (one Batch::step), the boat action,
  /// the reward's weights.
  PairEnvOptions env;
};

/// \brief n independent worlds of a scenario (seeds seed, seed + 1, …, seed + n − 1), stepped
/// together.
///
/// step(n_steps, actions) advances every world by n_steps control periods
/// (BatchOptions::env.control_period, 0.1 s by default): with `actions` (n × action_size, row
/// major; the same action applied at every step of the call, i.e. n_steps calls of
/// TetheredPairEnv::step) the actions fly the ROVs (and boats) as in TetheredPairEnv; without,
/// the scenario's controllers fly them, as in a run of kelp-tethered-pair. A world whose episode
/// has ended (terminated: a failed step, or the ROV beyond PairEnvOptions::max_path_error;
/// truncated: the scenario's duration reached) stays as it was until reset(); terminated() and
/// error() say which and why.
///
/// After every step() (and reset()) the per-world quantities below are in row-major arrays
/// owned by the batch, row i for world i, at fixed addresses for the batch's life (Python exposes
/// them as numpy views without copying). No allocation in step().
class KELP_SIM_API Batch {
 public:
  /// Row-major array of per-world rows.
  using Rows = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

  /// \brief Builds n worlds of `scenario` with seeds seed … seed + n − 1 (in parallel) and starts
  /// the threads.
  /// \throws kelp::invalid_argument for n = 0, bad environment options (TetheredPairEnv), and what
  /// building a world throws (scenario_error, kelp::invalid_argument, kelp::numerical_error).
  /// \param scenario the scenario of every world (copied) \param n the number of worlds, ≥ 1
  /// \param seed the sea seed of world 0 (world i: seed + i)
  /// \param options the thread count and the worlds' environment options
  Batch(const Scenario& scenario, std::size_t n, std::uint64_t seed,
        const BatchOptions& options = {});

  Batch(const Batch&) = delete;
  Batch& operator=(const Batch&) = delete;
  ~Batch();

  /// \brief Worlds n. \return the number of worlds
  std::size_t size() const { return worlds_.size(); }
  /// \brief Threads stepping them (the caller's included). \return 1 … size()
  unsigned threads() const { return threads_; }
  /// \brief Seed of world 0. \return the seed of the last construction or reset()
  std::uint64_t seed() const { return seed_; }
  /// \brief Entries of one world's action. \return TetheredPairEnv::action_size()
  int action_size() const { return worlds_.front()->action_size(); }
  /// \brief World i (its loop, state, summary). Not to be used while step() runs.
  /// \param i the world's index, < size() \return the world
  /// \throws std::out_of_range for i ≥ size()
  const TetheredPairEnv& world(std::size_t i) const { return *worlds_.at(i); }

  /// \brief Advances every world by `n_steps` control periods (see the class); `actions`:
  /// null (the controllers fly) or size() × action_size() doubles, row major, each clipped to
  /// [−1, 1]. reward() then holds each world's reward summed over the call's steps.
  /// \param n_steps control periods to advance, ≥ 0 \param actions the actions, or nullptr
  /// \throws kelp::invalid_argument for a negative n_steps or a non-finite action (nothing is
  /// stepped).
  void step(long n_steps = 1, const double* actions = nullptr);

  /// \brief Starts new episodes: world i rebuilt with seed `seed + i`. Allocates.
  /// \param seed the new sea seed of world 0
  /// \throws as the constructor (the batch is then unusable until a reset succeeds).
  void reset(std::uint64_t seed);

  /// \name Per-world arrays (row i: world i), updated by step() and reset().
  /// Each returns the batch's array, at a fixed address for the batch's life.
  ///@{
  /// \brief The ROV's position. \return NED [m] (n × 3)
  const Rows& auv_position() const { return auv_position_; }
  /// \brief The ROV's attitude. \return unit quaternions body → NED (w, x, y, z) (n × 4)
  const Rows& auv_attitude() const { return auv_attitude_; }
  /// \brief The ROV's body velocity ν. \return u, v, w [m/s], p, q, r [rad/s], body (n × 6)
  const Rows& auv_velocity() const { return auv_velocity_; }
  /// \brief The boat's position. \return NED [m] (n × 3)
  const Rows& asv_position() const { return asv_position_; }
  /// \brief The boat's attitude. \return unit quaternions body → NED (w, x, y, z) (n × 4)
  const Rows& asv_attitude() const { return asv_attitude_; }
  /// \brief The boat's body velocity ν. \return u, v, w [m/s], p, q, r [rad/s], body (n × 6)
  const Rows& asv_velocity() const { return asv_velocity_; }
  /// \brief The tether's end forces' magnitudes.
  /// \return [N]: column 0 on the boat, 1 on the ROV (n × 2)
  const Rows& tension() const { return tension_; }
  /// \brief The environments' observations (TetheredPairEnv::observation()).
  /// \return n × TetheredPairEnv::observation_size
  const Rows& observation() const { return observation_; }
  /// \brief The reward summed over the last step()'s steps. \return n × 1 (0 after reset())
  const Rows& reward() const { return reward_; }
  /// \brief Simulation time. \return [s] (n × 1; a terminated world's stops)
  const Rows& time() const { return time_; }
  /// \brief Which episodes have ended.
  /// \return 1 where the episode terminated (column 0) or was truncated (column 1), else 0
  /// (n × 2)
  const Eigen::Matrix<std::uint8_t, Eigen::Dynamic, 2, Eigen::RowMajor>& ended() const {
    return ended_;
  }
  ///@}
  /// \brief Why world i terminated on a failed step.
  /// \param i the world's index, < size() \return the error's message (empty otherwise)
  /// \throws std::out_of_range for i ≥ size()
  const std::string& error(std::size_t i) const { return worlds_.at(i)->error(); }

 private:
  enum class Job { none, build, step };

  // Runs `job` on every thread's block of worlds (the caller does block 0) and waits; rethrows
  // the first exception of the lowest block.
  void run(Job job);

  void work(unsigned w);

  // Block w of the fixed partition: worlds [w n / T, (w + 1) n / T).
  void do_block(unsigned w);

  // Copies world i's state into row i of the arrays.
  void publish(std::size_t i);

  void stop();

  Scenario scenario_;
  BatchOptions options_;
  std::uint64_t seed_;
  unsigned threads_ = 1;
  std::vector<std::unique_ptr<TetheredPairEnv>> worlds_;
  Rows auv_position_, asv_position_, auv_attitude_, asv_attitude_, auv_velocity_, asv_velocity_;
  Rows tension_, observation_, reward_, time_;
  Eigen::Matrix<std::uint8_t, Eigen::Dynamic, 2, Eigen::RowMajor> ended_;
  // The pool: workers 1 … threads − 1 wait for a new generation, run their block of job_, and
  // count down pending_.
  std::vector<std::thread> pool_;
  std::mutex mutex_;
  std::condition_variable start_, done_;
  std::uint64_t generation_ = 0;
  unsigned pending_ = 0;
  bool stop_ = false;
  Job job_ = Job::none;
  long steps_ = 0;
  const double* actions_ = nullptr;
  std::vector<std::exception_ptr> errors_;
};

}  // namespace sim
}  // namespace kelp
