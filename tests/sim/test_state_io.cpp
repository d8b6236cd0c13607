// State files (kelp/sim/state_io.hpp): a saved and loaded state steps on bit for bit, the pair's
// and a fleet's (BDF2 with its history and kept Newton matrix, a winch that has re-meshed,
// thrusters and batteries); bad input of every kind (truncated, one bit flipped, another magic,
// format, kind or system, NaN, absurd lengths, unknown or missing sections) is refused with a
// state_error naming it; the file helpers write atomically.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "../support/heap_counter.hpp"
#include "kelp/sim/fleet_run.hpp"
#include "kelp/sim/ros2/mcap.hpp"  // kelp::ros2::crc32, to forge files with a valid checksum
#include "kelp/sim/scenario.hpp"
#include "kelp/sim/state_io.hpp"
#include "kelp/sim/world.hpp"

// One namespace for the whole file: the directory's tests are compiled as one unity unit, whose
// other files have their own `ks`, `sim` and helpers at namespace scope.
namespace state_io_test {
namespace {

namespace sim = kelp::sim;
namespace ks = kelp::system;
namespace fs = std::filesystem;

std::string state_scenario(const char* name) {
  return std::string(KELP_SCENARIO_DIR) + "/" + name + ".json";
}

// The pair of winch_dive.json (a winch on the boat, both vehicles' thrusters and batteries,
// BDF2 with the simplified Newton method), on a coarse tether: built afresh for every use, as a
// program that restarts from a state file would.
struct Pair {
  sim::Scenario scenario;
  sim::WorldSetup world;
  ks::SystemModeld model;
  ks::SystemWorkspaced ws;
  explicit Pair(const char* name = "winch_dive", double segment_length = 1.0)
      : scenario(coarse(name, segment_length)),
        world(sim::world_setup(scenario, state_scenario(name))),
        model(world.parameters, world.environment),
        ws(model) {}
  static sim::Scenario coarse(const char* name, double segment_length) {
    sim::Scenario sc = sim::load_scenario(state_scenario(name));
    sc.segment_length = segment_length;
    return sc;
  }
  ks::SystemStated start() { return sim::start_state(model, ws, world, scenario); }
  ks::SystemInputsd inputs(double payout) const {
    ks::SystemInputsd in;
    in.asv_commands.setConstant(model.asv_propulsion()->size(), 0.3);
    in.auv_commands.setConstant(model.auv_propulsion()->size(), -0.2);
    in.auv_commands(0) = 0.6;
    in.winch_payout_rate = payout;
    return in;
  }
};

// ship_tms_rov.json (an anchored umbilical to a point mass, a winch paying out the ROV's
// tether, the ROV's thrusters and battery) on coarse tethers.
struct Fleet {
  sim::Scenario scenario;
  sim::FleetWorld world;
  ks::FleetModeld model;
  ks::FleetWorkspaced ws;
  explicit Fleet(const char* name = "ship_tms_rov")
      : scenario(coarse(name)),
        world(sim::fleet_world(scenario, state_scenario(name))),
        model(world.parameters, world.environment),
        ws(model) {}
  static sim::Scenario coarse(const char* name) {
    sim::Scenario sc = sim::load_scenario(state_scenario(name));
    for (auto& t : sc.fleet->tethers) t.segment_length = t.length / 10;
    return sc;
  }
  ks::FleetStated start() {
    return sim::fleet_start_state(model, ws, world, scenario, state_scenario("ship_tms_rov"));
  }
  ks::FleetInputsd inputs(double payout) const {
    ks::FleetInputsd in(model);
    for (int i = 0; i < model.vehicle_count(); ++i)
      if (const auto* p = model.propulsion(i))
        in.commands[std::size_t(i)].setConstant(p->size(), 0.4);
    for (int k = 0; k < model.tether_count(); ++k)
      if (model.winch(k)) in.winch_payout_rates[std::size_t(k)] = payout;
    return in;
  }
};

bool same_bits(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::memcmp(a.data(), b.data(), sizeof(double) * 3) == 0;
}

// Two files compared without printing their bytes: false names the first byte that differs.
bool same_bytes(const std::string& a, const std::string& b) {
  if (a == b) return true;
  std::size_t i = 0;
  while (i < a.size() && i < b.size() && a[i] == b[i]) ++i;
  UNSCOPED_INFO("the files differ from byte " << i << " (sizes " << a.size() << ", " << b.size()
                                              << ")");
  return false;
}

// The byte where the payload starts (docs/state-files.md): magic 8, format 2, kind 2, the
// writer's version (1 + n), the payload's length 8.
std::size_t payload_at(const std::string& b) { return 13 + static_cast<unsigned char>(b[12]) + 8; }
std::uint64_t get_u64(const std::string& b, std::size_t at) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= std::uint64_t(static_cast<unsigned char>(b[at + i])) << (8 * i);
  return v;
}
void put_u(std::string& b, std::size_t at, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) b[at + i] = static_cast<char>((v >> (8 * i)) & 0xFF);
}
// The CRC-32 at the end recomputed, so that a forged change reaches the checks behind it.
std::string resealed(std::string b) {
  put_u(b, b.size() - 4, kelp::ros2::crc32(b.data(), b.size() - 4), 4);
  return b;
}
void put_f64(std::string& b, std::size_t at, double v) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &v, 8);
  put_u(b, at, bits, 8);
}
// The offset of section number `index` (0: HEAD) of a file, at its tag.
std::size_t section_at(const std::string& b, int index) {
  std::size_t at = payload_at(b);
  for (int i = 0; i < index; ++i) at += 12 + get_u64(b, at + 4);
  return at;
}
// The payload's length field set to the bytes between it and the CRC.
std::string with_payload_length_fixed(std::string b) {
  const std::size_t at = payload_at(b) - 8;
  put_u(b, at, b.size() - 4 - payload_at(b), 8);
  return resealed(b);
}

