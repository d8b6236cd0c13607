// Tether presets: the Fathom-class ROV tether and the paper's bead chain as a lumped-mass line.
#include <catch2/catch.hpp>
#include <cmath>

#include "kelp/environment/environment.hpp"
#include "kelp/environment/sea_state.hpp"
#include "kelp/tether/initial_state.hpp"
#include "kelp/tether/integrators.hpp"
#include "kelp/tether/presets.hpp"

namespace kt = kelp::tether;
using kelp::Vector3;

TEST_CASE("ROV tether preset: 7.6 mm Fathom-class line, von Benzon et al.'s E and drag",
          "[tether][presets]") {
  for (double length : {5.0, 10.0, 15.0}) {
    const auto p = kt::presets::rov_tether(length);
    const kt::TetherModeld model(p);  // valid
    CHECK(p.length == length);
    CHECK(p.segments == static_cast<int>(std::lround(length / 0.25)));
    CHECK(model.segment_length() <= 0.25 + 1e-12);
    // Independent numbers: A = π (7.6 mm)²/4 = 4.5365e-5 m²; EA = 6.437e7 A = 2920 N.
    CHECK(model.area() == Approx(4.5365e-5).epsilon(1e-4));
    CHECK(p.axial_stiffness == Approx(2920.1).epsilon(1e-4));
    // Neutral in fresh water, slightly buoyant in seawater: w = (ρ_f − ρ_s) A g.
    CHECK(std::abs(model.submerged_weight_per_length(1000.0, 9.80665)) < 1e-12);
    CHECK(model.submerged_weight_per_length(1025.0, 9.80665) == Approx(-0.011122).epsilon(1e-3));
  }
  CHECK_THROWS_AS(kt::presets::rov_tether(0.0), kelp::invalid_argument);
  CHECK_THROWS_AS(kt::presets::rov_tether(10.0, -1.0), kelp::invalid_argument);
}

TEST_CASE("bead-chain preset: one node per 0.5 m bead, same mass and volume, neutral in seawater",
          "[tether][presets]") {
  const auto p = kt::presets::bead_chain(10.0);
  const kt::TetherModeld model(p);
  CHECK(p.segments == 20);
  CHECK(p.length == Approx(10.0));
  // An interior node carries one bead: 0.00429 kg and the sphere's volume 4/3 π (0.01 m)³.
  CHECK(model.node_mass(10) == Approx(0.00429).epsilon(1e-12));
  CHECK(model.node_volume(10) == Approx(4.0 / 3.0 * kelp::pi * 1e-6).epsilon(1e-12));
  // 0.00429 kg is the sphere's mass of seawater at 1024 kg/m³: (almost) no submerged weight.
  CHECK(std::abs(model.submerged_weight_per_length(1024.0, 9.80665)) < 1e-4);
  CHECK(kt::presets::bead_chain(5.0).segments == 10);
  CHECK(kt::presets::bead_chain(3.0).segments == 6);  // the paper's 3, 5 and 10 m chains
}

TEST_CASE("the ROV tether between an ASV and an AUV in the moderate sea steps with BDF2 at 10 ms",
          "[tether][presets]") {
  const auto env =
      kelp::environment::make_environment<double>(kelp::environment::presets::moderate());
  const kt::TetherModeld model(kt::presets::rov_tether(10.0));
  kt::TetherWorkspaced ws(model);
  const Vector3<double> asv(0, 0, 0.2), auv(6, 0, 5);
  kt::TetherStated s;
  REQUIRE(kt::static_initial_state(model, ws, kelp::environment::Environmentd{}, asv, auv, s)
              .converged);
  kt::StepReportd total;
  for (int k = 0; k < 1000; ++k) {  // 10 s
    auto b = kt::TetherBoundaryd::fixed(asv, auv);
    b.start.position.z() -= env.surface_elevation(0.0, 0.0, s.time);
    total += kt::step(model, ws, env, s, b, 0.01, {kt::Integrator::bdf2});
  }
  INFO("Newton per step " << double(total.newton_iterations) / total.substeps << ", retries "
                          << total.retries);
  CHECK(total.substeps >= 1000);
  CHECK(kelp::all_finite(s.position));
  CHECK(ws.tension.minCoeff() >= 0.0);
}
