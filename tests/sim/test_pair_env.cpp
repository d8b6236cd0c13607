// kelp::sim's gym-style environment core (TetheredPairEnv) and the shared thrust allocation
// (control::allocate_wrench): the action reaches the ROV through the controller's allocation, the
// episode is the same bit for bit for a seed and differs between seeds, the reward is the
// documented one, the episode ends as documented, bad input is refused, and a step allocates
// nothing.
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "../support/heap_counter.hpp"
#include "kelp/sim/pair_env.hpp"
#include "kelp/vehicle/presets.hpp"

namespace ks = kelp::sim;

namespace {

// The default world (moderate sea), 3 s long.
ks::Scenario short_run() {
  ks::Scenario sc;
  sc.duration = 3.0;
  return sc;
}

std::vector<double> run(ks::TetheredPairEnv& env, std::uint64_t seed, int steps,
                        const double* action) {
  env.reset(seed);
  std::vector<double> out;
  for (int k = 0; k < steps; ++k) {
    out.push_back(env.step(action));
    for (double o : env.observation()) out.push_back(o);
  }
  return out;
}

}  // namespace

TEST_CASE("allocate_wrench delivers a reachable wrench exactly and scales an unreachable one",
          "[sim][env]") {
  const auto rov = kelp::vehicle::bluerov2_heavy<double>();
  const kelp::vehicle::ThrusterAllocationd b(rov.thruster_positions, rov.thruster_directions);
  const kelp::vehicle::ThrusterChain<double> chain(
      b, kelp::vehicle::t200_model, kelp::vehicle::PwmMapping<double>(), rov.thruster_facing, 16.0);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(8), scratch = Eigen::VectorXd::Zero(8);
  kelp::Vector6<double> tau;
  tau << 20, -10, 15, 0, 0, 3;
  for (bool split : {false, true}) {
    const auto s = kelp::control::allocate_wrench(chain, tau, 50.0, split, f, scratch);
    CHECK_FALSE(s.saturated());
    CHECK((b.matrix() * f - tau).norm() < 1e-9);
  }
  // 400 N of heave is far beyond four vertical T200s: scaled down and flagged; with split
  // saturation the vertical group alone is scaled first, so more of the surge survives than
  // with the whole scaled uniformly.
  tau << 20, 0, 400, 0, 0, 0;
  auto s = kelp::control::allocate_wrench(chain, tau, 50.0, true, f, scratch);
  CHECK(s.saturated());
  CHECK(s.vertical < 1.0);
  CHECK(s.horizontal == 1.0);
  const kelp::Vector6<double> split = b.matrix() * f;
  CHECK(split(2) < 400.0);
  CHECK(f.cwiseAbs().maxCoeff() <= 50.0 + 1e-9);
  s = kelp::control::allocate_wrench(chain, tau, 50.0, false, f, scratch);
  CHECK(s.total < 1.0);
  const kelp::Vector6<double> uniform = b.matrix() * f;
  CHECK(uniform(0) < 20.0);  // uniform scaling shrinks the surge too
  CHECK(uniform(0) / 20.0 == Approx(uniform(2) / 400.0));
  CHECK(split(0) > 1.5 * uniform(0));
  Eigen::VectorXd small = Eigen::VectorXd::Zero(3);
  CHECK_THROWS_AS(kelp::control::allocate_wrench(chain, tau, 50.0, true, f, small),
                  kelp::invalid_argument);
}

TEST_CASE("the environment's episode is the same for a seed and differs between seeds",
          "[sim][env]") {
  ks::TetheredPairEnv env(short_run());
  CHECK(env.action_size() == 6);
  CHECK(env.substeps() == 10);
  const double action[6] = {0.3, -0.2, 0.1, 0.0, 0.0, 0.05};
  const std::vector<double> a = run(env, 7, 12, action);
  const std::vector<double> b = run(env, 7, 12, action);
  const std::vector<double> c = run(env, 8, 12, action);
  CHECK(a == b);  // bit for bit
  CHECK(a != c);
  for (double x : a) CHECK(std::isfinite(x));
  // A second environment: the same episode.
  ks::TetheredPairEnv other(short_run());
  CHECK(run(other, 7, 12, action) == a);
}

TEST_CASE("the action flies the ROV through the controller's allocation", "[sim][env]") {
  ks::Scenario sc = short_run();
  sc.sea = ks::Sea::calm;
  ks::TetheredPairEnv ahead(sc), astern(sc);
  const double fwd[6] = {1, 0, 0, 0, 0, 0}, back[6] = {-1, 0, 0, 0, 0, 0};
  for (int k = 0; k < 20; ++k) {
    ahead.step(fwd);
    astern.step(back);
  }
  // 2 s of full surge either way: body-x speeds of opposite signs, positions apart.
  CHECK(ahead.loop().state().auv.nu(0) > 0.2);
  CHECK(astern.loop().state().auv.nu(0) < -0.2);
  const auto& cmd = ahead.auv_command();
  CHECK(cmd.wrench(0) > 70.0);  // 80 N asked; the allocation delivers it (within the T200s)
  CHECK(std::abs(cmd.wrench(1)) < 1e-6);
  // The ROV's thrusters follow the commands (the propulsion's lagged thrust).
  const auto& thrust = ahead.loop().state().auv_propulsion.thrust;
  CHECK((thrust.head(8) - cmd.thrust).norm() < 1.0);
  // Clipping: an action of 5 is an action of 1.
  ks::TetheredPairEnv clipped(sc);
  const double five[6] = {5, 0, 0, 0, 0, 0};
  clipped.step(five);
  ks::TetheredPairEnv one(sc);
  one.step(fwd);
  CHECK(clipped.observation() == one.observation());
}

