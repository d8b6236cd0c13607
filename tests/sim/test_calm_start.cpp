// A calm start (issue 25): a ROV resting in the default world (no thrust) reads a specific force
// within 3 m/s² of g over its first second, as its accelerometer would: the body acceleration
// from the system state's `auv_nu_dot` (v̇ + ω × v) minus gravity, in body axes (the formula
// kelp-sitl's bridge sends to ArduSub). The sea is ramped in over the scenario's `start.ramp`.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

#include "kelp/sim.hpp"

namespace ks = kelp::sim;
namespace sy = kelp::system;

namespace {

// Largest |‖f‖ − g| of the AUV's specific force over `seconds` with no thrust on either vehicle.
double worst_specific_force_error(const ks::Scenario& sc, double seconds, double dt) {
  const ks::WorldSetup w = ks::world_setup(sc, "test");
  const sy::SystemModeld model(w.parameters, w.environment);
  sy::SystemWorkspaced ws(model);
  sy::SystemStated s = ks::start_state(model, ws, w, sc);
  const double g = model.environment().gravity();
  const sy::SystemInputsd in;
  double worst = 0;
  const long n = std::lround(seconds / dt);
  for (long k = 0; k < n; ++k) {
    sy::step(model, ws, s, in, dt);
    const kelp::Vector3<double> v = s.auv.nu.head<3>(), om = s.auv.nu.tail<3>();
    const kelp::Vector3<double> f = s.auv_nu_dot.head<3>() + om.cross(v) -
                                    s.auv.attitude.conjugate() * kelp::Vector3<double>(0, 0, g);
    worst = std::max(worst, std::abs(f.norm() - g));
  }
  return worst;
}

}  // namespace

TEST_CASE("calm start: a resting ROV reads about g over its first second", "[sim][start]") {
  ks::Scenario sc;  // the embedded default of kelp-tethered-pair: moderate sea, 10 m tether
  SECTION("kelp-tethered-pair's default world") {
    const double e = worst_specific_force_error(sc, 1.0, ks::ClosedLoop::dt);
    INFO("worst |f - g| = " << e << " m/s^2");
    CHECK(e < 3.0);
  }
  SECTION("without the ramp and without starting with the water the transient is back") {
    sc.start_ramp = 0;
    sc.start_with_water = false;
    sc.auv_start = kelp::Vector3<double>(-4.0, 0.0, 0.3);  // kelp-sitl's start, at the surface
    const double e = worst_specific_force_error(sc, 1.0, ks::ClosedLoop::dt);
    INFO("worst |f - g| = " << e << " m/s^2");
    CHECK(e > 3.0);
  }
}
