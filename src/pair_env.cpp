// The tethered pair as a learning environment (kelp/sim/pair_env.hpp).
#include "kelp/sim/pair_env.hpp"

#include <algorithm>
#include <cmath>

#include "kelp/core/rotation.hpp"

namespace kelp {
namespace sim {

TetheredPairEnv::TetheredPairEnv(const Scenario& scenario, const PairEnvOptions& options)
    : scenario_(scenario), options_(options) {
  check_positive(options.control_period, "control_period");
  const double k = options.control_period / ClosedLoop::dt;
  KELP_CHECK(std::abs(k - std::round(k)) < 1e-9 && std::round(k) >= 1,
             "control_period must be a positive multiple of 0.01 s, got " +
                 std::to_string(options.control_period));
  substeps_ = std::lround(k);
  check_positive(options.max_path_error, "max_path_error");
  check_non_negative(options.path_weight, "path_weight");
  check_non_negative(options.energy_weight, "energy_weight");
  const Eigen::Index n = 8;  // the BlueROV2 Heavy's thrusters
  force_ = Eigen::VectorXd::Zero(n);
  scratch_ = Eigen::VectorXd::Zero(n);
  auv_.thrust = Eigen::VectorXd::Zero(n);
  auv_.command = Eigen::VectorXd::Zero(n);
  reset(scenario.seed);
}

void TetheredPairEnv::reset(std::uint64_t seed) {
  // The new world is built aside: if that throws, the environment is as it was.
  Scenario sc = scenario_;
  sc.seed = seed;
  auto loop = std::make_unique<ClosedLoop>(sc);
  scenario_.seed = seed;
  loop_ = std::move(loop);
  fly_by_controllers(controllers_);
  error_.clear();
  terminated_ = false;
  reward_ = 0.0;
  const std::array<double, 8> zero{};
  apply(zero.data());
  observe(obs_.data());
}

void TetheredPairEnv::apply(const double* action) {
  for (int i = 0; i < action_size(); ++i)
    KELP_CHECK(std::isfinite(action[i]), "action[" + std::to_string(i) + "] is not finite");
  const auto clip = [](double a) { return a < -1.0 ? -1.0 : (a > 1.0 ? 1.0 : a); };
  Vector6<double> tau;
  for (int i = 0; i < 6; ++i) tau(i) = clip(action[i]) * action_scale[static_cast<size_t>(i)];
  const auto& chain = loop_->auv_controller().thruster_chain();
  const control::AllocationScales s =
      control::allocate_wrench(chain, tau, max_thrust_, true, force_, scratch_);
  chain.commands_for(force_, auv_.command, auv_.thrust);
  auv_.wrench = chain.wrench(auv_.thrust);
  auv_.saturated = s.saturated();
  if (options_.asv_action) {
    const auto& boat = loop_->asv_controller().thruster_chain();
    const double c = scenario_.asv_thrust_clip;
    const Eigen::Vector2d wanted(clip(action[6]) * c, clip(action[7]) * c);
    asv_.left = wanted(0);
    asv_.right = wanted(1);
    boat.commands_for(wanted, asv_.command, asv_thrust_);
    asv_.wrench = boat.wrench(asv_thrust_);
  }
}

void TetheredPairEnv::fly_by_controllers(bool yes) {
  controllers_ = yes;
  loop_->set_auv_override(yes ? nullptr : &auv_);
  loop_->set_asv_override(yes || !options_.asv_action ? nullptr : &asv_);
}

double TetheredPairEnv::step(const double* action) {
  if (terminated_ || truncated()) return 0.0;
  apply(action);
  return advance();
}

double TetheredPairEnv::advance() {
  if (terminated_ || truncated()) return 0.0;
  const double e0 = energy_drawn();
  try {
    for (long i = 0; i < substeps_ && !loop_->done(); ++i) loop_->step();
  } catch (const kelp::error& e) {
    error_ = e.what();
    terminated_ = true;
  }
  observe(obs_.data());
  const double path_error = obs_[19];
  if (!(path_error <= options_.max_path_error)) terminated_ = true;
  reward_ = -options_.path_weight * path_error - options_.energy_weight * (energy_drawn() - e0);
  return reward_;
}

void TetheredPairEnv::observe(double* out) const {
  const auto& s = loop_->state();
  const Vector3<double> rel = s.auv.position - loop_->auv_controller().target();
  const Vector3<double> rpy = euler_from_quaternion(s.auv.attitude);
  const Vector3<double> boat = s.asv.position - s.auv.position;
  const Vector3<double>& f = loop_->last_report().force_on_auv;
  for (int i = 0; i < 3; ++i) {
    out[i] = rel(i);
    out[3 + i] = rpy(i);
    out[12 + i] = boat(i);
    out[16 + i] = f(i);
  }
  for (int i = 0; i < 6; ++i) out[6 + i] = s.auv.nu(i);
  out[15] = euler_from_quaternion(s.asv.attitude).z();
  out[19] = loop_->sample().auv_error;
}

double TetheredPairEnv::energy_drawn() const {
  return loop_->model().auv_propulsion() ? loop_->state().auv_propulsion.battery.energy_drawn : 0.0;
}

}  // namespace sim
}  // namespace kelp