TEST_CASE("the reward is minus the path error and the ROV's battery energy, weighted",
          "[sim][env]") {
  ks::PairEnvOptions o;
  o.path_weight = 2.0;
  o.energy_weight = 0.05;
  ks::TetheredPairEnv env(short_run(), o);
  const double action[6] = {0.5, 0, 0.5, 0, 0, 0};
  for (int k = 0; k < 5; ++k) {
    const double e0 = env.energy_drawn();
    const double r = env.step(action);
    const double de = env.energy_drawn() - e0;
    CHECK(de > 0.0);  // the thrusters draw from the battery
    CHECK(env.observation()[19] == env.loop().sample().auv_error);
    CHECK(r == Approx(-2.0 * env.observation()[19] - 0.05 * de).epsilon(1e-12));
  }
}

TEST_CASE("the episode is truncated at the scenario's end and terminated off the path",
          "[sim][env]") {
  ks::Scenario sc = short_run();
  sc.duration = 1.0;
  ks::TetheredPairEnv env(sc);
  const double zero[6] = {0, 0, 0, 0, 0, 0};
  for (int k = 0; k < 9; ++k) {
    env.step(zero);
    CHECK_FALSE(env.truncated());
  }
  env.step(zero);
  CHECK(env.truncated());
  CHECK_FALSE(env.terminated());
  const double t = env.loop().time();
  CHECK(env.step(zero) == 0.0);  // nothing happens after the end
  CHECK(env.loop().time() == t);
  // A tight corridor: the ROV, driven sideways at full thrust, leaves it.
  ks::PairEnvOptions o;
  o.max_path_error = 0.3;
  ks::TetheredPairEnv tight(short_run(), o);
  const double sideways[6] = {0, 1, 0, 0, 0, 0};
  int k = 0;
  while (!tight.terminated() && k < 30) tight.step(sideways), ++k;
  CHECK(tight.terminated());
  CHECK_FALSE(tight.truncated());
  CHECK(tight.observation()[19] > 0.3);
  CHECK(tight.error().empty());
  // Reset: a new episode.
  tight.reset(3);
  CHECK_FALSE(tight.terminated());
  CHECK(tight.loop().time() == 0.0);
}

TEST_CASE("the environment refuses bad options and actions", "[sim][env]") {
  ks::PairEnvOptions o;
  o.control_period = 0.015;
  CHECK_THROWS_AS(ks::TetheredPairEnv(short_run(), o), kelp::invalid_argument);
  o.control_period = 0.0;
  CHECK_THROWS_AS(ks::TetheredPairEnv(short_run(), o), kelp::invalid_argument);
  o = {};
  o.max_path_error = -1;
  CHECK_THROWS_AS(ks::TetheredPairEnv(short_run(), o), kelp::invalid_argument);
  ks::TetheredPairEnv env(short_run());
  const double bad[6] = {0, 0, std::nan(""), 0, 0, 0};
  try {
    env.step(bad);
    FAIL("a NaN action was accepted");
  } catch (const kelp::invalid_argument& e) {
    CHECK(std::string(e.what()).find("action[2]") != std::string::npos);
  }
  CHECK(env.loop().steps_taken() == 0);  // nothing stepped
}

TEST_CASE("the boat action drives the boat's thrusters", "[sim][env]") {
  ks::Scenario sc = short_run();
  sc.sea = ks::Sea::calm;
  ks::PairEnvOptions o;
  o.asv_action = true;
  ks::TetheredPairEnv env(sc, o);
  CHECK(env.action_size() == 8);
  const double turn[8] = {0, 0, 0, 0, 0, 0, 1, -1};  // port ahead, starboard astern
  for (int k = 0; k < 10; ++k) env.step(turn);
  CHECK(env.loop().state().asv.nu(5) > 0.05);  // turning to starboard (positive yaw rate)
  // The controllers fly again on request: the boat stops being driven by the action.
  env.fly_by_controllers(true);
  CHECK(env.loop().asv_override() == nullptr);
  CHECK(env.loop().auv_override() == nullptr);
}

TEST_CASE("an environment step allocates nothing", "[sim][env][malloc]") {
  ks::TetheredPairEnv env(short_run());
  const double action[6] = {0.2, 0.1, 0.3, 0, 0, 0.1};
  env.step(action);
  const long before = kelp_test::heap_allocations();  // the whole program's, the library's too
  Eigen::internal::set_is_malloc_allowed(false);
  for (int k = 0; k < 5; ++k) env.step(action);
  Eigen::internal::set_is_malloc_allowed(true);
  CHECK(kelp_test::heap_allocations() == before);
  CHECK(env.loop().steps_taken() == 60);
}