std::string load_error(const std::string& bytes, const ks::SystemModeld& model) {
  try {
    (void)sim::load_state(bytes, model);
  } catch (const sim::state_error& e) {
    return e.what();
  }
  return "(no error)";
}

// True when the next step of `s` uses its kept Newton matrix: stepped without it (cleared), the
// line ends elsewhere. (p's workspace is lent to each copy in turn: system::fit_workspace.)
bool newton_matters(Pair& p, const ks::SystemStated& s) {
  ks::SystemStated x = s, y = s;
  y.tether.newton.clear();
  for (ks::SystemStated* z : {&x, &y}) {
    ks::fit_workspace(p.model, p.ws, *z);
    (void)ks::step(p.model, p.ws, *z, p.inputs(0.5), 0.01);
  }
  return x.tether.position.cols() == y.tether.position.cols() &&
         std::memcmp(x.tether.position.data(), y.tether.position.data(),
                     sizeof(double) * std::size_t(x.tether.position.size())) != 0;
}

// A stepped pair: BDF2 history, a kept Newton matrix that its next step uses, a winch that has
// inserted nodes, thrust.
ks::SystemStated stepped_pair(Pair& p) {
  ks::SystemStated s = p.start();
  const auto in = p.inputs(0.5);
  const auto nodes0 = s.tether.position.cols();
  for (int i = 0; i < 400 && s.tether.position.cols() < nodes0 + 2; ++i)
    (void)ks::step(p.model, p.ws, s, in, 0.01);
  REQUIRE(s.tether.position.cols() == nodes0 + 2);
  // A re-mesh starts the history afresh: on until the line has it again, with a kept matrix
  // that the next step uses (not every step does: a matrix paused after a slow correction, or
  // one whose segments changed branch, is formed anew).
  for (int i = 0; i < 300; ++i) {
    if (s.tether.has_history() && s.tether.newton.gh > 0.0 && newton_matters(p, s)) break;
    ks::fit_workspace(p.model, p.ws, s);
    (void)ks::step(p.model, p.ws, s, in, 0.01);
  }
  ks::fit_workspace(p.model, p.ws, s);
  return s;
}

}  // namespace

