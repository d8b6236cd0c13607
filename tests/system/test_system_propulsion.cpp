// The system with propulsion: the thrusters' commands move the vehicles through the lag and the
// battery, the battery drains, save/restore reproduces a run bit for bit, a refused step leaves
// the propulsion state as it was, and propulsion off is the earlier behaviour.
#include <Eigen/Core>
#include <catch2/catch.hpp>

#include "kelp/core/error.hpp"
#include "kelp/system/presets.hpp"
#include "kelp/system/system.hpp"

using namespace kelp;
namespace sp = kelp::system::presets;

namespace {

system::SystemInputsd commands(double surge) {
  system::SystemInputsd in;
  // The BlueROV2's horizontal thrusters forward (directions: 1, 2 aft-ward, 3, 4 forward for a
  // positive command), the boat's two thrusters at half.
  in.auv_commands = vehicle::ThrusterVector<double>::Zero(8);
  in.auv_commands << -surge, -surge, surge, surge, 0, 0, 0, 0;
  in.asv_commands = vehicle::ThrusterVector<double>::Constant(2, 0.5);
  return in;
}

bool same(const system::SystemStated& a, const system::SystemStated& b) {
  return a.time == b.time && a.asv.position == b.asv.position && a.auv.position == b.auv.position &&
         a.asv.nu == b.asv.nu && a.auv.nu == b.auv.nu && a.tether.position == b.tether.position &&
         a.asv_propulsion.thrust == b.asv_propulsion.thrust &&
         a.auv_propulsion.thrust == b.auv_propulsion.thrust &&
         a.auv_propulsion.battery.charge_drawn == b.auv_propulsion.battery.charge_drawn &&
         a.auv_propulsion.battery.energy_drawn == b.auv_propulsion.battery.energy_drawn &&
         a.asv_propulsion.battery.energy_drawn == b.asv_propulsion.battery.energy_drawn;
}

}  // namespace

TEST_CASE("System propulsion: commands drive the vehicles and drain the batteries",
          "[system][propulsion]") {
  sp::PaperWorld<double> w(10.0, sp::Sea::calm);
  REQUIRE(w.model.auv_propulsion() != nullptr);
  REQUIRE(w.model.asv_propulsion() != nullptr);
  REQUIRE(w.state.auv_propulsion.thrust.size() == 8);
  const system::SystemInputsd in = commands(0.5);
  const double x0 = w.state.auv.position.x();
  system::SystemReportd r;
  for (int k = 0; k < 200; ++k) r = system::step(w.model, w.workspace, w.state, in, 0.01);
  // Forward thrust: the ROV has moved forward (north; it starts astern, heading north).
  CHECK(w.state.auv.nu(0) > 0.1);
  CHECK(w.state.auv.position.x() > x0 + 0.1);
  // The thrust settled on the static curve at the step's voltage (20 ms lag, 2 s run; the
  // lag trails the voltage's slow fall by ~1e-6 relative).
  CHECK(w.state.auv_propulsion.thrust(2) ==
        Approx(vehicle::t200_thrust(0.5, r.auv_propulsion.voltage)).epsilon(1e-5));
  CHECK(r.auv_propulsion.current > 1.0);
  CHECK(r.auv_propulsion.voltage <
        vehicle::open_circuit_voltage(w.model.auv_propulsion()->parameters().battery, 1.0));
  const auto& b = w.state.auv_propulsion.battery;
  CHECK(b.charge_drawn > 0.0);
  CHECK(b.energy_drawn == Approx(b.charge_drawn * r.auv_propulsion.voltage).epsilon(0.01));
  CHECK(w.state.asv_propulsion.battery.charge_drawn > 0.0);
}

TEST_CASE("System propulsion: save and restore reproduce a run bit for bit",
          "[system][propulsion]") {
  sp::PaperWorld<double> w(10.0, sp::Sea::moderate);
  system::SystemInputsd in = commands(0.3);
  for (int k = 0; k < 50; ++k) system::step(w.model, w.workspace, w.state, in, 0.01);
  const system::SystemStated saved = w.state;
  const auto run = [&](system::SystemStated& s) {
    for (int k = 0; k < 60; ++k) {
      in.auv_commands(0) = -0.3 - 0.01 * k;  // commands that change every step
      system::step(w.model, w.workspace, s, in, 0.01);
    }
  };
  system::SystemStated a = saved;
  run(a);
  system::SystemStated b = saved;
  run(b);
  CHECK(same(a, b));
  CHECK_FALSE(same(a, saved));
}

TEST_CASE(
    "System propulsion: a refused step leaves the state as it was; off is the old "
    "behaviour",
    "[system][propulsion]") {
  sp::PaperWorld<double> w(10.0, sp::Sea::calm);
  system::SystemInputsd in = commands(0.5);
  for (int k = 0; k < 10; ++k) system::step(w.model, w.workspace, w.state, in, 0.01);
  const system::SystemStated before = w.state;
  in.auv_commands = vehicle::ThrusterVector<double>::Zero(3);
  CHECK_THROWS_AS(system::step(w.model, w.workspace, w.state, in, 0.01), kelp::invalid_argument);
  CHECK(same(w.state, before));
  in = commands(0.5);
  in.auv.tau(0) = std::nan("");
  CHECK_THROWS_AS(system::step(w.model, w.workspace, w.state, in, 0.01), kelp::invalid_argument);
  CHECK(same(w.state, before));
  system::SystemStated hand = w.state;
  hand.auv_propulsion = vehicle::PropulsionStated{};
  CHECK_THROWS_AS(system::step(w.model, w.workspace, hand, commands(0.5), 0.01),
                  kelp::invalid_argument);

  // Propulsion off: commands are refused, the wrench τ alone moves the vehicle; with propulsion
  // on and no commands, the same τ gives the same motion bit for bit (B·0 adds nothing).
  system::SystemParametersd off = sp::paper_system(10.0);
  off.asv_propulsion.reset();
  off.auv_propulsion.reset();
  const system::SystemModeld m_off(off, sp::environment<double>(sp::Sea::calm));
  system::SystemWorkspaced ws_off(m_off);
  const sp::StartPoses<double> start = sp::paper_start(10.0);
  system::SystemStated s_off = system::initial_state(m_off, ws_off, start.asv, start.auv);
  CHECK(s_off.auv_propulsion.thrust.size() == 0);
  CHECK_THROWS_AS(system::step(m_off, ws_off, s_off, commands(0.5), 0.01), kelp::invalid_argument);
  sp::PaperWorld<double> on(10.0, sp::Sea::calm);
  system::SystemInputsd tau_only;
  tau_only.auv.tau(0) = 20.0;
  for (int k = 0; k < 50; ++k) {
    system::step(m_off, ws_off, s_off, tau_only, 0.01);
    system::step(on.model, on.workspace, on.state, tau_only, 0.01);
  }
  CHECK(s_off.auv.position == on.state.auv.position);
  CHECK(s_off.asv.nu == on.state.asv.nu);
}

TEST_CASE("System propulsion: no heap allocation in a step", "[system][propulsion]") {
  sp::PaperWorld<double> w(10.0, sp::Sea::moderate);
  const system::SystemInputsd in = commands(0.5);
  system::step(w.model, w.workspace, w.state, in, 0.01);
  Eigen::internal::set_is_malloc_allowed(false);
  for (int k = 0; k < 5; ++k) system::step(w.model, w.workspace, w.state, in, 0.01);
  Eigen::internal::set_is_malloc_allowed(true);
  CHECK(w.state.auv_propulsion.battery.charge_drawn > 0.0);
}
