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
class Batch {
 public:
  /// Row-major array of per-world rows.
  using Rows = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

  /// \brief Builds n worlds of `scenario` with seeds seed … seed + n − 1 (in parallel) and starts
  /// the threads.
  /// \throws kelp::invalid_argument for n = 0, bad environment options (TetheredPairEnv), and what
  /// building a world throws (scenario_error, kelp::invalid_argument, kelp::numerical_error).
  Batch(const Scenario& scenario, std::size_t n, std::uint64_t seed,
        const BatchOptions& options = {})
      : scenario_(scenario), options_(options), seed_(seed) {
    KELP_CHECK(n >= 1, "Batch: n must be at least 1");
    unsigned t = options.threads ? options.threads : std::thread::hardware_concurrency();
    if (t == 0) t = 1;
    threads_ = static_cast<unsigned>(std::min<std::size_t>(t, n));
    worlds_.resize(n);
    errors_.resize(threads_);
    const auto rows = static_cast<Eigen::Index>(n);
    auv_position_ = Rows::Zero(rows, 3);
    asv_position_ = Rows::Zero(rows, 3);
    auv_attitude_ = Rows::Zero(rows, 4);
    asv_attitude_ = Rows::Zero(rows, 4);
    auv_velocity_ = Rows::Zero(rows, 6);
    asv_velocity_ = Rows::Zero(rows, 6);
    tension_ = Rows::Zero(rows, 2);
    observation_ = Rows::Zero(rows, TetheredPairEnv::observation_size);
    reward_ = Rows::Zero(rows, 1);
    time_ = Rows::Zero(rows, 1);
    ended_ = Eigen::Matrix<std::uint8_t, Eigen::Dynamic, 2, Eigen::RowMajor>::Zero(rows, 2);
    for (unsigned w = 1; w < threads_; ++w) pool_.emplace_back([this, w] { work(w); });
    try {
      run(Job::build);
    } catch (...) {
      stop();
      throw;
    }
  }

  Batch(const Batch&) = delete;
  Batch& operator=(const Batch&) = delete;
  ~Batch() { stop(); }

  /// \brief Worlds n.
  std::size_t size() const { return worlds_.size(); }
  /// \brief Threads stepping them (the caller's included).
  unsigned threads() const { return threads_; }
  /// \brief Seed of world 0.
  std::uint64_t seed() const { return seed_; }
  /// \brief Entries of one world's action (TetheredPairEnv::action_size()).
  int action_size() const { return worlds_.front()->action_size(); }
  /// \brief World i (its loop, state, summary). Not to be used while step() runs.
  const TetheredPairEnv& world(std::size_t i) const { return *worlds_.at(i); }

  /// \brief Advances every world by `n_steps` control periods (see the class); `actions`:
  /// null (the controllers fly) or size() × action_size() doubles, row major, each clipped to
  /// [−1, 1]. reward() then holds each world's reward summed over the call's steps.
  /// \throws kelp::invalid_argument for a negative n_steps or a non-finite action (nothing is
  /// stepped).
  void step(long n_steps = 1, const double* actions = nullptr) {
    KELP_CHECK(n_steps >= 0, "Batch::step: n_steps must be non-negative");
    if (actions) {
      const std::size_t m = size() * static_cast<std::size_t>(action_size());
      for (std::size_t k = 0; k < m; ++k)
        if (!std::isfinite(actions[k]))
          ::kelp::detail::throw_invalid_argument(
              "Batch::step: actions[" + std::to_string(k / action_size()) + ", " +
              std::to_string(k % action_size()) + "] is not finite");
    }
    steps_ = n_steps;
    actions_ = actions;
    run(Job::step);
  }

  /// \brief Starts new episodes: world i rebuilt with seed `seed + i`. Allocates.
  /// \throws as the constructor (the batch is then unusable until a reset succeeds).
  void reset(std::uint64_t seed) {
    seed_ = seed;
    run(Job::build);
  }

