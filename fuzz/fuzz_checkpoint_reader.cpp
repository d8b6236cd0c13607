// libFuzzer target: the reader of a closed-loop run's checkpoint (kelp/sim/checkpoint.hpp,
// src/checkpoint.cpp) on untrusted bytes, restoring a loop of the fuzz worlds' pair (with its
// winch), with or without navigation from sensors, and a few steps of what it accepts.
//
// The loops are built once and restored again and again: a restore overwrites everything a
// loop remembers (that is what a checkpoint is), so what an earlier input left in a loop cannot
// matter once a restore succeeds; a restore that fails leaves a loop that is never stepped.
//
// Input: byte 0 holds CheckpointInputFlags; the rest is the checkpoint. Oracle: the reader either
// throws kelp::sim::state_error or restores a loop whose checkpoint, written again, restores a new
// loop to the same checkpoint (the reader and the writer agree on every accepted byte); with
// `step`, the restored loop then steps or throws kelp::error. Any other exception, a crash, a
// sanitizer report or an allocation past the input's size (-malloc_limit_mb) is a finding.
#include <string>
#include <string_view>

#include "checkpoint.hpp"
#include "fuzz_common.hpp"
#include "kelp/sim/ros2/mcap.hpp"  // kelp::ros2::crc32
#include "kelp/sim/version.hpp"
#include "state_world.hpp"

namespace {

namespace sim = kelp::sim;

/// The first byte of the inputs.
enum CheckpointInputFlags : std::uint8_t {
  sensors = 1,  ///< the scenario with navigation from sensors (else the true state)
  seal = 2,     ///< the writer's version made this kelp's, the payload length and CRC-32
                ///< rewritten to fit the rest (reach the sections; seeds outlive a release)
  step = 4,     ///< an accepted loop is stepped 3 times
};

// A scenario, its world, and two loops of it (the one restored, the one the oracle restores).
struct World {
  sim::Scenario scenario;
  sim::WorldSetup world;
  sim::ClosedLoop loop, back;
  explicit World(bool with_sensors)
      : scenario(make(with_sensors)),
        world(sim::world_setup(scenario, "fuzz_checkpoint")),
        loop(scenario, world),
        back(scenario, world) {}
  static sim::Scenario make(bool with_sensors) {
    sim::Scenario sc = kelp_fuzz::StateWorld::make_scenario();
    sc.duration = 2.0;
    if (with_sensors) sc.navigation.mode = sim::NavigationMode::sensors;
    return sc;
  }
};

World& world(bool with_sensors) {
  static World plain(false), navigated(true);
  return with_sensors ? navigated : plain;
}

void put_le(std::string& b, std::size_t at, std::uint64_t v, int n) {
  for (int i = 0; i < n; ++i) b[at + std::size_t(i)] = static_cast<char>((v >> (8 * i)) & 0xFF);
}

// The writer's version set to this kelp's, then the payload's length and the CRC-32 set to fit
// the bytes (the archive's layout: the version's length at byte 12, the version from byte 13).
void reseal(std::string& b) {
  if (b.size() < 13) return;
  const std::size_t n = static_cast<unsigned char>(b[12]);
  if (b.size() >= 13 + n) {
    const std::string v = sim::version();
    b = b.substr(0, 12) + char(v.size()) + v + b.substr(13 + n);
  }
  const std::size_t payload_at = 13 + static_cast<unsigned char>(b[12]) + 8;
  if (b.size() < payload_at + 4) return;
  put_le(b, payload_at - 8, b.size() - 4 - payload_at, 8);
  put_le(b, b.size() - 4, kelp::ros2::crc32(b.data(), b.size() - 4), 4);
}

void run(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return;
  const std::uint8_t flags = data[0];
  std::string bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  if (flags & seal) reseal(bytes);
  World& w = world(flags & sensors);
  sim::ClosedLoop& loop = w.loop;
  try {
    sim::restore_checkpoint(bytes, "checkpoint", loop);
  } catch (const sim::state_error&) {
    return;
  }
  std::string again;
  try {
    again = sim::checkpoint_bytes(loop);
    sim::restore_checkpoint(again, "checkpoint written again", w.back);
    KELP_FUZZ_REQUIRE(sim::checkpoint_bytes(w.back) == again,
                      "a checkpoint written, restored and written again differs");
  } catch (const sim::state_error& e) {
    kelp_fuzz::finding(std::string("an accepted checkpoint does not write and restore: ") +
                       e.what());
  }
  if (flags & step) {
    try {
      for (int i = 0; i < 3 && !loop.done(); ++i) loop.step();
    } catch (const kelp::error&) {
      // refused or failed: the step's own business (fuzz_tether_step covers it)
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return kelp_fuzz::run_catching_stray_errors(run, data, size);
}
