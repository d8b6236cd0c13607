// The entanglement scenarios of kelp-tethered-pair (apps/tethered_pair/scenarios/):
// - pile_wrap.json: a ROV circles a pile once on its tether while its boat keeps station; the
//   tether wraps, and `entangled` fires when the chord between the tether's ends leaves the
//   pile's shadow past the half orbit (computed here from the vehicles' attachment points), and
//   not before;
// - mooring_flyby_snag.json / mooring_flyby_slide.json: a ROV flies under an inclined mooring
//   line in a current and on beyond the reach of its tether; with friction (μ = 1) the tether
//   sticks on the mooring line while the ROV pulls (`pinned`), without friction (μ = 0) it slides
//   over it (no `pinned`, the same tension on both sides of the contact).
#include <Eigen/Core>
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "kelp/environment/obstacles.hpp"
#include "kelp/sim/closed_loop.hpp"
#include "kelp/sim/scenario.hpp"
#include "kelp/sim/world.hpp"
#include "sim_test_support.hpp"

namespace ksim = kelp::sim;
using V3 = kelp::Vector3<double>;

#ifndef KELP_SCENARIO_DIR
#error "KELP_SCENARIO_DIR must name apps/tethered_pair/scenarios"
#endif

namespace {

std::string scenario_path(const std::string& name) {
  return std::string(KELP_SCENARIO_DIR) + "/" + name;
}

// The scenario and its world, as kelp-tethered-pair builds them.
struct Loaded {
  ksim::Scenario scenario;
  ksim::WorldSetup world;
};

Loaded load(const std::string& name) {
  const std::string file = scenario_path(name);
  Loaded l{ksim::load_scenario(file), {}};
  l.world = ksim::world_setup(l.scenario, file);
  // kelp::sim gives the vehicles their hulls when the world has a seabed or obstacles.
  REQUIRE(l.world.parameters.auv_hull.has_value());
  REQUIRE(l.world.parameters.asv_hull.has_value());
  return l;
}

// The 2-D distance of the segment a–b (horizontal projections) from the point c.
double distance_2d(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const Eigen::Vector2d ab = b - a;
  const double s = std::clamp((c - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (a + s * ab - c).norm();
}

}  // namespace

TEST_CASE("scenario pile_wrap: the tether wraps once and `entangled` fires on time",
          "[sim][entanglement][scenario]") {
  const Loaded l = load("pile_wrap.json");
  const auto* obstacles = l.world.environment.obstacles();
  REQUIRE(obstacles != nullptr);
  REQUIRE(obstacles->cylinders().size() == 1);
  const kelp::environment::Cylinder pile = obstacles->cylinders()[0];
  const Eigen::Vector2d axis = pile.from.head<2>();
  REQUIRE((pile.to.head<2>() - axis).norm() == 0.0);  // vertical
  // The expected time: the first step after the ROV has passed behind the pile (its angle about
  // the pile more than π from its start) at which the chord between the tether's ends
  // (the attachment points) is the blend radius b = r + d/2 clear of the axis.
  ksim::ClosedLoop loop(l.scenario, l.world);
  const double b = pile.radius + 0.5 * loop.model().tether().parameters().diameter;
  const auto& p = loop.model().parameters();
  const auto ends = [&](Eigen::Vector2d& boat, Eigen::Vector2d& rov) {
    boat = loop.state().asv.point_position(p.asv_attachment).head<2>();
    rov = loop.state().auv.point_position(p.auv_attachment).head<2>();
  };
  Eigen::Vector2d boat, rov;
  ends(boat, rov);
  const double start_angle = std::atan2(rov.y() - axis.y(), rov.x() - axis.x());
  double orbit = 0, last = start_angle, expected = -1, min_clearance = 1e9;
  while (!loop.done()) {
    loop.step();
    ends(boat, rov);
    const double a = std::atan2(rov.y() - axis.y(), rov.x() - axis.x());
    orbit += std::remainder(a - last, 2 * kelp::pi);
    last = a;
    const double d = distance_2d(boat, rov, axis);
    if (std::abs(orbit) > kelp::pi && expected < 0) {
      min_clearance = std::min(min_clearance, d);
      if (d >= b) expected = loop.time();
    }
  }
  const ksim::EntanglementMonitor& m = loop.entanglement();
  INFO("orbit " << orbit << " rad, expected event at " << expected << " s, final winding "
                << m.obstacle(0).winding << " rad, max " << m.obstacle(0).max_abs_winding);
  REQUIRE(std::abs(orbit) > 2 * kelp::pi);  // the ROV went round once
  REQUIRE(expected > 0);
  REQUIRE(m.events().size() >= 1);
  const ksim::EntanglementEvent& e = m.events()[0];
  CHECK(e.kind == ksim::EntanglementEvent::Kind::entangled);
  INFO("event at " << e.time << " s");
  CHECK(std::abs(e.time - expected) <= 0.011);
  // One wrap, and it stays wound: |W| = 2π at the end (the chord is clear of the pile).
  CHECK(std::abs(std::abs(m.obstacle(0).winding) - 2 * kelp::pi) < 0.05);
  // The summary carries it.
  const nlohmann::json s = kelp_test::json_of(loop.summary());
  const auto& o = s["entanglement"]["obstacles"][0];
  CHECK(o["name"] == "pile");
  CHECK(o["entangled_s"].get<double>() == e.time);
  CHECK(std::abs(o["max_abs_winding_rad"].get<double>() - 2 * kelp::pi) < 0.05);
  // The scenario echo keeps the obstacles (the replay draws them from it).
  CHECK(s["scenario"]["obstacles"][0]["name"] == "pile");
}

TEST_CASE("scenario mooring_flyby: the tether snags with friction and slides without",
          "[sim][entanglement][scenario]") {
  const bool snag = GENERATE(true, false);
  const Loaded l = load(snag ? "mooring_flyby_snag.json" : "mooring_flyby_slide.json");
  REQUIRE(l.world.environment.obstacles() != nullptr);
  ksim::ClosedLoop loop(l.scenario, l.world);
  double max_difference = 0, max_contact = 0;
  while (!loop.done()) {
    loop.step();
    const ksim::ObstacleWinding& w = loop.entanglement().obstacle(0);
    max_contact = std::max(max_contact, double(w.contact_nodes));
    max_difference = std::max(max_difference, w.tension_difference);
  }
  const ksim::EntanglementMonitor& m = loop.entanglement();
  INFO((snag ? "snag" : "slide") << ": most contact nodes " << max_contact
                                 << ", largest tension difference " << max_difference
                                 << " N, events " << m.events().size());
  CHECK(max_contact >= 1);  // the tether reached the mooring line
  bool pinned = false;
  for (const auto& e : m.events()) {
    pinned = pinned || e.kind == ksim::EntanglementEvent::Kind::pinned;
    UNSCOPED_INFO(ksim::event_name(e.kind) << " at " << e.time << " s, value " << e.value << ", at "
                                           << e.position.transpose());
  }
  CHECK(pinned == snag);
  if (!snag) CHECK(max_difference < m.settings().pin_tension_difference);
}
