// libFuzzer target: kelp::sim's state file reader (kelp/sim/state_io.hpp, src/archive.hpp) on
// untrusted bytes, with and without the system the state is for, and one step of what it
// accepts.
//
// Input: byte 0 holds StateInputFlags (state_world.hpp): which reader (pair or fleet), whether
// the payload length and CRC-32 are rewritten to fit the rest of the input before reading
// (`seal`: mutations then reach the sections behind the checksum instead of all failing it),
// whether the state is checked against the system (load_state(bytes, model)) or on its own,
// and whether an accepted state is stepped once (10 ms, zero inputs). The rest is the file.
// Oracle: the reader either throws kelp::sim::state_error or returns a state that save_state
// writes (it runs the same checks) and that loads back from those bytes to the same bytes; with
// the model, fit_workspace and the step then either succeed or throw kelp::error. Any other
// exception, a crash, a sanitizer report or an allocation past the input's size (libFuzzer's
// -malloc_limit_mb) is a finding.
#include <string>
#include <string_view>
#include <type_traits>

#include "fuzz_common.hpp"
#include "kelp/sim/ros2/mcap.hpp"  // kelp::ros2::crc32
#include "kelp/sim/state_io.hpp"
#include "state_world.hpp"

namespace {

namespace ks = kelp::system;
namespace sim = kelp::sim;

kelp_fuzz::StateWorld& world() {
  static kelp_fuzz::StateWorld w;
  return w;
}

void put_le(std::string& b, std::size_t at, std::uint64_t v, int n) {
  for (int i = 0; i < n; ++i) b[at + std::size_t(i)] = static_cast<char>((v >> (8 * i)) & 0xFF);
}

// The payload's length and the CRC-32 set to fit the bytes (docs/state-files.md's layout).
void reseal(std::string& b) {
  if (b.size() < 13) return;
  const std::size_t payload_at = 13 + static_cast<unsigned char>(b[12]) + 8;
  if (b.size() < payload_at + 4) return;
  put_le(b, payload_at - 8, b.size() - 4 - payload_at, 8);
  put_le(b, b.size() - 4, kelp::ros2::crc32(b.data(), b.size() - 4), 4);
}

template <class State, class Model, class Workspace, class Inputs>
void check(const std::string& bytes, const Model& model, Workspace& ws, const Inputs& zero,
           std::uint8_t flags) {
  State s;
  try {
    if (flags & kelp_fuzz::with_model) {
      s = sim::load_state(bytes, model);
    } else if constexpr (std::is_same_v<State, ks::SystemStated>) {
      s = sim::load_system_state(bytes);
    } else {
      s = sim::load_fleet_state(bytes);
    }
  } catch (const sim::state_error&) {
    return;
  }
  std::string again;
  try {
    again = sim::save_state(s);
  } catch (const sim::state_error& e) {
    kelp_fuzz::finding(std::string("an accepted state does not save: ") + e.what());
  }
  try {
    const State back = (flags & kelp_fuzz::with_model) ? sim::load_state(again, model) : s;
    KELP_FUZZ_REQUIRE(sim::save_state(back) == again, "saved, loaded and saved again differs");
  } catch (const sim::state_error& e) {
    kelp_fuzz::finding(std::string("a saved state does not load: ") + e.what());
  }
  if ((flags & kelp_fuzz::with_model) && (flags & kelp_fuzz::step_once)) {
    try {
      ks::fit_workspace(model, ws, s);
      (void)ks::step(model, ws, s, zero, 0.01);
    } catch (const kelp::error&) {
      // refused or failed: the step's own business (fuzz_tether_step's oracle covers it)
    }
  }
}

void run(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return;
  const std::uint8_t flags = data[0];
  std::string bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  if (flags & kelp_fuzz::seal) reseal(bytes);
  kelp_fuzz::StateWorld& w = world();
  if (flags & kelp_fuzz::fleet_file) {
    static const ks::FleetInputsd zero(w.fleet);
    check<ks::FleetStated>(bytes, w.fleet, w.fleet_ws, zero, flags);
  } else {
    static const ks::SystemInputsd zero;
    check<ks::SystemStated>(bytes, w.pair, w.pair_ws, zero, flags);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return kelp_fuzz::run_catching_stray_errors(run, data, size);
}