TEST_CASE("a pair's state saved and loaded steps on bit for bit (BDF2, winch, thrusters)",
          "[sim][state_io]") {
  Pair a;
  REQUIRE(a.model.winch());
  REQUIRE(a.model.asv_propulsion());
  REQUIRE(a.model.auv_propulsion());
  REQUIRE(a.model.parameters().tether_integrator == kelp::tether::Integrator::bdf2);
  ks::SystemStated s = stepped_pair(a);
  // Everything that matters is there to be saved.
  REQUIRE(s.tether.has_history());
  REQUIRE(s.tether.newton.gh > 0.0);
  REQUIRE(newton_matters(a, s));  // its next step uses the kept Newton matrix
  ks::fit_workspace(a.model, a.ws, s);
  REQUIRE(s.tether.winch_length > 0.0);
  REQUIRE(s.tether.payout_rate > 0.0);
  REQUIRE(s.asv_propulsion.thrust.norm() > 0.0);
  REQUIRE(s.auv_nu_dot.norm() > 0.0);
  REQUIRE(std::isfinite(s.auv_propulsion.battery.voltage));

  const std::string bytes = sim::save_state(s);
  // A restart: a new world from the same scenario, the state loaded into it.
  Pair b;
  ks::SystemStated loaded = sim::load_state(bytes, b.model);
  CHECK(same_bytes(sim::save_state(loaded), bytes));
  CHECK(loaded.tether.position.cols() == s.tether.position.cols());
  // b's workspace holds the initial node count: the loaded state needs its own.
  CHECK_THROWS_WITH(ks::step(b.model, b.ws, loaded, b.inputs(0.5), 0.01),
                    Catch::Contains("fit_workspace"));
  ks::fit_workspace(b.model, b.ws, loaded);
  // Pay out until a node is inserted, then reel in until one is removed, both states side by
  // side.
  int inserted = 0, removed = 0;
  for (int i = 0; i < 800 && removed == 0; ++i) {
    const auto in = a.inputs(inserted == 0 ? 0.5 : -0.5);
    const ks::SystemReportd ra = ks::step(a.model, a.ws, s, in, 0.01);
    const long before = kelp_test::heap_allocations();
    const ks::SystemReportd rb = ks::step(b.model, b.ws, loaded, in, 0.01);
    REQUIRE(kelp_test::heap_allocations() == before);
    REQUIRE(same_bits(ra.force_on_asv, rb.force_on_asv));
    REQUIRE(same_bits(ra.force_on_auv, rb.force_on_auv));
    REQUIRE(ra.tether.newton_iterations == rb.tether.newton_iterations);
    inserted += ra.remesh.inserted;
    removed += ra.remesh.removed;
    if (i % 20 == 19) REQUIRE(same_bytes(sim::save_state(s), sim::save_state(loaded)));
  }
  CHECK(inserted >= 1);
  CHECK(removed >= 1);
  CHECK(same_bytes(sim::save_state(s), sim::save_state(loaded)));
}

TEST_CASE(
    "the integrator history, the accelerations and the kept Newton matrix change the next "
    "steps' bits",
    "[sim][state_io]") {
  // What the test above relies on: without them a loaded state would step differently.
  Pair a;
  const ks::SystemStated s = stepped_pair(a);
  const std::string bytes = sim::save_state(s);
  REQUIRE(s.tether.has_acceleration);
  for (int variant = 0; variant < 4; ++variant) {
    Pair b;
    ks::SystemStated x = sim::load_state(bytes, b.model), y = x;
    if (variant == 0) y.tether.newton.clear();
    if (variant == 1) y.tether.clear_history();
    if (variant == 2) y.tether.has_acceleration = false;
    if (variant == 3) y.tether.predict_from_acceleration = !y.tether.predict_from_acceleration;
    const auto in = b.inputs(0.5);
    for (ks::SystemStated* z : {&x, &y}) {
      ks::fit_workspace(b.model, b.ws, *z);
      (void)ks::step(b.model, b.ws, *z, in, 0.01);
    }
    INFO("variant " << variant);
    CHECK_FALSE(same_bytes(sim::save_state(x), sim::save_state(y)));
  }
}

