// The sea of a running system can change (SystemModel::set_environment): a tide turning the
// current reverses the drift of the unpowered pair; a new environment is checked against the
// vehicles' water as at construction, and a refused one leaves the old in place.
#include <catch2/catch.hpp>
#include <cmath>

#include "kelp/environment/environment.hpp"
#include "kelp/system/presets.hpp"
#include "kelp/system/system.hpp"

namespace ke = kelp::environment;
namespace ks = kelp::system;
using V3 = kelp::Vector3<double>;

TEST_CASE("a running system's current can turn: the ROV's drift reverses at t = 30 s",
          "[system][environment]") {
  ks::presets::PaperWorld<double> w(10.0, ks::presets::Sea::calm);
  const double speed = 0.5;  // [m/s], towards north, then towards south
  ke::Environmentd env = w.model.environment();
  env.set_current(V3(speed, 0, 0));
  w.model.set_environment(env);
  CHECK(w.model.environment().current().velocity(V3(0, 0, 5), 0.0).x() == Approx(speed));
  const ks::SystemInputs<double> none;
  const double dt = 0.01;
  const auto run = [&](double seconds) {
    for (int i = 0; i < static_cast<int>(std::lround(seconds / dt)); ++i)
      ks::step(w.model, w.workspace, w.state, none, dt);
  };
  const double x0 = w.state.auv.position.x();
  run(30.0);
  const double x30 = w.state.auv.position.x();
  const double u30 = (w.state.auv.attitude * w.state.auv.nu.head<3>()).x();  // NED velocity
  INFO("after 30 s with the current north: drift " << x30 - x0 << " m, velocity " << u30);
  // Pushed north: the unpowered pair, both vehicles in the same uniform current, drifts with the
  // water at its speed once the transient (tens of seconds of its damping) is over.
  CHECK(x30 - x0 > 0.5 * speed * 30.0);
  CHECK(u30 > 0.9 * speed);

  // The tide turns: the same sea with the current reversed.
  env.set_current(V3(-speed, 0, 0));
  w.model.set_environment(env);
  run(30.0);
  const double u60 = (w.state.auv.attitude * w.state.auv.nu.head<3>()).x();
  INFO("30 s after the current turned: velocity " << u60 << " m/s, position "
                                                  << w.state.auv.position.x());
  CHECK(u60 < -0.9 * speed);
  CHECK(w.state.auv.position.x() < x30);
}

TEST_CASE("set_environment checks the water against the vehicles and keeps the old sea on refusal",
          "[system][environment]") {
  ks::presets::PaperWorld<double> w(10.0, ks::presets::Sea::calm);
  ke::Environmentd env = w.model.environment();
  env.set_current(V3(0.3, 0.1, 0));
  w.model.set_environment(env);
  ke::Environmentd fresh = env;
  fresh.set_water_density(1000.0);  // fresh water: the vehicles were built for seawater
  fresh.set_current(V3(-1, 0, 0));
  CHECK_THROWS_AS(w.model.set_environment(fresh), kelp::invalid_argument);
  CHECK_THROWS_WITH(w.model.set_environment(fresh), Catch::Contains("water"));
  // The old environment is still there, whole.
  CHECK(w.model.environment().water_density() == env.water_density());
  CHECK(w.model.environment().current().velocity(V3(0, 0, 1), 0.0).x() == Approx(0.3));
  // A different gravity is refused as well; a different air density or seabed is a new sea.
  ke::Environmentd mars = env;
  mars.set_gravity(3.71);
  CHECK_THROWS_AS(w.model.set_environment(mars), kelp::invalid_argument);
  ke::Environmentd thin_air = env;
  thin_air.set_air_density(1.0);
  CHECK_NOTHROW(w.model.set_environment(thin_air));
  CHECK(w.model.environment().air_density() == 1.0);
  // And the system still steps.
  const ks::SystemInputs<double> none;
  CHECK_NOTHROW(ks::step(w.model, w.workspace, w.state, none, 0.01));
}
