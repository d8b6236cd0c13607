// Many worlds of one scenario on a thread pool (kelp/sim/batch.hpp).
#include "kelp/sim/batch.hpp"

#include <algorithm>

namespace kelp {
namespace sim {

Batch::Batch(const Scenario& scenario, std::size_t n, std::uint64_t seed,
             const BatchOptions& options)
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

void Batch::step(long n_steps, const double* actions) {
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

void Batch::reset(std::uint64_t seed) {
  seed_ = seed;
  run(Job::build);
}

void Batch::run(Job job) {
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

void Batch::work(unsigned w) {
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

void Batch::do_block(unsigned w) {
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

void Batch::publish(std::size_t i) {
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

void Batch::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  start_.notify_all();
  for (auto& t : pool_)
    if (t.joinable()) t.join();
  pool_.clear();
}

Batch::~Batch() { stop(); }

}  // namespace sim
}  // namespace kelp