TEST_CASE("one workspace steps states of other node counts in turn (fit_workspace), bit for bit",
          "[sim][state_io]") {
  // A copy kept at one node count is stepped after the original re-meshed past it: the
  // workspace lends the copy's count back, and its spare buffers are whole again, so that the
  // copy's own re-mesh into the count the original left goes through (and allocates nothing).
  Pair p;
  ks::SystemStated a = stepped_pair(p);
  const ks::SystemStated copy = a;
  const auto in = p.inputs(0.5);
  const auto nodes = a.tether.position.cols();
  std::vector<std::string> trail;
  for (int i = 0; i < 400 && a.tether.position.cols() == nodes; ++i) {
    (void)ks::step(p.model, p.ws, a, in, 0.01);
    trail.push_back(sim::save_state(a));
  }
  REQUIRE(a.tether.position.cols() == nodes + 1);
  ks::SystemStated b = copy;
  CHECK_THROWS_WITH(ks::step(p.model, p.ws, b, in, 0.01), Catch::Contains("fit_workspace"));
  ks::fit_workspace(p.model, p.ws, b);
  for (const std::string& expected : trail) {
    const long before = kelp_test::heap_allocations();
    (void)ks::step(p.model, p.ws, b, in, 0.01);
    REQUIRE(kelp_test::heap_allocations() == before);
    REQUIRE(same_bytes(sim::save_state(b), expected));
  }
  CHECK(b.tether.position.cols() == nodes + 1);
}

TEST_CASE("a fleet's state saved and loaded steps on bit for bit (point mass, winch, thrusters)",
          "[sim][state_io]") {
  Fleet a;
  ks::FleetStated s = a.start();
  const int winch = a.model.tether_index("tether");
  const int rov = a.model.vehicle_index("rov");
  REQUIRE(a.model.winch(winch));
  REQUIRE(a.model.propulsion(rov));
  REQUIRE(a.model.point_mass_count() == 1);
  const auto out = a.inputs(0.5);
  const auto nodes0 = s.tethers[std::size_t(winch)].position.cols();
  for (int i = 0; i < 400 && s.tethers[std::size_t(winch)].position.cols() < nodes0 + 1; ++i)
    (void)ks::step(a.model, a.ws, s, out, 0.01);
  REQUIRE(s.tethers[std::size_t(winch)].position.cols() == nodes0 + 1);
  const auto ready = [&] {
    for (const auto& t : s.tethers)
      if (!t.has_history() || !(t.newton.gh > 0.0)) return false;
    return true;
  };
  for (int i = 0; i < 100 && !ready(); ++i) (void)ks::step(a.model, a.ws, s, out, 0.01);
  for (const auto& t : s.tethers) {
    REQUIRE(t.has_history());
    REQUIRE(t.newton.gh > 0.0);
  }
  REQUIRE(s.point_mass_acceleration[0].norm() > 0.0);
  REQUIRE(s.propulsion[std::size_t(rov)].thrust.norm() > 0.0);

  const std::string bytes = sim::save_state(s);
  Fleet b;
  ks::FleetStated loaded = sim::load_state(bytes, b.model);
  CHECK(same_bytes(sim::save_state(loaded), bytes));
  ks::fit_workspace(b.model, b.ws, loaded);
  int inserted = 0, removed = 0;
  for (int i = 0; i < 800 && removed == 0; ++i) {
    const auto in = a.inputs(inserted == 0 ? 0.5 : -0.5);
    const ks::FleetReportd& ra = ks::step(a.model, a.ws, s, in, 0.01);
    const long before = kelp_test::heap_allocations();
    const ks::FleetReportd& rb = ks::step(b.model, b.ws, loaded, in, 0.01);
    REQUIRE(kelp_test::heap_allocations() == before);
    for (std::size_t k = 0; k < s.tethers.size(); ++k) {
      REQUIRE(same_bits(ra.force_at_start[k], rb.force_at_start[k]));
      REQUIRE(same_bits(ra.force_at_end[k], rb.force_at_end[k]));
    }
    inserted += ra.remesh[std::size_t(winch)].inserted;
    removed += ra.remesh[std::size_t(winch)].removed;
    if (i % 20 == 19) REQUIRE(same_bytes(sim::save_state(s), sim::save_state(loaded)));
  }
  CHECK(inserted >= 1);
  CHECK(removed >= 1);
  CHECK(same_bytes(sim::save_state(s), sim::save_state(loaded)));
}

