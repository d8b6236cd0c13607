// kelp::sim::Batch: every world's numbers are the same bit for bit whatever the thread count,
// world i is the scenario with seed + i (the same as a TetheredPairEnv or a ClosedLoop of that
// seed), actions reach their own world, bad actions are refused before anything is stepped, the
// arrays stay where they are, and a step allocates nothing.
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "../support/heap_counter.hpp"
#include "kelp/sim/batch.hpp"

namespace ks = kelp::sim;

namespace {

ks::Scenario short_batch_run() {
  ks::Scenario sc;
  sc.duration = 2.0;
  return sc;
}

// Every array of a batch, flattened.
std::vector<double> snapshot(const ks::Batch& b) {
  std::vector<double> v;
  for (const ks::Batch::Rows* m : {&b.auv_position(), &b.auv_attitude(), &b.auv_velocity(),
                                   &b.asv_position(), &b.asv_attitude(), &b.asv_velocity(),
                                   &b.tension(), &b.observation(), &b.reward(), &b.time()})
    v.insert(v.end(), m->data(), m->data() + m->size());
  for (Eigen::Index i = 0; i < b.ended().size(); ++i) v.push_back(b.ended().data()[i]);
  return v;
}

// Actions that differ per world and per call.
std::vector<double> actions(std::size_t n, int call) {
  std::vector<double> a(n * 6);
  for (std::size_t k = 0; k < a.size(); ++k) a[k] = std::sin(0.7 * k + 1.3 * call);
  return a;
}

std::vector<double> run(unsigned threads) {
  ks::BatchOptions o;
  o.threads = threads;
  ks::Batch b(short_batch_run(), 5, 11, o);
  CHECK(b.threads() == threads);
  std::vector<double> out = snapshot(b);
  b.step(3);  // the controllers
  for (double x : snapshot(b)) out.push_back(x);
  for (int call = 0; call < 3; ++call) {
    const std::vector<double> a = actions(5, call);
    b.step(2, a.data());
    for (double x : snapshot(b)) out.push_back(x);
  }
  return out;
}

}  // namespace

TEST_CASE("a batch's numbers do not depend on the thread count", "[sim][batch]") {
  const std::vector<double> one = run(1);
  CHECK(run(2) == one);  // bit for bit
  CHECK(run(3) == one);
  CHECK(run(5) == one);
}

TEST_CASE("world i of a batch is the scenario with seed + i", "[sim][batch]") {
  ks::BatchOptions o;
  o.threads = 2;
  ks::Batch b(short_batch_run(), 3, 20, o);
  CHECK(b.size() == 3);
  CHECK(b.action_size() == 6);
  // The controllers fly: world i is the ClosedLoop of seed 20 + i.
  b.step(5);
  for (std::size_t i = 0; i < 3; ++i) {
    ks::Scenario sc = short_batch_run();
    sc.seed = 20 + i;
    ks::ClosedLoop loop(sc);
    loop.run_for(0.5);
    const auto r = static_cast<Eigen::Index>(i);
    CHECK(b.auv_position().row(r) == loop.state().auv.position.transpose());
    CHECK(b.asv_velocity().row(r) == loop.state().asv.nu.transpose());
    CHECK(b.tension()(r, 1) == loop.last_report().force_on_auv.norm());
    CHECK(b.time()(r, 0) == loop.state().time);
    CHECK(b.auv_attitude()(r, 0) == loop.state().auv.attitude.w());
  }
  // The seeds give different seas, hence different worlds.
  CHECK(b.auv_position().row(0) != b.auv_position().row(1));
  // Actions: world i is a TetheredPairEnv of seed 20 + i flown by row i.
  const std::vector<double> a = actions(3, 0);
  b.step(4, a.data());
  for (std::size_t i = 0; i < 3; ++i) {
    ks::Scenario sc = short_batch_run();
    sc.seed = 20 + i;
    ks::TetheredPairEnv env(sc);
    env.fly_by_controllers(true);
    for (int k = 0; k < 5; ++k) env.advance();
    env.fly_by_controllers(false);
    double reward = 0;
    for (int k = 0; k < 4; ++k) reward += env.step(a.data() + 6 * i);
    const auto r = static_cast<Eigen::Index>(i);
    CHECK(b.reward()(r, 0) == reward);
    for (int k = 0; k < ks::TetheredPairEnv::observation_size; ++k)
      CHECK(b.observation()(r, k) == env.observation()[static_cast<std::size_t>(k)]);
  }
}

TEST_CASE("a batch ends, resets, and refuses bad actions", "[sim][batch]") {
  ks::BatchOptions o;
  o.threads = 2;
  ks::Batch b(short_batch_run(), 2, 1, o);
  const double* address = b.auv_position().data();
  std::vector<double> a = actions(2, 0);
  a[7] = std::nan("");
  try {
    b.step(1, a.data());
    FAIL("a NaN action was accepted");
  } catch (const kelp::invalid_argument& e) {
    CHECK(std::string(e.what()).find("actions[1, 1]") != std::string::npos);
  }
  CHECK(b.time()(0, 0) == 0.0);  // nothing stepped
  CHECK_THROWS_AS(b.step(-1), kelp::invalid_argument);
  b.step(25);  // past the 2 s
  CHECK(b.ended()(0, 1) == 1);
  CHECK(b.ended()(1, 1) == 1);
  CHECK(b.time()(0, 0) == Approx(2.0));
  b.reset(1);
  CHECK(b.ended()(0, 1) == 0);
  CHECK(b.time()(0, 0) == 0.0);
  CHECK(b.auv_position().data() == address);  // the arrays stay put
  CHECK_THROWS_AS(ks::Batch(short_batch_run(), 0, 1), kelp::invalid_argument);
}

TEST_CASE("a batch step allocates nothing", "[sim][batch][malloc]") {
  ks::BatchOptions o;
  o.threads = 1;  // Eigen's malloc check is one flag for the process
  ks::Batch b(short_batch_run(), 2, 1, o);
  const std::vector<double> a = actions(2, 0);
  b.step(1, a.data());
  const long before = kelp_test::heap_allocations();  // the whole program's, the library's too
  Eigen::internal::set_is_malloc_allowed(false);
  b.step(2, a.data());
  b.step(1);
  Eigen::internal::set_is_malloc_allowed(true);
  CHECK(kelp_test::heap_allocations() == before);
  CHECK(b.time()(0, 0) == Approx(0.4));
}