  /// \name Per-world arrays (row i: world i), updated by step() and reset().
  ///@{
  /// The ROV's position, NED [m] (n × 3).
  const Rows& auv_position() const { return auv_position_; }
  /// The ROV's attitude, unit quaternion body → NED (w, x, y, z) (n × 4).
  const Rows& auv_attitude() const { return auv_attitude_; }
  /// The ROV's body velocity ν (u, v, w [m/s], p, q, r [rad/s]) (n × 6).
  const Rows& auv_velocity() const { return auv_velocity_; }
  /// The boat's position, NED [m] (n × 3).
  const Rows& asv_position() const { return asv_position_; }
  /// The boat's attitude (w, x, y, z) (n × 4).
  const Rows& asv_attitude() const { return asv_attitude_; }
  /// The boat's body velocity (n × 6).
  const Rows& asv_velocity() const { return asv_velocity_; }
  /// The tether's end forces' magnitudes [N]: column 0 on the boat, 1 on the ROV (n × 2).
  const Rows& tension() const { return tension_; }
  /// The environments' observations (n × TetheredPairEnv::observation_size).
  const Rows& observation() const { return observation_; }
  /// The reward summed over the last step()'s steps (n × 1; 0 after reset()).
  const Rows& reward() const { return reward_; }
  /// Simulation time [s] (n × 1; a terminated world's stops).
  const Rows& time() const { return time_; }
  /// 1 where the episode terminated (column 0) or was truncated (column 1), else 0 (n × 2).
  const Eigen::Matrix<std::uint8_t, Eigen::Dynamic, 2, Eigen::RowMajor>& ended() const {
    return ended_;
  }
  ///@}
  /// \brief Why world i terminated on a failed step (empty otherwise).
  const std::string& error(std::size_t i) const { return worlds_.at(i)->error(); }

 private:
  enum class Job { none, build, step };

  // Runs `job` on every thread's block of worlds (the caller does block 0) and waits; rethrows
  // the first exception of the lowest block.
  void run(Job job) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      job_ = job;
      pending_ = threads_ - 1;
      ++generation_;
    }
    start_.notify_all();
    do_block(0);
    {
      std::unique_lock<std::mutex> lock(mutex_);
      done_.wait(lock, [this] { return pending_ == 0; });
      job_ = Job::none;
    }
    for (auto& e : errors_)
      if (e) {
        std::exception_ptr first = e;
        for (auto& x : errors_) x = nullptr;
        std::rethrow_exception(first);
      }
  }

  void work(unsigned w) {
    std::uint64_t seen = 0;
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(mutex_);
        start_.wait(lock, [&] { return stop_ || generation_ != seen; });
        if (stop_) return;
        seen = generation_;
      }
      do_block(w);
      {
        std::lock_guard<std::mutex> lock(mutex_);
        --pending_;
      }
      done_.notify_one();
    }
  }

  // Block w of the fixed partition: worlds [w n / T, (w + 1) n / T).
  void do_block(unsigned w) {
    const std::size_t n = size();
    const std::size_t begin = n * w / threads_, end = n * (w + 1) / threads_;
    try {
      for (std::size_t i = begin; i < end; ++i) {
        if (job_ == Job::build) {
          if (!worlds_[i]) {
            Scenario sc = scenario_;
            sc.seed = seed_ + i;
            worlds_[i] = std::make_unique<TetheredPairEnv>(sc, options_.env);
          } else {
            worlds_[i]->reset(seed_ + i);
          }
          reward_(static_cast<Eigen::Index>(i), 0) = 0.0;
        } else {
          TetheredPairEnv& env = *worlds_[i];
          env.fly_by_controllers(actions_ == nullptr);
          const double* action =
              actions_ ? actions_ + i * static_cast<std::size_t>(env.action_size()) : nullptr;
          double r = 0.0;
          for (long k = 0; k < steps_; ++k) r += action ? env.step(action) : env.advance();
          reward_(static_cast<Eigen::Index>(i), 0) = r;
        }
        publish(i);
      }
    } catch (...) {
      errors_[w] = std::current_exception();
    }
  }

  // Copies world i's state into row i of the arrays.
  void publish(std::size_t i) {
    const TetheredPairEnv& env = *worlds_[i];
    const auto& s = env.loop().state();
    const auto r = static_cast<Eigen::Index>(i);
    auv_position_.row(r) = s.auv.position.transpose();
    asv_position_.row(r) = s.asv.position.transpose();
    const auto quat = [](const Quaternion<double>& q, auto row) {
      row << q.w(), q.x(), q.y(), q.z();
    };
    quat(s.auv.attitude, auv_attitude_.row(r));
    quat(s.asv.attitude, asv_attitude_.row(r));
    auv_velocity_.row(r) = s.auv.nu.transpose();
    asv_velocity_.row(r) = s.asv.nu.transpose();
    const auto& rep = env.loop().last_report();
    tension_(r, 0) = rep.force_on_asv.norm();
    tension_(r, 1) = rep.force_on_auv.norm();
    for (int k = 0; k < TetheredPairEnv::observation_size; ++k)
      observation_(r, k) = env.observation()[static_cast<std::size_t>(k)];
    time_(r, 0) = s.time;
    ended_(r, 0) = env.terminated();
    ended_(r, 1) = env.truncated();
  }

  void stop() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    start_.notify_all();
    for (auto& t : pool_)
      if (t.joinable()) t.join();
    pool_.clear();
  }

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