TEST_CASE("a state file is refused when truncated or with any one bit flipped",
          "[sim][state_io][bad_input]") {
  Pair p;
  const std::string bytes = sim::save_state(p.start());
  const std::size_t header = payload_at(bytes);
  std::vector<std::size_t> cuts;
  for (std::size_t c = 0; c <= header; ++c) cuts.push_back(c);  // every byte of the header
  for (int k = 1; k < 10; ++k) cuts.push_back(bytes.size() * std::size_t(k) / 10);
  cuts.push_back(bytes.size() - 1);
  for (std::size_t c : cuts) {
    INFO("cut at " << c << " of " << bytes.size());
    CHECK_THAT(load_error(bytes.substr(0, c), p.model), Catch::Contains("truncated"));
  }
  // One bit flipped anywhere (CRC-32 finds every single-bit error; the header's fields are
  // checked before it).
  int refused = 0, flips = 0;
  std::string b = bytes;
  for (std::size_t i = 0; i < b.size(); ++i) {
    for (int bit = 0; bit < 8; ++bit) {
      b[i] = static_cast<char>(b[i] ^ (1 << bit));
      ++flips;
      try {
        (void)sim::load_state(b, p.model);
      } catch (const sim::state_error& e) {
        ++refused;
      }
      b[i] = bytes[i];
    }
  }
  CHECK(refused == flips);
  // The common cases' messages.
  CHECK_THAT(load_error(bytes.substr(0, bytes.size() - 1), p.model),
             Catch::StartsWith("state: truncated"));
  std::string corrupt = bytes;
  corrupt[header + 40] = static_cast<char>(corrupt[header + 40] ^ 0x10);
  CHECK_THAT(load_error(corrupt, p.model), Catch::Contains("checksum mismatch"));
  CHECK_THAT(load_error(bytes + "x", p.model), Catch::Contains("1 bytes past the end"));
}

TEST_CASE("a state file of another magic, format, kind or system is refused, naming it",
          "[sim][state_io][bad_input]") {
  Pair p;
  const std::string bytes = sim::save_state(p.start());
  CHECK_THAT(load_error("{\"not\": \"a state\"}", p.model),
             Catch::Contains("not a kelp state file"));
  std::string b = bytes;
  put_u(b, 8, 1, 2);  // format 1: before the tethers' accelerations were saved
  CHECK_THAT(load_error(resealed(b), p.model),
             Catch::Contains("archive format 1, this kelp reads format 2 only"));
  put_u(b, 8, 3, 2);
  CHECK_THAT(load_error(resealed(b), p.model), Catch::Contains("archive format 3"));
  // A fleet's file for a pair, and the other way round.
  Fleet f;
  const std::string fleet_bytes = sim::save_state(f.start());
  CHECK_THAT(load_error(fleet_bytes, p.model),
             Catch::Contains("holds a fleet state, a pair state is expected"));
  CHECK_THROWS_WITH(sim::load_state(bytes, f.model),
                    Catch::Contains("holds a pair state, a fleet state is expected"));
  // Another pair: without a winch its tether keeps its node count; without thrusters.
  const ks::SystemStated winched = stepped_pair(p);
  Pair plain("calm_hold", 1.0);
  REQUIRE_FALSE(plain.model.winch());
  CHECK_THAT(load_error(sim::save_state(winched), plain.model), Catch::Contains("nodes"));
  ks::SystemStated s = plain.start();
  s.tether.winch_length = 1.0;
  CHECK_THAT(load_error(sim::save_state(s), plain.model), Catch::Contains("no winch"));
  kelp::sim::WorldSetup w = plain.world;
  w.parameters.auv_propulsion.reset();
  const ks::SystemModeld no_thrusters(w.parameters, w.environment);
  CHECK_THAT(load_error(sim::save_state(plain.start()), no_thrusters),
             Catch::Contains("the AUV's propulsion: 8 thrusters, the system's vehicle has 0"));
  // Another fleet.
  Fleet other("boat_two_rovs");
  CHECK_THROWS_WITH(sim::load_state(fleet_bytes, other.model),
                    Catch::Contains("1 vehicles, 1 point masses and 2 tethers, the fleet has 3 "
                                    "vehicles, 0 point masses and 2 tethers"));
  // Without a model the structure alone is checked.
  CHECK(same_bytes(sim::save_state(sim::load_system_state(bytes)), bytes));
  CHECK(same_bytes(sim::save_state(sim::load_fleet_state(fleet_bytes)), fleet_bytes));
}

TEST_CASE("NaN, infinity and broken invariants are refused when saving and when loading",
          "[sim][state_io][bad_input]") {
  Pair p;
  const ks::SystemStated good = p.start();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  // Saving: what the loader would refuse is not written.
  const auto save_error = [](const ks::SystemStated& s) {
    try {
      (void)sim::save_state(s);
    } catch (const sim::state_error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  ks::SystemStated s = good;
  s.asv.position.x() = nan;
  CHECK_THAT(save_error(s), Catch::Contains("the ASV: state.position"));
  s = good;
  s.auv.attitude.coeffs() *= 2.0;
  CHECK_THAT(save_error(s), Catch::Contains("unit quaternion"));
  s = good;
  s.tether.velocity(2, 3) = -inf;
  CHECK_THAT(save_error(s), Catch::Contains("the tether: its velocities must be finite"));
  s = good;
  s.tether.time = 1.0;
  CHECK_THAT(save_error(s), Catch::Contains("differs from the system's"));
  s = good;
  s.auv_propulsion.thrust(1) = nan;
  CHECK_THAT(save_error(s), Catch::Contains("the AUV's propulsion: the thrust must be finite"));
  s = good;
  s.tether.previous_dt = 0.01;
  s.tether.previous_position(0, 1) = inf;
  CHECK_THAT(save_error(s), Catch::Contains("previous positions and velocities must be finite"));
  // A state whose battery was never loaded (voltage NaN) is fine: that NaN is not an input.
  REQUIRE(std::isnan(good.asv_propulsion.battery.voltage));
  CHECK(same_bytes(sim::save_state(sim::load_state(sim::save_state(good), p.model)),
                   sim::save_state(good)));

  // Loading: the same values forged into a file with a valid checksum.
  const std::string bytes = sim::save_state(good);
  const std::size_t asv = section_at(bytes, 1) + 12;  // VEHI #0's body: position first
  std::string b = bytes;
  put_f64(b, asv, nan);
  CHECK_THAT(load_error(resealed(b), p.model), Catch::Contains("the ASV: state.position"));
  b = bytes;
  put_f64(b, asv + 24 + 24, 0.0);  // the quaternion's w
  CHECK_THAT(load_error(resealed(b), p.model), Catch::Contains("unit quaternion"));
  b = bytes;
  put_f64(b, payload_at(b) + 12, inf);  // HEAD's clock
  CHECK_THAT(load_error(resealed(b), p.model), Catch::Contains("the system's clock"));
  const std::size_t tether = section_at(bytes, 5) + 12;
  b = bytes;
  put_f64(b, tether + 44 + 8 * 7, nan);  // a node's position
  CHECK_THAT(load_error(resealed(b), p.model), Catch::Contains("positions must be finite"));
  b = bytes;
  put_f64(b, tether + 16, -0.01);  // previous_dt
  CHECK_THAT(load_error(resealed(b), p.model), Catch::Contains("previous_dt"));
}

TEST_CASE("absurd lengths, unknown and missing sections are refused without allocating for them",
          "[sim][state_io][bad_input]") {
  Pair p;
  const std::string bytes = sim::save_state(p.start());
  const std::size_t head = payload_at(bytes);
  // The payload's length.
  std::string b = bytes;
  put_u(b, head - 8, std::uint64_t(1) << 62, 8);
  CHECK_THAT(load_error(resealed(b), p.model), Catch::Contains("truncated: the header says"));
  // A section's length.
  b = bytes;
  put_u(b, head + 4, std::uint64_t(-1), 8);
  CHECK_THAT(load_error(resealed(b), p.model), Catch::Contains("section 'HEAD' says"));
  // The tether's node count (its first u32, after five doubles).
  const std::size_t tether = section_at(bytes, 5) + 12;
  b = bytes;
  put_u(b, tether + 40, 0x7FFFFFFF, 4);
  CHECK_THAT(load_error(resealed(b), p.model),
             Catch::Contains("section 'TETH' #0: nodes: 2147483647, more than"));
  b = bytes;
  put_u(b, tether + 40, 5, 4);
  CHECK_THAT(load_error(resealed(b), p.model), Catch::Contains("5 nodes need"));
  // A thruster count.
  b = bytes;
  put_u(b, section_at(bytes, 2) + 12, 1000000000, 4);
  CHECK_THAT(load_error(resealed(b), p.model), Catch::Contains("thrusters: 1000000000"));
  // A fleet counting four billion vehicles: refused before anything is sized by it.
  Fleet f;
  std::string fb = sim::save_state(f.start());
  put_u(fb, payload_at(fb) + 12 + 8, 0xFFFFFFFF, 4);
  CHECK_THROWS_WITH(sim::load_state(resealed(fb), f.model),
                    Catch::Contains("the header counts 4294967295 vehicles"));
  // An unknown section after the last, one in place of another, a missing one.
  b = bytes.substr(0, bytes.size() - 4) + "XTRA" + std::string(8, '\0') + "0000";
  CHECK_THAT(load_error(with_payload_length_fixed(b), p.model),
             Catch::Contains("unknown section 'XTRA'"));
  b = bytes;
  b.replace(section_at(bytes, 2), 4, "XTRA");
  CHECK_THAT(load_error(resealed(b), p.model),
             Catch::Contains("section 'XTRA' where 'PROP' is expected"));
  b = bytes.substr(0, section_at(bytes, 5)) + "0000";
  CHECK_THAT(load_error(with_payload_length_fixed(b), p.model),
             Catch::Contains("missing section 'TETH'"));
  // A section with bytes past its values.
  b = bytes;
  b.insert(section_at(bytes, 2), bytes.substr(section_at(bytes, 1), 12 + 160));  // a VEHI more
  CHECK_THAT(load_error(with_payload_length_fixed(b), p.model),
             Catch::Contains("section 'VEHI' where 'PROP' is expected"));
  b = bytes;
  put_u(b, section_at(bytes, 1) + 4, 168, 8);  // VEHI says 8 bytes more than its values
  b.insert(section_at(bytes, 2), 8, '\0');
  CHECK_THAT(load_error(with_payload_length_fixed(b), p.model),
             Catch::Contains("section 'VEHI' #0: 8 bytes past the end of its values"));
}

TEST_CASE("state files are written atomically and read back; errors name the path",
          "[sim][state_io]") {
  const fs::path dir = fs::temp_directory_path() / "kelp_test_state_io";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string path = (dir / "pair.kelpstate").string();
  Pair p;
  const ks::SystemStated s = p.start();
  sim::save_state_file(path, s);
  CHECK(same_bytes(sim::save_state(sim::load_state_file(path, p.model)), sim::save_state(s)));
  // A state that cannot be saved leaves the file as it was, and no temporary file.
  ks::SystemStated bad = s;
  bad.auv.nu(3) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(sim::save_state_file(path, bad), sim::state_error);
  // Nor does a file that cannot be written (a directory stands in the way of the rename).
  fs::create_directories(dir / "taken");
  CHECK_THROWS_AS(sim::save_state_file((dir / "taken").string(), s), kelp::error);
  CHECK(std::distance(fs::directory_iterator(dir), fs::directory_iterator()) == 2);
  CHECK(same_bytes(sim::save_state(sim::load_state_file(path, p.model)), sim::save_state(s)));
  // Overwriting replaces the whole file.
  ks::SystemStated later = s;
  (void)ks::step(p.model, p.ws, later, p.inputs(0.0), 0.01);
  sim::save_state_file(path, later);
  CHECK(same_bytes(sim::save_state(sim::load_state_file(path, p.model)), sim::save_state(later)));
  // Reading: a missing file, a truncated one, each named by its path.
  CHECK_THROWS_WITH(sim::load_state_file((dir / "none").string(), p.model),
                    Catch::Contains("none: cannot open"));
  {
    std::ofstream cut(dir / "cut.kelpstate", std::ios::binary);
    const std::string full = sim::save_state(s);
    cut << full.substr(0, full.size() / 2);
  }
  CHECK_THROWS_WITH(sim::load_state_file((dir / "cut.kelpstate").string(), p.model),
                    Catch::Contains("cut.kelpstate: truncated"));
  fs::remove_all(dir);
}

}  // namespace state_io_test
